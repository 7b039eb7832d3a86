// One simulated servo cycle of a Puma 560 and a WAM 7: the control law (PD with gravity
// compensation), forward dynamics with motor inertia and viscous friction, and one
// step of 1 ms, through ManipulatorSimulation (its default integrator; ServoCycle_rpEuler and
// ServoCycle_rpRK4 take each integrator, with counter error_2s_rad: the largest joint error after
// 2 s of free motion against RK4 at 10 us; Part_rpStep* time the step alone), next to MuJoCo
// stepping the same arm, which
// this program writes in MJCF from the same model (same DH frames, masses, centres of mass,
// inertias, armature G^2 Jm, viscous damping B G^2; no contacts, timestep 1 ms, integrator Euler
// (MuJoCo's is semi-implicit with implicit damping)). Our step also applies the model's Coulomb
// friction as a constraint through the mass matrix; MuJoCo gets none. The same control torques
// are computed for both with our gravity routine (so its cost is in both cycles). A second MuJoCo
// variant has no damping attribute and gets the viscous torque as an applied force, so that both
// sides take the same semi-implicit Euler step with explicit damping. Part_* entries time the
// pieces (our gravity torque and forward dynamics, mj_step alone: our whole cycle against
// mj_step alone is the strictest of the comparisons).
//
// The counter arms_per_core of ServoCycle_rp is 1 ms over the cycle time: an upper bound with no
// thread switches or wake-ups; bench/arms_per_core measures arms per core in real time.
#include <benchmark/benchmark.h>

#include <mujoco/mujoco.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "MjcfArm.hpp"
#include "rp/manipulator/ManipulatorSimulation.hpp"
#include "rp/model/Model.hpp"

namespace {

using namespace rp;
using rp::test::mjcf;

// A MuJoCo model and data loaded from the MJCF the benchmark writes.
struct MuJoCoArm {
  mjModel* m = nullptr;
  mjData* d = nullptr;
  MuJoCoArm(const ManipulatorModel& model, bool damping) {
    const std::string path =
        "/tmp/rp_simulation_bench_" + model.getName() + (damping ? "" : "_undamped") + ".xml";
    if (FILE* f = std::fopen(path.c_str(), "w")) {
      const std::string xml = mjcf(model, damping);
      std::fputs(xml.c_str(), f);
      std::fclose(f);
    }
    char error[1000] = "";
    m = mj_loadXML(path.c_str(), nullptr, error, sizeof error);
    if (m == nullptr) throw std::runtime_error(std::string("MuJoCo: ") + error);
    d = mj_makeData(m);
    for (int i = 0; i < model.getNumberOfJoints(); ++i) d->qpos[i] = model.getHomePosition()(i);
  }
  ~MuJoCoArm() {
    mj_deleteData(d);
    mj_deleteModel(m);
  }
};

struct Arm {
  std::unique_ptr<ManipulatorModel> model;
  std::unique_ptr<ManipulatorData> data;
  std::unique_ptr<ManipulatorSimulation> sim;
  JointVector target, kp, kd, g, tau, viscous;
  std::unique_ptr<MuJoCoArm> mujoco;          // damping as a joint attribute (MuJoCo integrates it implicitly)
  std::unique_ptr<MuJoCoArm> mujocoExplicit;  // no damping attribute: viscous friction applied as a force

  explicit Arm(std::unique_ptr<ManipulatorModel> mm) : model(std::move(mm)) {
    data = std::make_unique<ManipulatorData>(*model);
    sim = std::make_unique<ManipulatorSimulation>(*model);
    const int n = model->getNumberOfJoints();
    target = model->getHomePosition();
    // 0.1 rad from home towards the middle of each joint's range (away from the stops).
    for (int i = 0; i < n; ++i) {
      const double middle = 0.5 * (model->getPositionMin()(i) + model->getPositionMax()(i));
      target(i) += target(i) < middle ? 0.1 : -0.1;
    }
    kp = kd = g = tau = viscous = JointVector(n);
    const JointMatrix& M = massMatrix(*model, *data, model->getHomePosition(), true);
    for (int i = 0; i < n; ++i) {
      kp(i) = M(i, i) * 625;
      kd(i) = M(i, i) * 50;
      const LinkParameters& l = model->getLink(i);
      viscous(i) = l.viscousFriction * l.gearRatio * l.gearRatio;
    }
    mujoco = std::make_unique<MuJoCoArm>(*model, true);
    mujocoExplicit = std::make_unique<MuJoCoArm>(*model, false);
  }
  // The control law: PD towards the target plus gravity compensation.
  void control(const JointVector& q, const JointVector& qd) {
    gravityTorque(*model, *data, q, g);
    tau = kp.cwiseProduct(target - q) - kd.cwiseProduct(qd) + g;
    for (int i = 0; i < tau.size(); ++i) tau(i) = std::clamp(tau(i), -model->getTorqueLimit()(i), model->getTorqueLimit()(i));
  }
};

Arm& arm(const benchmark::State& s) {
  static Arm puma(std::make_unique<Puma560Model>());
  static Arm wam(std::make_unique<WAM7Model>());
  return s.range(0) == 6 ? puma : wam;
}

// Largest joint error [rad] after 2 s of free motion (no gravity, no friction: the arm coasts from
// the middle of its ranges, coupled through M and C) of a 1 ms step of `integrator`, against the
// same dynamics by RK4 at 10 us.
double freeMotionError(const ManipulatorModel& arm, SimulationIntegrator integrator) {
  const int n = arm.getNumberOfJoints();
  std::vector<LinkParameters> links;
  for (int i = 0; i < n; ++i) {
    LinkParameters l = arm.getLink(i);
    l.viscousFriction = l.coulombFrictionPositive = l.coulombFrictionNegative = 0;
    links.push_back(l);
  }
  const ManipulatorModel model(arm.getName(), links, arm.getBaseTransform(), arm.getToolTransform(), Vector<3>());
  JointVector q0(n), v0(n);
  for (int i = 0; i < n; ++i) {
    q0(i) = 0.5 * (model.getPositionMin()(i) + model.getPositionMax()(i));
    v0(i) = i % 2 ? -0.3 : 0.4;
  }
  auto run = [&](SimulationIntegrator which, double h) {
    ManipulatorSimulation sim(model);
    sim.setIntegrator(which);
    sim.setState(q0, v0);
    const JointVector zero = JointVector::Zero(n);
    const long steps = std::lround(2.0 / h);
    for (long k = 0; k < steps; ++k) sim.step(zero, h);
    return sim.getTruePosition();
  };
  static std::map<std::string, JointVector> reference;
  if (reference.count(model.getName()) == 0) reference[model.getName()] = run(SimulationIntegrator::RK4, 1e-5);
  return (run(integrator, 1e-3) - reference[model.getName()]).cwiseAbs().maxCoeff();
}

// One servo cycle with the given integrator; counters: the free-motion accuracy above. `moving`:
// the arm in motion, as bench/arms_per_core's arms move - the target swings 0.1 rad at 0.5 Hz on
// joints 1-3 about the start, the other joints held, so some joints slide and others stick (the
// friction solve's harder case; without it the arm comes to rest at the target).
void servoCycle(benchmark::State& s, SimulationIntegrator integrator, bool moving = false) {
  Arm& a = arm(s);
  a.sim->setIntegrator(integrator);
  const JointVector start = a.target;
  a.sim->setState(moving ? start : a.model->getHomePosition(), JointVector(a.model->getNumberOfJoints()));
  long k = 0;
  for (auto _ : s) {
    if (moving) {
      const double swing = 0.1 * std::sin(2 * 3.14159265358979 * 0.5 * 1e-3 * static_cast<double>(k++));
      for (int i = 0; i < 3; ++i) a.target(i) = start(i) + swing;
    }
    a.control(a.sim->getPosition(), a.sim->getVelocity());
    a.sim->step(a.tau, 1e-3);
    benchmark::DoNotOptimize(a.sim->getPosition().data());
  }
  a.target = start;
  if (moving) return;
  s.counters["error_2s_rad"] = freeMotionError(*a.model, integrator);
  s.counters["arms_per_core"] = benchmark::Counter(1e-3, benchmark::Counter::kIsIterationInvariantRate);
}
void ServoCycle_rpEuler(benchmark::State& s) { servoCycle(s, SimulationIntegrator::Euler); }
void ServoCycle_rpRK4(benchmark::State& s) { servoCycle(s, SimulationIntegrator::RK4); }
void ServoCycle_rpEulerMoving(benchmark::State& s) { servoCycle(s, SimulationIntegrator::Euler, true); }
void ServoCycle_rpRK4Moving(benchmark::State& s) { servoCycle(s, SimulationIntegrator::RK4, true); }

// The simulation step alone (no control law), each integrator, next to Part_MuJoCoStep.
void stepOnly(benchmark::State& s, SimulationIntegrator integrator) {
  Arm& a = arm(s);
  a.sim->setIntegrator(integrator);
  a.sim->setState(a.target, JointVector(a.model->getNumberOfJoints()));
  a.control(a.target, JointVector(a.model->getNumberOfJoints()));
  for (auto _ : s) {
    a.sim->step(a.tau, 1e-3);
    benchmark::DoNotOptimize(a.sim->getPosition().data());
  }
}
void Part_rpStepEuler(benchmark::State& s) { stepOnly(s, SimulationIntegrator::Euler); }
void Part_rpStepRK4(benchmark::State& s) { stepOnly(s, SimulationIntegrator::RK4); }

void ServoCycle_rp(benchmark::State& s) {
  Arm& a = arm(s);
  a.sim->setIntegrator(ManipulatorSimulation(*a.model).getIntegrator());  // the default
  a.sim->setState(a.model->getHomePosition(), JointVector(a.model->getNumberOfJoints()));
  for (auto _ : s) {
    a.control(a.sim->getPosition(), a.sim->getVelocity());
    a.sim->step(a.tau, 1e-3);
    benchmark::DoNotOptimize(a.sim->getPosition().data());
  }
  // Arms one core could simulate at 1 kHz if nothing but this cycle ran (no thread switches or
  // timer wake-ups; bench/arms_per_core measures those in real time): 1 ms / cycle time.
  s.counters["arms_per_core"] = benchmark::Counter(1e-3, benchmark::Counter::kIsIterationInvariantRate);
}

// The same control law around mj_step. `explicitDamping`: the model has no damping attribute and
// the viscous friction -B G^2 qd is added to the applied force, so that MuJoCo's Euler step is the
// plain semi-implicit Euler step ManipulatorSimulation takes (with a damping attribute MuJoCo
// integrates damping implicitly, which costs it a second factorisation of M + h D).
void mujocoCycle(benchmark::State& s, bool explicitDamping) {
  Arm& a = arm(s);
  MuJoCoArm& mj = explicitDamping ? *a.mujocoExplicit : *a.mujoco;
  const int n = a.model->getNumberOfJoints();
  JointVector q(n), qd(n);
  for (auto _ : s) {
    for (int i = 0; i < n; ++i) {
      q(i) = mj.d->qpos[i];
      qd(i) = mj.d->qvel[i];
    }
    a.control(q, qd);
    for (int i = 0; i < n; ++i) mj.d->qfrc_applied[i] = a.tau(i) - (explicitDamping ? a.viscous(i) * qd(i) : 0.0);
    mj_step(mj.m, mj.d);
    benchmark::DoNotOptimize(mj.d->qpos);
  }
}

void ServoCycle_MuJoCo(benchmark::State& s) { mujocoCycle(s, false); }
void ServoCycle_MuJoCoExplicitDamping(benchmark::State& s) { mujocoCycle(s, true); }

// The parts of our cycle: the control law's gravity torque (forward kinematics and link mass
// moments), and the forward dynamics inside the simulation step (in world coordinates after one
// forward kinematics: the same gravity routine, the velocity products by a spatial Newton-Euler
// pass, M by composite rigid bodies, an unpivoted LDL^T solve).
void Part_rpGravityTorque(benchmark::State& s) {
  Arm& a = arm(s);
  JointVector q = a.target;
  for (auto _ : s) {
    gravityTorque(*a.model, *a.data, q, a.g);
    benchmark::DoNotOptimize(a.g.data());
    q(0) += 1e-9;
  }
}

void Part_rpForwardDynamics(benchmark::State& s) {
  Arm& a = arm(s);
  JointVector q = a.target, qd(a.model->getNumberOfJoints()), tau(a.model->getNumberOfJoints());
  DynamicsOptions options;
  options.motorInertia = true;
  for (auto _ : s) {
    benchmark::DoNotOptimize(forwardDynamics(*a.model, *a.data, q, qd, tau, options).data());
    q(0) += 1e-9;
  }
}

// mj_step alone (no control law around it).
void Part_MuJoCoStep(benchmark::State& s) {
  Arm& a = arm(s);
  for (auto _ : s) {
    mj_step(a.mujoco->m, a.mujoco->d);
    benchmark::DoNotOptimize(a.mujoco->d->qpos);
  }
}

BENCHMARK(ServoCycle_rp)->Arg(6)->Arg(7);
BENCHMARK(ServoCycle_rpEuler)->Arg(6)->Arg(7);
BENCHMARK(ServoCycle_rpRK4)->Arg(6)->Arg(7);
BENCHMARK(ServoCycle_rpEulerMoving)->Arg(6)->Arg(7);
BENCHMARK(ServoCycle_rpRK4Moving)->Arg(6)->Arg(7);
BENCHMARK(Part_rpStepEuler)->Arg(6)->Arg(7);
BENCHMARK(Part_rpStepRK4)->Arg(6)->Arg(7);
BENCHMARK(ServoCycle_MuJoCo)->Arg(6)->Arg(7);
BENCHMARK(ServoCycle_MuJoCoExplicitDamping)->Arg(6)->Arg(7);
BENCHMARK(Part_rpGravityTorque)->Arg(6)->Arg(7);
BENCHMARK(Part_rpForwardDynamics)->Arg(6)->Arg(7);
BENCHMARK(Part_MuJoCoStep)->Arg(6)->Arg(7);

}  // namespace

BENCHMARK_MAIN();
