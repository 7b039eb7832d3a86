// Step and trajectory tracking of simulated arms under DefaultPositionControl, against bounds
// derived from the control law and the model (not tuned to the observed errors).
//
// The derivation. With e = q_d - q, the arm M qdd + C qd + g + B qd + F_c sgn(qd) = tau under
// tau = K_p e + K_d (qd_d - qd) + K_i int e + B qd_d + F_c tanh(qd_d / eps) + g gives, per joint i,
//   m_i e'' + (K_d + B) e' + K_p e + K_i int e = d_i,
//   d_i = [M qdd_d + C qd_d]_i - sum_{j != i} M_ij e''_j + (Coulomb mismatch, |.| <= 2 F_c)
// with m_i = M_ii. The servo loop is discrete (1 ms, the simulation's semi-implicit Euler step
// after the control), so each joint is a linear discrete system from d to e. Its impulse response
// h_k (computed below by running that recursion) bounds the error for any disturbance with
// |d| <= D: |e| <= D sum |h_k| = L1 D (the peak-to-peak gain). A step of size s adds the
// recursion's own step response. The error some time T after the disturbance has ended is bounded
// by the tail of the same sum (lags >= T). D is evaluated along the desired motion; a factor 1.2 covers
// evaluating M and C there instead of along the actual motion and the e''_j coupling, which the
// observed errors (printed) show to be far smaller than the bound's main terms.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numbers>

#include "SimulatedArmTest.hpp"
#include "rp/RoboticPlatform.hpp"

namespace rp {
namespace {

using test::simClock;
using TrackingTest = test::SimulatedArmTest;

// One joint's discrete servo loop: control on (e, e'), then semi-implicit Euler of
// m a = u + d - b v over the period dt, exactly as DefaultManipulator and ManipulatorSimulation.
struct JointLoop {
  double m, b, kp, kd, ki, dt;

  // Runs the loop for `steps` with reference r (a step of `target` from 0) and disturbance
  // `disturbance(k)`; returns the position history's extremes through the callbacks.
  template <class Disturbance, class Visit>
  void run(double target, int steps, Disturbance disturbance, Visit visit) const {
    double q = 0, v = 0, integral = 0;
    for (int k = 0; k < steps; ++k) {
      const double e = target - q;
      integral += e * dt;
      const double u = kp * e - kd * v + ki * integral;
      const double a = (u + disturbance(k) - b * v) / m;
      v += dt * a;
      q += dt * v;
      visit(q, a);
    }
  }
  // L1 norm of the response of q (rad) to a unit torque (N m) held for one period: the
  // peak-to-peak gain from a disturbance torque to the error, in rad per N m. With `from` > 0,
  // only the lags from `from` periods on: it bounds the error `from` periods after a disturbance
  // has ended.
  double l1Gain(int from = 0) const {
    double sum = 0;
    int k = 0;
    run(0.0, 20000, [](int j) { return j == 0 ? 1.0 : 0.0; }, [&](double q, double) {
      if (k++ >= from) sum += std::abs(q);
    });
    return sum;
  }
};

JointLoop jointLoop(const ManipulatorModel& model, DefaultPositionControl& pid, const JointVector& q, int i,
                    double dt) {
  ManipulatorData data(model);
  const JointMatrix& M = massMatrix(model, data, q, true);
  const LinkParameters& l = model.getLink(i);
  return {M(i, i), l.viscousFriction * l.gearRatio * l.gearRatio, pid.getKp()(i), pid.getKd()(i), pid.getKi()(i),
          dt};
}

double coulomb(const LinkParameters& l) {
  return std::abs(l.gearRatio) * std::max(l.coulombFrictionPositive, -l.coulombFrictionNegative);
}

// q_d = q0 + A (1 - cos(w t)) on every joint for one period from `start`, then q0 again.
class CosineGenerator : public TrajectoryGenerator {
 public:
  CosineGenerator(const JointVector& q0, const JointVector& amplitude, double w)
      : q0_(q0), amplitude_(amplitude), w_(w) {}
  ~CosineGenerator() override { releaseFromManipulators(); }
  void at(double t, Setpoint& sp) const {
    const double period = 2 * std::numbers::pi / w_;
    sp.position = q0_;
    sp.velocity.setZero(q0_.size());
    sp.acceleration.setZero(q0_.size());
    if (t < 0 || t > period) return;
    for (int i = 0; i < q0_.size(); ++i) {
      sp.position(i) += amplitude_(i) * (1 - std::cos(w_ * t));
      sp.velocity(i) = amplitude_(i) * w_ * std::sin(w_ * t);
      sp.acceleration(i) = amplitude_(i) * w_ * w_ * std::cos(w_ * t);
    }
  }
  bool getCurrentSetpoint(double time, Setpoint& sp) override {
    if (t0_ < 0) t0_ = time;
    at(time - t0_, sp);
    return true;
  }
  double period() const { return 2 * std::numbers::pi / w_; }

 private:
  JointVector q0_, amplitude_;
  double w_;
  double t0_ = -1;
};

// Wraps the default control and records, per joint, the largest |q_d - q| and the largest
// q - q_final past the final target, over the cycles it runs; stops recording after `cycles`.
class ErrorProbe : public test::WrappedControl {
 public:
  ErrorProbe(ServoControl& inner, std::uint64_t cycles, const JointVector& finalTarget)
      : WrappedControl(inner), cycles_(cycles), final_(finalTarget) {
    maxError_.setZero(finalTarget.size());
    overshoot_.setZero(finalTarget.size());
  }
  ~ErrorProbe() override { release(); }

  void calculate() override {
    if (count_ < cycles_) {
      const JointVector q = d_manipulator->getJointPosition();
      const JointVector e = d_manipulator->getSetpoint().position - q;
      maxError_ = maxError_.cwiseMax(e.cwiseAbs());
      overshoot_ = overshoot_.cwiseMax(q - final_);
      lastError_ = e;
      if (++count_ == cycles_) done_.store(true);
    }
    inner().calculate();
  }
  bool done() const { return done_.load(); }
  JointVector maxError_, overshoot_, lastError_;

 private:
  std::uint64_t cycles_, count_ = 0;
  JointVector final_;
  std::atomic<bool> done_{false};
};

template <class Arm>
void trackCosine(Arm& arm, double amplitude) {
  const ManipulatorModel& model = arm.getModel();
  const int n = model.getNumberOfJoints();
  const double dt = arm.getServoPeriod();
  ASSERT_TRUE(arm.waitForCycles(5));
  simClock().pause();
  const JointVector q0 = arm.getJointPosition();
  JointVector amp(n);
  for (int i = 0; i < n; ++i) {
    // Towards the middle of the range, so that the motion stays clear of the stops.
    const double middle = 0.5 * (model.getPositionMin()(i) + model.getPositionMax()(i));
    amp(i) = q0(i) < middle ? amplitude : -amplitude;
  }
  const double w = std::numbers::pi;  // one period of 2 s
  CosineGenerator gen(q0, amp, w);
  DefaultPositionControl& pid = arm.getDefaultPositionControl();
  const auto cycles = static_cast<std::uint64_t>(std::llround(gen.period() / dt)) + 1000;
  ErrorProbe probe(pid, cycles, q0);
  arm.setServoControl(probe);
  arm.setTrajectoryGenerator(gen);

  // The bound: D_i = max over the motion of |[M qdd_d + C qd_d]_i| + 2 F_c,i, with L1 from the
  // joint's discrete loop at the largest and smallest m_i along the motion.
  ManipulatorData data(model);
  DynamicsOptions options;
  options.gravity = false;
  options.motorInertia = true;
  JointVector D = JointVector::Zero(n), bound(n), finalBound(n);
  Setpoint sp;
  for (double t = 0; t <= gen.period(); t += 0.01) {
    gen.at(t, sp);
    D = D.cwiseMax(inverseDynamics(model, data, sp.position, sp.velocity, sp.acceleration, options).cwiseAbs());
  }
  for (int i = 0; i < n; ++i) {
    double l1 = 0, tail = 0;
    for (double t = 0; t <= gen.period(); t += 0.05) {
      gen.at(t, sp);
      const JointLoop loop = jointLoop(model, pid, sp.position, i, dt);
      l1 = std::max(l1, loop.l1Gain());
      tail = std::max(tail, loop.l1Gain(1000));
    }
    bound(i) = 1.2 * l1 * (D(i) + 2 * coulomb(model.getLink(i)));
    // One second after the motion the inertial and Coriolis disturbance has been gone for 1000
    // periods: what remains of it is bounded by the tail of the impulse response; Coulomb
    // friction can hold the joint anywhere in the PD's dead band F_c / K_p.
    finalBound(i) = 1.2 * tail * D(i) + coulomb(model.getLink(i)) / pid.getKp()(i);
  }

  simClock().resume();
  while (!probe.done()) ASSERT_TRUE(arm.waitForCycles(100));
  for (int i = 0; i < n; ++i) {
    std::printf("  joint %d: max tracking error %.3g rad (bound %.3g), final error %.3g rad (bound %.3g)\n", i + 1,
                probe.maxError_(i), bound(i), std::abs(probe.lastError_(i)), finalBound(i));
    EXPECT_LE(probe.maxError_(i), bound(i)) << "joint " << i + 1;
    EXPECT_LE(std::abs(probe.lastError_(i)), finalBound(i)) << "joint " << i + 1;
  }
  EXPECT_EQ(arm.getErrorCode(), 0) << arm.getErrorStatus().message;
}

TEST_F(TrackingTest, PumaTracksASmoothMotionWithinTheDerivedBound) {
  Puma560 puma;
  trackCosine(puma, 0.2);  // 0.4 rad travel, peak 0.63 rad/s, 1.97 rad/s^2
}

TEST_F(TrackingTest, Wam7TracksASmoothMotionWithinTheDerivedBound) {
  WAM wam("", 7);
  trackCosine(wam, 0.2);
}

TEST_F(TrackingTest, PumaStepOvershootAndFinalErrorWithinTheDerivedBounds) {
  // A 0.02 rad step on every joint at once. Per joint, the bound on the overshoot is the
  // decoupled discrete loop's own overshoot for that step, plus L1 (D_i + F_c,i), where D_i bounds
  // the coupling torques sum_{j != i} |M_ij| max|qdd_j| + |C qd| with the accelerations and speeds
  // taken from the decoupled loops' step responses (times 1.2, as above); Coulomb friction
  // enters once, since with qd_d = 0 it only opposes the motion. Final error (after 2 s): the
  // Coulomb dead band F_c / K_p.
  Puma560 puma;
  const ManipulatorModel& model = puma.getModel();
  const int n = 6;
  const double dt = puma.getServoPeriod(), step = 0.02;
  ASSERT_TRUE(puma.waitForCycles(5));
  simClock().pause();
  const JointVector q0 = puma.getJointPosition();
  const JointVector target = q0 + JointVector::Constant(n, step);
  DefaultPositionControl& pid = puma.getDefaultPositionControl();

  JointVector ownOvershoot(n), maxAcceleration(n), maxSpeed(n);
  std::vector<JointLoop> loops;
  for (int i = 0; i < n; ++i) {
    loops.push_back(jointLoop(model, pid, q0, i, dt));
    double peak = 0, amax = 0, vmax = 0, previous = 0;
    loops.back().run(step, 2000, [](int) { return 0.0; }, [&](double q, double a) {
      peak = std::max(peak, q - step);
      amax = std::max(amax, std::abs(a));
      vmax = std::max(vmax, std::abs(q - previous) / dt);
      previous = q;
    });
    ownOvershoot(i) = peak;
    maxAcceleration(i) = amax;
    maxSpeed(i) = vmax;
  }
  ManipulatorData data(model);
  const JointMatrix M = massMatrix(model, data, q0, true);
  DynamicsOptions options;
  options.gravity = false;
  const JointVector velocityTorque = inverseDynamics(model, data, q0, maxSpeed, JointVector::Zero(n), options);
  JointVector overshootBound(n);
  for (int i = 0; i < n; ++i) {
    double D = std::abs(velocityTorque(i));
    for (int j = 0; j < n; ++j) {
      if (j != i) D += std::abs(M(i, j)) * maxAcceleration(j);
    }
    overshootBound(i) = ownOvershoot(i) + 1.2 * loops[static_cast<std::size_t>(i)].l1Gain() * (D + coulomb(model.getLink(i)));
  }

  class Step : public TrajectoryGenerator {
   public:
    explicit Step(const JointVector& t) : t_(t) {}
    ~Step() override { releaseFromManipulators(); }
    bool getCurrentSetpoint(double, Setpoint& sp) override {
      sp.position = t_;
      return true;
    }

   private:
    JointVector t_;
  } gen(target);
  ErrorProbe probe(pid, 2000, target);
  puma.setServoControl(probe);
  puma.setTrajectoryGenerator(gen);
  simClock().resume();
  while (!probe.done()) ASSERT_TRUE(puma.waitForCycles(100));
  for (int i = 0; i < n; ++i) {
    const double band = coulomb(model.getLink(i)) / pid.getKp()(i);
    std::printf("  joint %d: overshoot %.3g rad (bound %.3g, decoupled loop alone %.3g), final error %.3g (bound %.3g)\n",
                i + 1, std::max(0.0, probe.overshoot_(i)), overshootBound(i), ownOvershoot(i),
                std::abs(probe.lastError_(i)), band);
    EXPECT_LE(probe.overshoot_(i), overshootBound(i)) << "joint " << i + 1;
    EXPECT_LE(std::abs(probe.lastError_(i)), band) << "joint " << i + 1;
  }
  EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
}

}  // namespace
}  // namespace rp
