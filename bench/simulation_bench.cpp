// One simulated servo cycle of a Puma 560 and a WAM 7: the control law (PD with gravity
// compensation), forward dynamics with motor inertia and viscous friction, and one semi-implicit
// Euler step of 1 ms, through ManipulatorSimulation; next to MuJoCo stepping the same arm, which
// this program writes in MJCF from the same model (same DH frames, masses, centres of mass,
// inertias, armature G^2 Jm, viscous damping B G^2; no contacts, no Coulomb friction on either
// side, timestep 1 ms, integrator Euler (MuJoCo's is semi-implicit with implicit damping)). The
// same control torques are computed for both with our gravity routine.
//
// Also: how many simulated Puma arms one core could run at 1 kHz in real time, from the
// measured cycle time (reported as the counter arms_per_core).
#include <benchmark/benchmark.h>

#include <mujoco/mujoco.h>

#include <cstdio>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>

#include "rp/manipulator/ManipulatorSimulation.hpp"
#include "rp/model/Model.hpp"

namespace {

using namespace rp;

// MJCF for a standard-DH model: body k sits at frame k-1 and turns about its z axis; link k's
// inertia lives in frame k = Rz(q_k) M_k with M_k = Tz(d) Tx(a) Rx(alpha), so it is given at
// M_k * com with the rotated inertia tensor, and body k+1 is placed at M_k.
std::string mjcf(const ManipulatorModel& model) {
  std::ostringstream x;
  x.precision(17);
  // balanceinertia: the Puma's link 1 (Ixx = Izz = 0, Iyy = 0.35) breaks MuJoCo's triangle
  // inequality check; MuJoCo then adjusts that inertia (timing is unaffected).
  x << "<mujoco model=\"" << model.getName() << "\">\n<compiler balanceinertia=\"true\"/>\n"
    << "<option timestep=\"0.001\" integrator=\"Euler\" gravity=\"0 0 -9.81\"><flag contact=\"disable\"/></option>\n"
    << "<worldbody>\n";
  Transform parent = Transform::unit();  // pose of body k's frame in body k-1's frame
  const int n = model.getNumberOfJoints();
  for (int k = 0; k < n; ++k) {
    const LinkParameters& l = model.getLink(k);
    const Transform M = translation(0, 0, l.d) * translation(l.a, 0, 0) * xRotation(l.alpha);
    const Eigen::Quaterniond qp(Eigen::Matrix3d(parent.topLeftCorner<3, 3>()));
    x << "<body name=\"link" << k + 1 << "\" pos=\"" << parent(0, 3) << " " << parent(1, 3) << " " << parent(2, 3)
      << "\" quat=\"" << qp.w() << " " << qp.x() << " " << qp.y() << " " << qp.z() << "\">\n";
    const double G = l.gearRatio;
    x << "<joint name=\"j" << k + 1 << "\" type=\"hinge\" axis=\"0 0 1\" armature=\"" << G * G * l.motorInertia
      << "\" damping=\"" << l.viscousFriction * G * G << "\"/>\n";
    const Eigen::Vector3d c = M.topLeftCorner<3, 3>() * Eigen::Vector3d(l.com) + M.topRightCorner<3, 1>();
    const Eigen::Matrix3d I = M.topLeftCorner<3, 3>() * Eigen::Matrix3d(l.inertia) * M.topLeftCorner<3, 3>().transpose();
    const double mass = l.mass > 0 ? l.mass : 1e-6;  // MuJoCo needs mass on a moving body
    x << "<inertial pos=\"" << c(0) << " " << c(1) << " " << c(2) << "\" mass=\"" << mass << "\" fullinertia=\""
      << I(0, 0) + 1e-9 << " " << I(1, 1) + 1e-9 << " " << I(2, 2) + 1e-9 << " " << I(0, 1) << " " << I(0, 2) << " "
      << I(1, 2) << "\"/>\n";
    parent = M;
  }
  for (int k = 0; k < n; ++k) x << "</body>\n";
  x << "</worldbody>\n</mujoco>\n";
  return x.str();
}

struct Arm {
  std::unique_ptr<ManipulatorModel> model;
  std::unique_ptr<ManipulatorData> data;
  std::unique_ptr<ManipulatorSimulation> sim;
  JointVector target, kp, kd, g, tau;
  mjModel* m = nullptr;
  mjData* d = nullptr;

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
    kp = kd = g = tau = JointVector(n);
    const JointMatrix& M = massMatrix(*model, *data, model->getHomePosition(), true);
    for (int i = 0; i < n; ++i) {
      kp(i) = M(i, i) * 625;
      kd(i) = M(i, i) * 50;
    }
    const std::string path = "/tmp/rp_simulation_bench_" + model->getName() + ".xml";
    if (FILE* f = std::fopen(path.c_str(), "w")) {
      const std::string xml = mjcf(*model);
      std::fputs(xml.c_str(), f);
      std::fclose(f);
    }
    char error[1000] = "";
    m = mj_loadXML(path.c_str(), nullptr, error, sizeof error);
    if (m == nullptr) throw std::runtime_error(std::string("MuJoCo: ") + error);
    d = mj_makeData(m);
    for (int i = 0; i < n; ++i) d->qpos[i] = model->getHomePosition()(i);
  }
  ~Arm() {
    mj_deleteData(d);
    mj_deleteModel(m);
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

void ServoCycle_rp(benchmark::State& s) {
  Arm& a = arm(s);
  a.sim->setState(a.model->getHomePosition(), JointVector(a.model->getNumberOfJoints()));
  for (auto _ : s) {
    a.control(a.sim->getPosition(), a.sim->getVelocity());
    a.sim->step(a.tau, 1e-3);
    benchmark::DoNotOptimize(a.sim->getPosition().data());
  }
  // Arms one core could simulate at 1 kHz: 1 ms divided by the time of one cycle.
  s.counters["arms_per_core"] = benchmark::Counter(1e-3, benchmark::Counter::kIsIterationInvariantRate);
}

void ServoCycle_MuJoCo(benchmark::State& s) {
  Arm& a = arm(s);
  const int n = a.model->getNumberOfJoints();
  JointVector q(n), qd(n);
  for (auto _ : s) {
    for (int i = 0; i < n; ++i) {
      q(i) = a.d->qpos[i];
      qd(i) = a.d->qvel[i];
    }
    a.control(q, qd);
    for (int i = 0; i < n; ++i) a.d->qfrc_applied[i] = a.tau(i);
    mj_step(a.m, a.d);
    benchmark::DoNotOptimize(a.d->qpos);
  }
}

BENCHMARK(ServoCycle_rp)->Arg(6)->Arg(7);
BENCHMARK(ServoCycle_MuJoCo)->Arg(6)->Arg(7);

}  // namespace

BENCHMARK_MAIN();
