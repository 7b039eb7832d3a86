// The simulated plant (ManipulatorSimulation) against physics it must have: Coulomb friction
// through the full mass matrix (against an independent integration of the model's forward
// dynamics with the same friction law), joint stops that are stable and dissipative on every joint
// of every arm, the RK4 integrator's accuracy against a fine-step ground truth, plant deviations
// and simulated sensors from rp.cfg, and no allocation while stepping.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <cmath>
#include <limits>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <unistd.h>

#include "AllocationCounter.hpp"
#include "MjcfArm.hpp"
#include "SimulatedArmTest.hpp"
#include "rp/RoboticPlatform.hpp"
#include "rp/manipulator/ManipulatorSimulation.hpp"
#include "rp/model/Model.hpp"

namespace rp {
namespace {

std::vector<std::unique_ptr<ManipulatorModel>> allArms() {
  std::vector<std::unique_ptr<ManipulatorModel>> arms;
  arms.push_back(std::make_unique<Puma560Model>());
  arms.push_back(std::make_unique<WAM4Model>());
  arms.push_back(std::make_unique<WAM7Model>());
  return arms;
}

double coulombPos(const LinkParameters& l) { return std::abs(l.gearRatio * l.coulombFrictionPositive); }
double coulombNeg(const LinkParameters& l) { return std::abs(l.gearRatio * l.coulombFrictionNegative); }

// ---- Coulomb friction through the full dynamics ------------------------------------------------

// In a sliding state (every joint moving fast enough not to stop within the step) a short step
// must change the velocity by the model's forward dynamics with its own friction law (viscous and
// Coulomb, DynamicsOptions::friction), which couples the joints through M^-1: the friction of one
// joint accelerates the others.
TEST(SimulationFriction, SlidingAccelerationIsTheModelsForwardDynamicsWithFriction) {
  std::mt19937 rng(7);
  for (const auto& model : allArms()) {
    const int n = model->getNumberOfJoints();
    ManipulatorData data(*model);
    DynamicsOptions options;
    options.motorInertia = true;
    options.friction = true;
    for (SimulationIntegrator integrator : {SimulationIntegrator::Euler, SimulationIntegrator::RK4}) {
      ManipulatorSimulation sim(*model);
      sim.setIntegrator(integrator);
      double worst = 0, largest = 0;
      for (int trial = 0; trial < 20; ++trial) {
        JointVector q(n), qd(n), tau(n);
        for (int i = 0; i < n; ++i) {
          std::uniform_real_distribution<double> in(model->getPositionMin()(i) + 0.1, model->getPositionMax()(i) - 0.1);
          q(i) = in(rng);
          qd(i) = std::uniform_real_distribution<double>(0.2, 1.0)(rng) * (rng() % 2 ? 1 : -1);
          tau(i) = std::uniform_real_distribution<double>(-0.3, 0.3)(rng) * model->getTorqueLimit()(i);
        }
        const double h = 1e-6;
        sim.setState(q, qd);
        sim.step(tau, h);
        const JointVector measured = (sim.getTrueVelocity() - qd) / h;
        const JointVector& expected = forwardDynamics(*model, data, q, qd, tau, options);
        worst = std::max(worst, (measured - expected).cwiseAbs().maxCoeff());
        largest = std::max(largest, expected.cwiseAbs().maxCoeff());
      }
      std::printf("  %s %s: largest acceleration %.3g rad/s^2, worst difference %.3g\n", model->getName().c_str(),
                  integrator == SimulationIntegrator::RK4 ? "rk4" : "euler", largest, worst);
      EXPECT_LT(worst, 1e-3 * largest) << model->getName();
    }
  }
}

// getAcceleration() after a step of either integrator: the model's forward dynamics at the step's
// start under the applied torque (clamped to the limits) and the viscous friction, as documented;
// the Euler step solves for it only when asked, from the start it kept, so a second step, a call
// before any step and setState() must each give their own.
TEST(SimulationFriction, TheAccelerationIsTheForwardDynamicsAtTheStepsStart) {
  std::mt19937 rng(11);
  for (const auto& model : allArms()) {
    const int n = model->getNumberOfJoints();
    ManipulatorData data(*model);
    DynamicsOptions options;
    options.motorInertia = true;
    for (SimulationIntegrator integrator : {SimulationIntegrator::Euler, SimulationIntegrator::RK4}) {
      ManipulatorSimulation sim(*model);
      sim.setIntegrator(integrator);
      EXPECT_EQ(sim.getAcceleration(), JointVector::Zero(n)) << "before any step";
      for (int trial = 0; trial < 10; ++trial) {
        JointVector q(n), qd(n), tau(n), viscous(n);
        for (int i = 0; i < n; ++i) {
          std::uniform_real_distribution<double> in(model->getPositionMin()(i) + 0.2, model->getPositionMax()(i) - 0.2);
          q(i) = in(rng);
          qd(i) = std::uniform_real_distribution<double>(-1.0, 1.0)(rng);
          tau(i) = std::uniform_real_distribution<double>(-1.2, 1.2)(rng) * model->getTorqueLimit()(i);
          const LinkParameters& l = model->getLink(i);
          viscous(i) = l.viscousFriction * l.gearRatio * l.gearRatio;
        }
        sim.setState(q, qd);
        EXPECT_EQ(sim.getAcceleration(), JointVector::Zero(n)) << "after setState()";
        sim.step(tau, 1e-3);
        const JointVector applied = tau.cwiseMax(-model->getTorqueLimit()).cwiseMin(model->getTorqueLimit());
        const JointVector expected = forwardDynamics(*model, data, q, qd, applied - viscous.cwiseProduct(qd), options);
        const double scale = 1 + expected.cwiseAbs().maxCoeff();
        EXPECT_LT((sim.getAcceleration() - expected).cwiseAbs().maxCoeff(), 1e-9 * scale) << model->getName();
        EXPECT_EQ(sim.getAcceleration(), sim.getAcceleration()) << "asked twice";
        // The next step's start is this step's end.
        const JointVector q1 = sim.getTruePosition(), qd1 = sim.getTrueVelocity();
        sim.step(tau, 1e-3);
        const JointVector next = forwardDynamics(*model, data, q1, qd1, applied - viscous.cwiseProduct(qd1), options);
        EXPECT_LT((sim.getAcceleration() - next).cwiseAbs().maxCoeff(), 1e-9 * scale) << model->getName();
        EXPECT_GT((next - expected).cwiseAbs().maxCoeff(), 1e-6 * scale) << "the two starts give different accelerations";
      }
    }
  }
}

// The reference: the model's forward dynamics with Coulomb friction in a fixed contact mode (each
// joint stuck, sliding up or sliding down), integrated by RK4 at 0.1 ms. The mode at the start is
// the one that satisfies Coulomb's law (found among all 3^n); along the run the reference checks
// that it stays valid (a sliding joint does not reverse, a stuck joint's holding torque stays
// within its friction), so the comparison is with the true solution of the friction law.
struct FrictionReference {
  const ManipulatorModel& model;
  ManipulatorData data;
  std::vector<int> mode;  // 0 stuck, +1 sliding up, -1 sliding down
  JointVector tau;
  bool valid = true;

  FrictionReference(const ManipulatorModel& m, const JointVector& q, const JointVector& t)
      : model(m), data(m), tau(t) {
    const int n = m.getNumberOfJoints();
    int total = 1;
    for (int i = 0; i < n; ++i) total *= 3;
    std::vector<std::vector<int>> valid;
    for (int code = 0; code < total; ++code) {
      std::vector<int> trial(static_cast<std::size_t>(n));
      for (int i = 0, c = code; i < n; ++i, c /= 3) trial[static_cast<std::size_t>(i)] = c % 3 - 1;
      mode = trial;
      JointVector qdd, hold;
      accelerations(q, JointVector::Zero(n), qdd, hold);
      bool ok = true;
      for (int i = 0; i < n; ++i) {
        const int s = trial[static_cast<std::size_t>(i)];
        const LinkParameters& l = m.getLink(i);
        if (s == 0 && !(hold(i) <= coulombNeg(l) && hold(i) >= -coulombPos(l))) ok = false;
        if (s != 0 && !(s * qdd(i) > 0)) ok = false;
      }
      if (ok) valid.push_back(trial);
    }
    // M is positive definite, so Coulomb's law gives exactly one mode.
    EXPECT_EQ(valid.size(), 1u);
    if (!valid.empty()) mode = valid.front();
  }

  // Accelerations in the mode; `hold` is the torque the stuck joints need (what friction supplies).
  void accelerations(const JointVector& q, const JointVector& qd, JointVector& qdd, JointVector& hold) {
    const int n = model.getNumberOfJoints();
    JointVector t = tau;
    for (int i = 0; i < n; ++i) {
      const LinkParameters& l = model.getLink(i);
      const int s = mode[static_cast<std::size_t>(i)];
      t(i) -= l.viscousFriction * l.gearRatio * l.gearRatio * qd(i);
      if (s > 0) t(i) -= coulombPos(l);
      if (s < 0) t(i) += coulombNeg(l);
    }
    DynamicsOptions options;
    options.motorInertia = true;
    const JointVector bias = inverseDynamics(model, data, q, qd, JointVector::Zero(n), options);
    const JointMatrix M = massMatrix(model, data, q, true);
    std::vector<int> freeJoints;
    for (int i = 0; i < n; ++i)
      if (mode[static_cast<std::size_t>(i)] != 0) freeJoints.push_back(i);
    const auto f = static_cast<int>(freeJoints.size());
    Eigen::MatrixXd Mf(f, f);
    Eigen::VectorXd rhs(f);
    for (int a = 0; a < f; ++a) {
      rhs(a) = t(freeJoints[static_cast<std::size_t>(a)]) - bias(freeJoints[static_cast<std::size_t>(a)]);
      for (int b = 0; b < f; ++b) Mf(a, b) = M(freeJoints[static_cast<std::size_t>(a)], freeJoints[static_cast<std::size_t>(b)]);
    }
    const Eigen::VectorXd x = f > 0 ? Eigen::VectorXd(Mf.ldlt().solve(rhs)) : Eigen::VectorXd();
    qdd.setZero(n);
    for (int a = 0; a < f; ++a) qdd(freeJoints[static_cast<std::size_t>(a)]) = x(a);
    // Holding torque of the stuck joints: M qdd + bias - t on their rows.
    hold = M * qdd + bias - t;
    for (int i = 0; i < n; ++i)
      if (mode[static_cast<std::size_t>(i)] != 0) hold(i) = 0;
  }

  // Integrates for `duration` from rest at q by RK4 at `h`; returns the final positions.
  JointVector run(JointVector q, double duration, double h) {
    const int n = model.getNumberOfJoints();
    JointVector v = JointVector::Zero(n), a1, a2, a3, a4, hold;
    const int steps = static_cast<int>(std::lround(duration / h));
    for (int k = 0; k < steps; ++k) {
      accelerations(q, v, a1, hold);
      for (int i = 0; i < n; ++i) {
        const LinkParameters& l = model.getLink(i);
        const int s = mode[static_cast<std::size_t>(i)];
        if (s == 0 && !(hold(i) <= coulombNeg(l) && hold(i) >= -coulombPos(l))) valid = false;
        if (s != 0 && k > 0 && !(s * v(i) > 0)) valid = false;
      }
      const JointVector v2 = v + 0.5 * h * a1;
      accelerations(q + 0.5 * h * v, v2, a2, hold);
      const JointVector v3 = v + 0.5 * h * a2;
      accelerations(q + 0.5 * h * v2, v3, a3, hold);
      const JointVector v4 = v + h * a3;
      accelerations(q + h * v3, v4, a4, hold);
      q += (h / 6) * (v + 2 * v2 + 2 * v3 + v4);
      v += (h / 6) * (a1 + 2 * a2 + 2 * a3 + a4);
    }
    return q;
  }
};

// One semi-implicit Euler step with Coulomb friction is a convex problem in the new velocity v:
// minimise 1/2 v^T A v - r^T v + h sum_i f_i(v_i), with A = M(q) + h diag(b) (b the viscous
// friction), r = M(q) qd + h (tau - g(q) - C(q, qd) qd) and f_i the joint's Coulomb dissipation.
// Its minimiser is the one contact mode of the 3^n (each joint stuck, sliding up or down) whose
// linear system gives velocities in the mode's directions and holding torques within the stuck
// joints' friction. From states slow enough that friction stops some joints within the step and
// not others, the simulation's step must land on that solution, found here by enumeration.
TEST(SimulationFriction, AnEulerStepIsTheExactSolutionOfTheFrictionLaw) {
  std::mt19937 rng(11);
  int arms = 0;
  for (const auto& model : allArms()) {
    const int n = model->getNumberOfJoints();
    bool coulomb = false;
    for (int i = 0; i < n; ++i) coulomb = coulomb || coulombPos(model->getLink(i)) > 0 || coulombNeg(model->getLink(i)) > 0;
    if (!coulomb) continue;
    ++arms;
    ManipulatorData data(*model);
    DynamicsOptions options;
    options.motorInertia = true;
    const double h = 1e-3;
    int mixed = 0, cases = 0;
    double worst = 0;
    for (int trial = 0; trial < 150; ++trial) {
      JointVector q(n), qd(n), tau(n), b(n), up(n), down(n);
      for (int i = 0; i < n; ++i) {
        std::uniform_real_distribution<double> in(model->getPositionMin()(i) + 0.1, model->getPositionMax()(i) - 0.1);
        q(i) = in(rng);
      }
      const JointMatrix M = massMatrix(*model, data, q, true);
      JointVector g(n);
      gravityTorque(*model, data, q, g);
      for (int i = 0; i < n; ++i) {
        const LinkParameters& l = model->getLink(i);
        b(i) = l.viscousFriction * l.gearRatio * l.gearRatio;
        up(i) = coulombPos(l);
        down(i) = coulombNeg(l);
        // About what friction takes from the joint in one step, either way, and a torque about
        // the size of its friction beyond gravity: some joints stop, others slide.
        const double dv = h * std::max(up(i), down(i)) / M(i, i);
        qd(i) = std::uniform_real_distribution<double>(-2.0, 2.0)(rng) * dv;
        tau(i) = g(i) + std::uniform_real_distribution<double>(-1.5, 1.5)(rng) * std::max(up(i), down(i));
        tau(i) = std::clamp(tau(i), -model->getTorqueLimit()(i), model->getTorqueLimit()(i));  // as the plant applies it
      }
      const JointVector bias = inverseDynamics(*model, data, q, qd, JointVector::Zero(n), options);
      Eigen::MatrixXd A = Eigen::MatrixXd(M.topLeftCorner(n, n));
      for (int i = 0; i < n; ++i) A(i, i) += h * b(i);
      const Eigen::VectorXd r = Eigen::MatrixXd(M.topLeftCorner(n, n)) * Eigen::VectorXd(qd) + h * Eigen::VectorXd(tau - bias);
      // Enumerate the modes.
      std::vector<Eigen::VectorXd> solutions;
      int total = 1;
      for (int i = 0; i < n; ++i) total *= 3;
      for (int code = 0; code < total; ++code) {
        std::vector<int> mode(static_cast<std::size_t>(n)), slide;
        for (int i = 0, c = code; i < n; ++i, c /= 3) {
          mode[static_cast<std::size_t>(i)] = c % 3 - 1;
          if (c % 3 != 1) slide.push_back(i);
        }
        const auto m = static_cast<int>(slide.size());
        Eigen::MatrixXd As(m, m);
        Eigen::VectorXd rs(m);
        for (int a = 0; a < m; ++a) {
          const int i = slide[static_cast<std::size_t>(a)];
          rs(a) = r(i) - h * (mode[static_cast<std::size_t>(i)] > 0 ? up(i) : -down(i));
          for (int c = 0; c < m; ++c) As(a, c) = A(i, slide[static_cast<std::size_t>(c)]);
        }
        Eigen::VectorXd v = Eigen::VectorXd::Zero(n);
        if (m > 0) {
          const Eigen::VectorXd vs = As.llt().solve(rs);
          for (int a = 0; a < m; ++a) v(slide[static_cast<std::size_t>(a)]) = vs(a);
        }
        const Eigen::VectorXd hold = r - A * v;  // what friction must supply at each joint
        bool ok = true;
        for (int i = 0; i < n; ++i) {
          const int s = mode[static_cast<std::size_t>(i)];
          if (s != 0 && !(s * v(i) > 0)) ok = false;
          if (s == 0 && !(hold(i) <= h * up(i) && hold(i) >= -h * down(i))) ok = false;
        }
        if (ok) solutions.push_back(v);
      }
      ASSERT_EQ(solutions.size(), 1u) << model->getName() << " trial " << trial;  // strictly convex
      const Eigen::VectorXd& expected = solutions.front();
      int stuck = 0;
      for (int i = 0; i < n; ++i) stuck += expected(i) == 0;
      mixed += stuck > 0 && stuck < n;
      ++cases;

      ManipulatorSimulation sim(*model);
      sim.setIntegrator(SimulationIntegrator::Euler);
      sim.setState(q, qd);
      sim.step(tau, h);
      for (int i = 0; i < n; ++i) {
        const double error = std::abs(sim.getTrueVelocity()(i) - expected(i));
        worst = std::max(worst, error);
        EXPECT_LT(error, 1e-10) << model->getName() << " trial " << trial << " joint " << i + 1;
        // A joint the law holds is exactly at rest.
        if (expected(i) == 0) {
          EXPECT_EQ(sim.getTrueVelocity()(i), 0.0) << model->getName() << " trial " << trial;
        }
      }
    }
    std::printf("  %s: %d of %d steps with joints both stuck and sliding; worst velocity difference %.3g rad/s\n",
                model->getName().c_str(), mixed, cases, worst);
    EXPECT_GT(mixed, cases / 4) << "the states must mix stick and slip to test the law";
  }
  EXPECT_GE(arms, 1);
}

// The Puma's shoulder falls freely (no torque) with the upper arm starting horizontal: its
// friction, and the torques that hold the joints that stick, act through the full mass matrix.
TEST(SimulationFriction, PumaShoulderFreeFallMatchesTheReference) {
  Puma560Model model;
  JointVector q = model.getHomePosition();
  q(1) = 0;  // upper arm horizontal
  q(2) = 0.3;
  const JointVector zero = JointVector::Zero(6);
  const double duration = 0.3;
  FrictionReference reference(model, q, zero);
  const JointVector expected = reference.run(q, duration, 1e-4);
  ASSERT_TRUE(reference.valid) << "the contact mode changed during the reference run";
  std::printf("  reference mode:");
  for (int s : reference.mode) std::printf(" %d", s);
  std::printf("\n");
  ASSERT_NE(reference.mode[1], 0) << "the shoulder should slide";
  const double fall = expected(1) - q(1);
  for (SimulationIntegrator integrator : {SimulationIntegrator::Euler, SimulationIntegrator::RK4}) {
    ManipulatorSimulation sim(model);
    sim.setIntegrator(integrator);
    sim.setState(q, zero);
    for (int k = 0; k < 300; ++k) sim.step(zero, 1e-3);
    const JointVector& got = sim.getTruePosition();
    std::printf("  %s: shoulder fell %.2f mrad in %.1f s (reference %.2f mrad); worst joint difference %.3g rad\n",
                integrator == SimulationIntegrator::RK4 ? "rk4" : "euler", 1e3 * (got(1) - q(1)), duration, 1e3 * fall,
                (got - expected).cwiseAbs().maxCoeff());
    EXPECT_NEAR(got(1) - q(1), fall, 0.02 * std::abs(fall));
    for (int i = 0; i < 6; ++i) {
      if (reference.mode[static_cast<std::size_t>(i)] == 0) {
        EXPECT_EQ(got(i), q(i)) << "joint " << i + 1 << " is held by its friction";
      } else {
        EXPECT_NEAR(got(i), expected(i), 0.02 * std::abs(expected(i) - q(i)) + 1e-4) << "joint " << i + 1;
      }
    }
  }
}

// The same free fall in MuJoCo (Debian's libmujoco-dev), an independent simulator: the arm as MJCF
// (same DH frames, masses, inertias, armature and damping), each joint's dry friction as MuJoCo's
// frictionloss (two-sided in MuJoCo: the shoulder gets the side it slides on, the others the
// smaller side, which still holds them), RK4 at 0.1 ms. MuJoCo's friction is a soft constraint
// (a joint that sticks creeps a little), so the shoulder's fall agrees to about 1 %.
TEST(SimulationFriction, PumaShoulderFreeFallAgreesWithMuJoCo) {
  Puma560Model model;
  JointVector q = model.getHomePosition();
  q(1) = 0;
  q(2) = 0.3;
  std::vector<double> friction;
  for (int i = 0; i < 6; ++i) {
    const LinkParameters& l = model.getLink(i);
    friction.push_back(i == 1 ? coulombNeg(l) : std::min(coulombPos(l), coulombNeg(l)));
  }
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("rp_simulation_test_" + std::to_string(::getpid()) + ".xml");
  std::ofstream(file) << test::mjcf(model, true, friction);
  char error[1000] = "";
  mjModel* m = mj_loadXML(file.c_str(), nullptr, error, sizeof error);
  std::filesystem::remove(file);
  ASSERT_NE(m, nullptr) << error;
  m->opt.integrator = mjINT_RK4;
  m->opt.timestep = 1e-4;
  mjData* d = mj_makeData(m);
  for (int i = 0; i < 6; ++i) d->qpos[i] = q(i);
  for (int k = 0; k < 3000; ++k) mj_step(m, d);
  const double mujocoFall = d->qpos[1] - q(1);
  mj_deleteData(d);
  mj_deleteModel(m);

  const JointVector zero = JointVector::Zero(6);
  for (SimulationIntegrator integrator : {SimulationIntegrator::Euler, SimulationIntegrator::RK4}) {
    ManipulatorSimulation sim(model);
    sim.setIntegrator(integrator);
    sim.setState(q, zero);
    for (int k = 0; k < 300; ++k) sim.step(zero, 1e-3);
    const double fall = sim.getTruePosition()(1) - q(1);
    std::printf("  %s: shoulder fell %.2f mrad in 0.3 s, MuJoCo %.2f mrad\n",
                integrator == SimulationIntegrator::RK4 ? "rk4" : "euler", 1e3 * fall, 1e3 * mujocoFall);
    EXPECT_NEAR(fall, mujocoFall, 0.015 * std::abs(mujocoFall));
  }
}

// ---- Joint stops -------------------------------------------------------------------------------

// Every joint of every arm hits each of its stops at 1 rad/s (the other joints at rest, no torque): the stop must send it back no faster than it came, the energy (kinetic
// plus the stop spring's) must never grow, and nothing diverges. The
// impact may whip the other joints (momentum moves through M), but not with energy from nowhere.
TEST(SimulationStops, EveryJointHitsItsStopsWithoutGainingEnergy) {
  for (const auto& arm : allArms()) {
    const int n = arm->getNumberOfJoints();
    // Without gravity (the WAM 7's shoulder cannot hold itself up within its torque limit, so
    // gravity would add energy): the energy is the kinetic energy and the stop springs'.
    std::vector<LinkParameters> links;
    for (int i = 0; i < n; ++i) links.push_back(arm->getLink(i));
    const auto model = std::make_unique<ManipulatorModel>(arm->getName(), links, arm->getBaseTransform(),
                                                          arm->getToolTransform(), Vector<3>());
    ManipulatorData data(*model);
    for (SimulationIntegrator integrator : {SimulationIntegrator::Euler, SimulationIntegrator::RK4}) {
      for (int i = 0; i < n; ++i) {
        for (int side : {-1, 1}) {
          ManipulatorSimulation sim(*model);
          sim.setIntegrator(integrator);
          JointVector q = arm->getHomePosition(), qd = JointVector::Zero(n), tau = JointVector::Zero(n);
          const double limit = side > 0 ? model->getPositionMax()(i) : model->getPositionMin()(i);
          q(i) = limit - side * 0.01;
          qd(i) = side * 1.0;
          sim.setState(q, qd);
          double impact = 0, rebound = 0, fastest = 0, deepest = 0, energy0 = 0, energy = 0;
          auto energyOf = [&](const ManipulatorSimulation& s) {
            const JointVector& v = s.getTrueVelocity();
            double spring = 0;
            for (int j = 0; j < n; ++j) {
              const double x = std::max({0.0, model->getPositionMin()(j) - s.getTruePosition()(j),
                                         s.getTruePosition()(j) - model->getPositionMax()(j)});
              spring += 0.5 * 2e4 * x * x;
            }
            return 0.5 * v.dot(massMatrix(*model, data, s.getTruePosition(), true) * v) + spring;
          };
          energy0 = energyOf(sim);
          bool finite = true;
          for (int k = 0; k < 500; ++k) {
            const double before = sim.getTrueVelocity()(i);
            const bool outside = side * (sim.getTruePosition()(i) - limit) > 0;
            if (!outside && impact == 0 && side * before > 0 && side * (sim.getTruePosition()(i) + 1e-3 * before - limit) > 0)
              impact = std::abs(before);
            sim.step(tau, 1e-3);
            const JointVector& v = sim.getTrueVelocity();
            finite = finite && v.allFinite() && sim.getTruePosition().allFinite();
            fastest = std::max(fastest, v.cwiseAbs().maxCoeff());
            deepest = std::max(deepest, side * (sim.getTruePosition()(i) - limit));
            rebound = std::max(rebound, -side * v(i));
            energy = std::max(energy, energyOf(sim));
          }
          std::printf("  %s %s joint %d %s stop: impact %.3f rad/s, rebound %.3f rad/s, depth %.2g rad, fastest %.3f rad/s, "
                      "largest energy %.3g of %.3g J\n",
                      model->getName().c_str(), integrator == SimulationIntegrator::RK4 ? "rk4" : "euler", i + 1,
                      side > 0 ? "upper" : "lower", impact, rebound, deepest, fastest, energy, energy0);
          ASSERT_TRUE(finite) << model->getName() << " joint " << i + 1;
          EXPECT_GT(impact, 0.5) << model->getName() << " joint " << i + 1 << " should reach its stop";
          EXPECT_LE(rebound, impact) << model->getName() << " joint " << i + 1;
          EXPECT_LE(energy, 1.01 * energy0) << model->getName() << " joint " << i + 1 << ": energy from nowhere";
          EXPECT_LT(fastest, 10.0) << model->getName() << " joint " << i + 1;
          EXPECT_LT(deepest, 0.05) << model->getName() << " joint " << i + 1;
        }
      }
    }
  }
}

// ---- Integrators -------------------------------------------------------------------------------

// 2 s of free motion (no gravity, no friction: the arm coasts, coupled through M and C) from the
// middle of the ranges, against the model's forward dynamics integrated by RK4 at 10 us in the
// test. RK4 at the servo period is far more accurate than Euler.
TEST(SimulationIntegrator, Rk4IsFarMoreAccurateThanEulerInFreeMotion) {
  for (const auto& nominal : allArms()) {
    const int n = nominal->getNumberOfJoints();
    std::vector<LinkParameters> links;
    for (int i = 0; i < n; ++i) {
      LinkParameters l = nominal->getLink(i);
      l.viscousFriction = l.coulombFrictionPositive = l.coulombFrictionNegative = 0;
      links.push_back(l);
    }
    const ManipulatorModel model(nominal->getName(), links, nominal->getBaseTransform(), nominal->getToolTransform(),
                                 Vector<3>());
    JointVector q0(n), v0(n);
    for (int i = 0; i < n; ++i) {
      q0(i) = 0.5 * (model.getPositionMin()(i) + model.getPositionMax()(i));
      v0(i) = (i % 2 ? -0.3 : 0.4);
    }
    // The ground truth.
    ManipulatorData data(model);
    DynamicsOptions options;
    options.motorInertia = true;
    const JointVector zero = JointVector::Zero(n);
    JointVector q = q0, v = v0;
    const double h = 1e-5;
    for (int k = 0; k < 200000; ++k) {
      const JointVector a1 = forwardDynamics(model, data, q, v, zero, options);
      const JointVector v2 = v + 0.5 * h * a1;
      const JointVector a2 = forwardDynamics(model, data, q + 0.5 * h * v, v2, zero, options);
      const JointVector v3 = v + 0.5 * h * a2;
      const JointVector a3 = forwardDynamics(model, data, q + 0.5 * h * v2, v3, zero, options);
      const JointVector v4 = v + h * a3;
      const JointVector a4 = forwardDynamics(model, data, q + h * v3, v4, zero, options);
      q += (h / 6) * (v + 2 * v2 + 2 * v3 + v4);
      v += (h / 6) * (a1 + 2 * a2 + 2 * a3 + a4);
    }
    ASSERT_TRUE(model.isWithinLimits(q)) << "the test motion should stay clear of the stops";
    double error[2];
    for (SimulationIntegrator integrator : {SimulationIntegrator::Euler, SimulationIntegrator::RK4}) {
      ManipulatorSimulation sim(model);
      sim.setIntegrator(integrator);
      sim.setState(q0, v0);
      for (int k = 0; k < 2000; ++k) sim.step(zero, 1e-3);
      error[integrator == SimulationIntegrator::RK4] = (sim.getTruePosition() - q).cwiseAbs().maxCoeff();
    }
    std::printf("  %s: 2 s free motion, largest joint error euler %.3g rad, rk4 %.3g rad\n", model.getName().c_str(),
                error[0], error[1]);
    EXPECT_LT(error[1], 1e-6) << model.getName();
    EXPECT_LT(error[1], 1e-3 * error[0]) << model.getName();
  }
}

// A servo cycle that skipped deadlines integrates the time that passed in a few steps
// (ManipulatorSimulation::advance(): at most 4 periods each), not one step per deadline: the cycle
// after an overrun then costs what any cycle costs. A cycle on time takes the very step step()
// takes; a late one moves the arm through the whole interval, as a fine integration of the same
// interval does (the reference: 0.1 ms steps), with either integrator and every arm, about as
// well as cycles on time every period do.
TEST(SimulationIntegrator, ACycleAfterSkippedDeadlinesIntegratesTheWholeIntervalInAFewSteps) {
  const double dt = 1e-3;
  for (const auto& model : allArms()) {
    const int n = model->getNumberOfJoints();
    JointVector q0(n), v0(n), tau(n);
    for (int i = 0; i < n; ++i) {
      q0(i) = 0.5 * (model->getPositionMin()(i) + model->getPositionMax()(i));
      v0(i) = (i % 2 ? -0.4 : 0.5);
      tau(i) = 0.05 * model->getTorqueLimit()(i);
    }
    ManipulatorData data(*model);
    JointVector gravity(n);
    gravityTorque(*model, data, q0, gravity);
    tau += gravity;  // pushes every joint (the arm starting in the middle of its range)
    for (SimulationIntegrator integrator : {SimulationIntegrator::Euler, SimulationIntegrator::RK4}) {
      for (const auto& [elapsed, steps] : std::vector<std::pair<double, int>>{
               {dt, 1}, {1.4 * dt, 1}, {2 * dt, 1}, {4 * dt, 1}, {5 * dt, 2}, {8 * dt, 2}, {60 * dt, 15}}) {
        const std::string what = model->getName() + (integrator == SimulationIntegrator::RK4 ? " rk4 " : " euler ") +
                                 std::to_string(elapsed / dt) + " periods";
        ManipulatorSimulation late(*model), fine(*model);
        late.setIntegrator(integrator);
        fine.setIntegrator(integrator);
        late.setState(q0, v0);
        fine.setState(q0, v0);
        EXPECT_EQ(late.advance(tau, elapsed, dt), steps) << what;
        if (elapsed < 1.5 * dt) {
          // On time: the step of one period, bit for bit.
          fine.step(tau, dt);
          EXPECT_EQ(late.getTruePosition(), fine.getTruePosition()) << what;
          EXPECT_EQ(late.getTrueVelocity(), fine.getTrueVelocity()) << what;
          continue;
        }
        const int fineSteps = static_cast<int>(std::lround(elapsed / 1e-4));
        for (int k = 0; k < fineSteps; ++k) fine.step(tau, 1e-4);
        ManipulatorSimulation periodic(*model);  // a cycle on time every period
        periodic.setIntegrator(integrator);
        periodic.setState(q0, v0);
        for (int k = 0; k < std::lround(elapsed / dt); ++k) periodic.step(tau, dt);
        const double periodicError = (periodic.getTruePosition() - fine.getTruePosition()).cwiseAbs().maxCoeff();
        const double periodicVelocityError = (periodic.getTrueVelocity() - fine.getTrueVelocity()).cwiseAbs().maxCoeff();
        const double moved = (fine.getTruePosition() - q0).cwiseAbs().maxCoeff();
        const double error = (late.getTruePosition() - fine.getTruePosition()).cwiseAbs().maxCoeff();
        const double velocityChange = (fine.getTrueVelocity() - v0).cwiseAbs().maxCoeff();
        const double velocityError = (late.getTrueVelocity() - fine.getTrueVelocity()).cwiseAbs().maxCoeff();
        std::printf("  %s: moved %.3g rad, error %.2g (periodic %.2g) rad; velocity change %.3g rad/s, error %.2g (%.2g) rad/s\n",
                      what.c_str(), moved, error, periodicError, velocityChange, velocityError, periodicVelocityError);
        // Against the reference, no worse than twice what a first-order method's steps of up to 4
        // periods give over those of one period (a cycle on time every period, whose integration
        // has errors of its own; 4.4 times them at most here, Coulomb friction's switches included).
        const double bound = 2.0 * ManipulatorSimulation::kCatchUpStepPeriods;
        EXPECT_LT(error, bound * periodicError + 1e-6 * moved) << what;
        EXPECT_LT(velocityError, bound * periodicVelocityError + 1e-6 * velocityChange) << what;
      }
    }
  }
  EXPECT_THROW(ManipulatorSimulation(Puma560Model()).advance(JointVector::Zero(6), 1e-3, 0), std::invalid_argument);
}

// The sensors take one reading per period across a late cycle's few steps: a delay of two
// readings is still two periods after 8 periods integrated in two steps (the readings within a
// step interpolated between its ends), not two steps (8 periods) back.
TEST(SimulationIntegrator, ASensorDelayStaysInPeriodsAcrossSkippedDeadlines) {
  Puma560Model model;
  const double dt = 1e-3;
  JointVector q0 = model.getHomePosition(), v0(6), tau = JointVector::Zero(6);
  v0 << 0.5, -0.4, 0.3, 0.8, -0.6, 1.0;
  ManipulatorData data(model);
  gravityTorque(model, data, q0, tau);
  tau(0) += 30;
  ManipulatorSimulation late(model), fine(model);
  late.setSensor(JointVector(), 2);
  late.setState(q0, v0);
  fine.setState(q0, v0);
  ASSERT_EQ(late.advance(tau, 8 * dt, dt), 2);
  for (int k = 0; k < 60; ++k) fine.step(tau, 1e-4);  // 6 periods: two before the end
  const double moved = (fine.getTruePosition() - q0).cwiseAbs().maxCoeff();
  EXPECT_LT((late.getPosition() - fine.getTruePosition()).cwiseAbs().maxCoeff(), 0.01 * moved);
  EXPECT_LT((late.getVelocity() - fine.getTrueVelocity()).cwiseAbs().maxCoeff(), 0.01);
}

// ---- A plant that differs from the controller's model -------------------------------------------

const ConfigSection& section(const Configuration& config) { return config.sections().front(); }

TEST(SimulationPlant, DeviationsFromRpCfgChangeThePlantOnly) {
  Puma560Model nominal;
  const Configuration config = Configuration::parse(
      "[puma]\nclass Puma560\nsimMassScale 1.1\nsimInertiaScale 1.2\nsimFrictionScale 1.3\nsimPayload 2\n"
      "integrator euler\n", "rp.cfg");
  const std::unique_ptr<ManipulatorSimulation> sim = makeSimulation(nominal, &section(config));
  const ManipulatorModel& plant = sim->getModel();
  ASSERT_NE(&plant, &nominal);
  EXPECT_EQ(sim->getIntegrator(), SimulationIntegrator::Euler);
  const Puma560Model fresh;
  for (int i = 0; i < 6; ++i) {
    const LinkParameters &p = plant.getLink(i), &l = nominal.getLink(i);
    EXPECT_EQ(l.mass, fresh.getLink(i).mass) << "the controller's model is unchanged";
    EXPECT_EQ(Eigen::Matrix3d(l.inertia), Eigen::Matrix3d(fresh.getLink(i).inertia));
    if (i < 5) {
      EXPECT_DOUBLE_EQ(p.mass, 1.1 * l.mass);
      EXPECT_TRUE(Eigen::Matrix3d(p.inertia).isApprox(1.2 * Eigen::Matrix3d(l.inertia)));
    } else {
      EXPECT_DOUBLE_EQ(p.mass, 1.1 * l.mass + 2);  // the payload rides on the last link
    }
    EXPECT_DOUBLE_EQ(p.viscousFriction, 1.3 * l.viscousFriction);
    EXPECT_DOUBLE_EQ(p.coulombFrictionPositive, 1.3 * l.coulombFrictionPositive);
  }
  // The payload: a point mass at the tool frame's origin. Its gravity torque is that of the mass
  // there: the plant's gravity torque minus the scaled links' is J_v^T (0, 0, m g).
  const JointVector q = nominal.getHomePosition();
  const Configuration noPayload = Configuration::parse("[puma]\nclass Puma560\nsimMassScale 1.1\n", "rp.cfg");
  const auto scaled = makeSimulation(nominal, &section(noPayload));
  ManipulatorData d1(plant), d2(scaled->getModel()), d3(nominal);
  JointVector g1, g2;
  gravityTorque(plant, d1, q, g1);
  gravityTorque(scaled->getModel(), d2, q, g2);
  Vector<6> weight;
  weight(2) = -2 * 9.81;
  const JointVector expected = jacobian(nominal, d3, q, ReferenceFrame::Base).transpose() * weight;
  EXPECT_LT((g1 - g2 + expected).cwiseAbs().maxCoeff(), 1e-9) << "payload torque";
}

TEST(SimulationPlant, SwitchesSensorsAndInitialState) {
  Puma560Model nominal;
  const Configuration config = Configuration::parse(
      "[puma]\nclass Puma560\nsimFriction off\nsimMotorInertia off\nsimCountsPerRadian 1000\nsimSensorDelay 3\n"
      "simInitialPosition 10 20 -30 0 40 0\nsimInitialVelocity 0 0 0 0 0 30\n", "rp.cfg");
  const auto sim = makeSimulation(nominal, &section(config));
  for (int i = 0; i < 6; ++i) {
    EXPECT_EQ(sim->getModel().getLink(i).coulombFrictionPositive, 0);
    EXPECT_EQ(sim->getModel().getLink(i).viscousFriction, 0);
    EXPECT_EQ(sim->getModel().getArmatureInertia()(i), 0);
    EXPECT_GT(nominal.getArmatureInertia()(i), 0);
  }
  const double deg = std::acos(-1.0) / 180;
  EXPECT_DOUBLE_EQ(sim->getTruePosition()(1), 20 * deg);
  EXPECT_DOUBLE_EQ(sim->getTrueVelocity()(5), 30 * deg);
  // Quantised to 1/1000 rad (the count below), and three steps old.
  std::vector<JointVector> truth{sim->getTruePosition()};
  JointVector tau;
  ManipulatorData data(sim->getModel());
  for (int k = 0; k < 10; ++k) {
    gravityTorque(sim->getModel(), data, sim->getTruePosition(), tau);
    sim->step(tau, 1e-3);
    truth.push_back(sim->getTruePosition());
    const JointVector& read = sim->getPosition();
    const JointVector& old = truth[static_cast<std::size_t>(std::max(0, k + 1 - 3))];
    for (int i = 0; i < 6; ++i) {
      EXPECT_EQ(read(i), std::floor(old(i) * 1000) / 1000) << "step " << k << " joint " << i + 1;
      EXPECT_NEAR(std::round(read(i) * 1000), read(i) * 1000, 1e-9);
    }
  }
  EXPECT_NE(sim->getPosition()(5), sim->getTruePosition()(5));
  // A start beyond a joint's velocity limit is refused at the setting's line (it used to be taken,
  // and the arm shut down in its first cycle; 1e6 deg/s gave NaN joints).
  for (const char* v : {"1000 0 0 0 0 0", "0 0 0 0 0 -1000000"}) {
    const Configuration fast = Configuration::parse(std::string("[puma]\nclass Puma560\nsimInitialVelocity ") + v + "\n", "rp.cfg");
    try {
      (void)makeSimulation(nominal, &section(fast));
      ADD_FAILURE() << v << " was accepted";
    } catch (const ConfigError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("rp.cfg:3: simInitialVelocity: joint ", 0), 0u) << e.what();
      EXPECT_NE(std::string(e.what()).find("deg/s is beyond its velocity limit"), std::string::npos) << e.what();
    }
  }
}

// simEncoderOffset: the readings are the plant's position plus the offset (degrees in rp.cfg),
// then quantised; the plant itself does not move.
TEST(SimulationPlant, EncoderOffsetShiftsTheReadingsOnly) {
  Puma560Model nominal;
  const Configuration config = Configuration::parse(
      "[puma]\nclass Puma560\nsimEncoderOffset 0 0.5 -0.25 0 0 1\nsimCountsPerRadian 100000\n", "rp.cfg");
  const auto sim = makeSimulation(nominal, &section(config));
  const double deg = std::acos(-1.0) / 180;
  EXPECT_EQ(sim->getTruePosition(), nominal.getHomePosition()) << "the plant starts at home";
  const double offset[6] = {0, 0.5 * deg, -0.25 * deg, 0, 0, 1 * deg};
  for (int i = 0; i < 6; ++i) {
    EXPECT_DOUBLE_EQ(sim->getEncoderOffset()(i), offset[i]);
    EXPECT_EQ(sim->getPosition()(i), std::floor((sim->getTruePosition()(i) + offset[i]) * 1e5) / 1e5) << i + 1;
  }
  JointVector wrong(5);
  EXPECT_THROW(sim->setEncoderOffset(wrong), std::invalid_argument);
  JointVector infinite = JointVector::Zero(6);
  infinite(2) = std::numeric_limits<double>::infinity();
  EXPECT_THROW(sim->setEncoderOffset(infinite), std::invalid_argument);
  try {
    const Configuration bad = Configuration::parse("[puma]\nclass Puma560\nsimEncoderOffset 0.1 0.2\n", "rp.cfg");
    (void)makeSimulation(nominal, &section(bad));
    ADD_FAILURE() << "no error for two offsets on six joints";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("rp.cfg:3:"), std::string::npos) << e.what();
  }
}

TEST(SimulationPlant, BadSettingsAreConfigErrorsWithTheLine) {
  Puma560Model nominal;
  auto expectError = [&](const std::string& text, const std::string& where) {
    try {
      const Configuration config = Configuration::parse(text, "rp.cfg");
      (void)makeSimulation(nominal, &section(config));
      ADD_FAILURE() << "no error for:\n" << text;
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(where), std::string::npos) << e.what();
    }
  };
  expectError("[puma]\nclass Puma560\nsimMassScale 1 1 1\n", "rp.cfg:3:");
  expectError("[puma]\nclass Puma560\nsimMassScale -1\n", "rp.cfg:3:");
  expectError("[puma]\nclass Puma560\n\nsimInitialPosition 0 0\n", "rp.cfg:4:");
  expectError("[puma]\nclass Puma560\nsimInitialPosition 0 0 0 0 0 500\n", "rp.cfg:3:");
  expectError("[puma]\nclass Puma560\nsimSensorDelay 100\n", "rp.cfg:3:");
  expectError("[puma]\nclass Puma560\nintegrator midpoint\n", "rp.cfg:3:");
  expectError("[puma]\nclass Puma560\nsimCountsPerRadian 0\n", "rp.cfg:3:");
  // Unchecked by the schema (a configuration read without the class checks), makeSimulation's
  // own checks still name the line of the setting at fault.
  Configuration::Options unchecked;
  unchecked.checkClasses = false;
  unchecked.loadPlugins = false;
  for (const auto& [text, where] : std::vector<std::pair<std::string, std::string>>{
           {"[puma]\nclass Puma560\nsimMassScale 1.1\nsimPayload -3\n", "rp.cfg:4:"},
           {"[puma]\nclass Puma560\nsimFrictionScale -1\nsimPayload 3\n", "rp.cfg:3:"},
           {"[puma]\nclass Puma560\nsimCountsPerRadian 100\nsimSensorDelay 17\n", "rp.cfg:4:"}}) {
    try {
      const Configuration config = Configuration::parse(text, "rp.cfg", unchecked);
      (void)makeSimulation(nominal, &section(config));
      ADD_FAILURE() << "no error for:\n" << text;
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(where), std::string::npos) << e.what();
    }
  }
}

// PD control with inverse-dynamics feed-forward (with friction) from the nominal model
// along a 2 s cosine on every joint: a plant with 10 % heavier links tracks worse than the nominal
// plant, which the controller's model cancels.
double trackingError(ManipulatorSimulation& sim, const ManipulatorModel& controllerModel) {
  const int n = controllerModel.getNumberOfJoints();
  ManipulatorData data(controllerModel);
  DynamicsOptions options;
  options.motorInertia = true;
  options.friction = true;
  const JointVector q0 = controllerModel.getHomePosition();
  const JointVector m = massMatrix(controllerModel, data, q0, true).diagonal();
  sim.setState(q0, JointVector::Zero(n));
  double worst = 0;
  JointVector qd(n), vd(n), ad(n);
  for (int k = 0; k < 2500; ++k) {
    const double t = k * 1e-3, w = std::acos(-1.0);
    for (int i = 0; i < n; ++i) {
      const double a = t < 2 ? 0.1 : 0;
      qd(i) = q0(i) + a * (1 - std::cos(w * t));
      vd(i) = a * w * std::sin(w * t);
      ad(i) = a * w * w * std::cos(w * t);
    }
    const JointVector& q = sim.getPosition();
    const JointVector& v = sim.getVelocity();
    worst = std::max(worst, (qd - q).cwiseAbs().maxCoeff());
    const JointVector ff = inverseDynamics(controllerModel, data, q, vd, ad, options);
    JointVector tau = ff;
    for (int i = 0; i < n; ++i) tau(i) += m(i) * (625 * (qd(i) - q(i)) + 50 * (vd(i) - v(i)));
    sim.step(tau, 1e-3);
  }
  return worst;
}

TEST(SimulationPlant, HeavierLinksTrackWorseUnderTheNominalController) {
  Puma560Model nominal;
  const double massBefore = nominal.getLink(2).mass;
  ManipulatorSimulation same(nominal);
  const double e0 = trackingError(same, nominal);
  const Configuration config = Configuration::parse("[puma]\nclass Puma560\nsimMassScale 1.1\nsimInertiaScale 1.1\n", "rp.cfg");
  const auto heavy = makeSimulation(nominal, &section(config));
  const double e1 = trackingError(*heavy, nominal);
  std::printf("  largest tracking error: nominal plant %.3g mrad, 10%% heavier links %.3g mrad\n", 1e3 * e0, 1e3 * e1);
  EXPECT_GT(e1, 1.5 * e0);
  EXPECT_EQ(nominal.getLink(2).mass, massBefore);
}

// Figure 23 of the paper: a real and a simulated Puma; in rp.cfg the simulated one gets a plant
// of its own. Through DefaultManipulator: its model (the controller's) stays nominal, the plant
// starts where rp.cfg puts it and deviates.
using SimulationPlantArm = test::SimulatedArmTest;
TEST_F(SimulationPlantArm, DefaultManipulatorTakesItsPlantFromRpCfg) {
  RoboticPlatform::setConfiguration(Configuration::parse(
      "[pumaSimulated]\nclass Puma560\nsimMassScale 1.1\nsimInitialPosition 0 30 -60 0 10 0\n"
      "simCountsPerRadian 1000\n", "rp.cfg"));
  Puma560 arm("pumaSimulated");
  const Puma560Model fresh;
  for (int i = 0; i < 6; ++i) EXPECT_EQ(arm.getModel().getLink(i).mass, fresh.getLink(i).mass);
  const double deg = std::acos(-1.0) / 180;
  // Where rp.cfg puts it, as 1000-count-per-radian encoders read it.
  const JointVector q = arm.getJointPosition();
  EXPECT_EQ(q(1), std::floor(30 * deg * 1000) / 1000);
  EXPECT_EQ(q(2), std::floor(-60 * deg * 1000) / 1000);
  EXPECT_EQ(q(4), std::floor(10 * deg * 1000) / 1000);
  EXPECT_NE(q(1), 30 * deg);
  // Running, the readings stay on the encoder's grid.
  ASSERT_TRUE(arm.waitForCycles(50));
  const JointVector later = arm.getJointPosition();
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(std::round(later(i) * 1000), later(i) * 1000, 1e-6) << "joint " << i + 1;
}

// Through the WAM object (servo loop, limit checks, damped hold), not the bare plant: its light
// wrist joint 7 driven at 0.8 rad/s into its upper stop. The position limit is a fault; the hold
// stops the joint at the stop without bouncing back (before the stops were dissipative, 2 of 8
// runs published joint 7 at -80.7 rad/s here), then the power goes off.
TEST_F(SimulationPlantArm, TheWamsWristRunsIntoItsStopAndComesToRest) {
  for (SimulationIntegrator integrator : {SimulationIntegrator::RK4, SimulationIntegrator::Euler}) {
    ObjectManager::resetShutdown();
    RoboticPlatform::setConfiguration(Configuration::parse(
        std::string("[wam]\nclass WAM\nintegrator ") + (integrator == SimulationIntegrator::RK4 ? "rk4" : "euler") + "\n",
        "rp.cfg"));
    WAM wam("wam", 7);
    const double limit = wam.getModel().getPositionMax()(6);
    test::JointRamp ramp(6, 0.8);
    test::simClock().pause();
    wam.setTrajectoryGenerator(ramp);
    double fastest = 0, deepest = -1;
    bool finite = true;
    int cycles = 0;
    for (; cycles < 20000 && !wam.isShutdownComplete(); ++cycles) {
      ASSERT_TRUE(wam.runCycles(1, 10));
      const JointVector q = wam.getJointPosition(), qd = wam.getJointVelocity();
      finite = finite && q.allFinite() && qd.allFinite();
      fastest = std::max(fastest, qd.cwiseAbs().maxCoeff());
      deepest = std::max(deepest, q(6) - limit);
    }
    test::simClock().resume();
    std::printf("  WAM 7 (%s) joint 7 into its stop: %d cycles, fastest joint %.3f rad/s, %.4f rad beyond the limit\n",
                integrator == SimulationIntegrator::RK4 ? "rk4" : "euler", cycles, fastest, deepest);
    EXPECT_TRUE(finite);
    EXPECT_TRUE(wam.isShutdownComplete()) << "the position limit did not stop the system";
    EXPECT_NE(ObjectManager::getShutdownReason().find("joint 7"), std::string::npos) << ObjectManager::getShutdownReason();
    EXPECT_GT(deepest, 0.0) << "joint 7 never reached its limit";
    EXPECT_LT(deepest, 0.05) << "joint 7 went far into its stop";
    EXPECT_LT(fastest, 1.6) << "a joint was flung (twice the driven speed)";
    EXPECT_LT(wam.getJointVelocity().cwiseAbs().maxCoeff(), 1e-2) << "not at rest when the power went off";
    EXPECT_FALSE(wam.isArmPowerOn());
    wam.clearTrajectoryGenerator();
  }
}

// ---- Real time ---------------------------------------------------------------------------------

TEST(SimulationRealTime, SteppingDoesNotAllocate) {
  Puma560Model nominal;
  const Configuration config = Configuration::parse(
      "[puma]\nclass Puma560\nsimMassScale 1.1\nsimCountsPerRadian 2000\nsimSensorDelay 2\n", "rp.cfg");
  for (SimulationIntegrator integrator : {SimulationIntegrator::Euler, SimulationIntegrator::RK4}) {
    const auto sim = makeSimulation(nominal, &section(config));
    sim->setIntegrator(integrator);
    JointVector q = nominal.getHomePosition(), tau = JointVector::Zero(6);
    q(1) = nominal.getPositionMax()(1) - 1e-3;
    JointVector qd = JointVector::Zero(6);
    qd(1) = 1;
    sim->setState(q, qd);  // into a stop: sub-steps, implicit stop, friction
    Vector<6> push;
    push(0) = 5;
    sim->setExternalWrench(push);
    Vector<3> centre;
    centre(2) = 0.1;
    sim->setPayload(2.0, centre);  // builds the unit payload model of this centre
    test::AllocationGuard guard;
    for (int k = 0; k < 200; ++k) {
      sim->setBrakes(k > 100);
      if (k == 50) sim->setPayload(0.5, centre);  // a centre used before: nothing to build
      if (k == 150) sim->setPayload(0, centre);
      if (k % 40 == 39) {
        sim->advance(tau, 7e-3, 1e-3);  // a late cycle's few steps, with readings between them
      } else {
        sim->step(tau, 1e-3);
      }
      if (k % 3 == 0) {
        EXPECT_TRUE(sim->getAcceleration().allFinite());  // (solved for when asked after an Euler step)
      }
    }
    EXPECT_EQ(guard.count(), 0u);
    EXPECT_GT(sim->getLastSubsteps(), 0);
  }
}

// Many arms in one thread share one workspace for their steps' forward dynamics (an arm's own
// data is cold by its next cycle when an executor steps hundreds). Arms of 6, 7 and 4 joints and a
// second Puma with heavier links, stepped in turn in one thread, each under its own torques: every
// state of every step must be bit for bit the one the arm reaches stepped on its own, and the
// turns (which make the workspace again for each new number of joints) allocate nothing.
TEST(SimulationRealTime, ArmsSteppedInTurnInOneThreadMoveAsEachAlone) {
  const Puma560Model puma;
  const WAM7Model wam7;
  const WAM4Model wam4;
  const Configuration heavy = Configuration::parse("[puma]\nclass Puma560\nsimMassScale 1.3\n", "rp.cfg");
  constexpr int kSteps = 300;
  for (SimulationIntegrator integrator : {SimulationIntegrator::Euler, SimulationIntegrator::RK4}) {
    auto make = [&] {
      std::vector<std::unique_ptr<ManipulatorSimulation>> arms;
      arms.push_back(std::make_unique<ManipulatorSimulation>(puma));
      arms.push_back(std::make_unique<ManipulatorSimulation>(wam7));
      arms.push_back(makeSimulation(puma, &section(heavy)));
      arms.push_back(std::make_unique<ManipulatorSimulation>(wam4));
      for (auto& a : arms) a->setIntegrator(integrator);
      return arms;
    };
    // Torques that move every joint of arm a at step k (away from gravity's rest, through friction).
    auto torque = [](int a, int k, int n) {
      JointVector tau(n);
      for (int i = 0; i < n; ++i) tau(i) = 3.0 * std::sin(0.02 * k + 0.7 * i + a);
      return tau;
    };
    // Alone: each arm's whole run in a thread of its own (whose workspace no other arm uses).
    std::vector<std::vector<JointVector>> alone(4);
    {
      auto arms = make();
      for (int a = 0; a < 4; ++a) {
        std::thread([&, a] {
          ManipulatorSimulation& s = *arms[static_cast<std::size_t>(a)];
          for (int k = 0; k < kSteps; ++k) {
            s.step(torque(a, k, s.getModel().getNumberOfJoints()), 1e-3);
            alone[static_cast<std::size_t>(a)].push_back(s.getTruePosition());
            alone[static_cast<std::size_t>(a)].push_back(s.getTrueVelocity());
          }
        }).join();
      }
    }
    // In turn: one step of each arm, then the next step.
    auto arms = make();
    std::vector<std::vector<JointVector>> torques(4);
    for (int a = 0; a < 4; ++a)
      for (int k = 0; k < kSteps; ++k)
        torques[static_cast<std::size_t>(a)].push_back(
            torque(a, k, arms[static_cast<std::size_t>(a)]->getModel().getNumberOfJoints()));
    std::vector<JointVector> states(4 * 2 * kSteps);
    for (JointVector& v : states) v = JointVector::Zero(7);
    test::AllocationGuard guard;
    for (int k = 0; k < kSteps; ++k) {
      for (int a = 0; a < 4; ++a) {
        ManipulatorSimulation& s = *arms[static_cast<std::size_t>(a)];
        s.step(torques[static_cast<std::size_t>(a)][static_cast<std::size_t>(k)], 1e-3);
        states[static_cast<std::size_t>((a * kSteps + k) * 2)] = s.getTruePosition();
        states[static_cast<std::size_t>((a * kSteps + k) * 2 + 1)] = s.getTrueVelocity();
      }
    }
    EXPECT_EQ(guard.count(), 0u);
    for (int a = 0; a < 4; ++a) {
      for (int k = 0; k < 2 * kSteps; ++k) {
        const JointVector& expected = alone[static_cast<std::size_t>(a)][static_cast<std::size_t>(k)];
        const JointVector& got = states[static_cast<std::size_t>(a * 2 * kSteps + k)];
        ASSERT_TRUE(got == expected) << "arm " << a << (k % 2 ? " velocity" : " position") << " after step "
                                     << k / 2 + 1 << ": " << got.transpose() << " alone " << expected.transpose();
      }
    }
    // The arms moved: the comparison is not of resting arms.
    for (int a = 0; a < 4; ++a)
      EXPECT_GT((alone[static_cast<std::size_t>(a)].back()).cwiseAbs().maxCoeff(), 0.1) << "arm " << a;
  }
}

}  // namespace
}  // namespace rp
