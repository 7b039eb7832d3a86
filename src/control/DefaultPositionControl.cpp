// PID position control with friction compensation (rp/control/DefaultPositionControl.hpp).
#include "rp/control/DefaultPositionControl.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "rp/manipulator/Manipulator.hpp"
#include "rp/model/Dynamics.hpp"
#include "rp/trajectory/Setpoint.hpp"

namespace rp {

DefaultPositionControl::DefaultPositionControl(const std::string& name) : ServoControl(name) {}

void DefaultPositionControl::attach(Manipulator& manipulator) {
  ServoControl::attach(manipulator);
  const ManipulatorModel& model = manipulator.getModel();
  const int n = model.getNumberOfJoints();
  period_ = manipulator.getServoPeriod();
  for (JointVector* v : {&integral_, &tau_, &viscous_, &coulombPos_, &coulombNeg_, &limit_}) v->setZero(n);
  for (int i = 0; i < n; ++i) {
    const LinkParameters& l = model.getLink(i);
    const double g = std::abs(l.gearRatio);
    viscous_(i) = l.viscousFriction * g * g;
    coulombPos_(i) = g * l.coulombFrictionPositive;
    coulombNeg_(i) = g * l.coulombFrictionNegative;
    limit_(i) = model.getTorqueLimit()(i);
  }
  if (!gainsSet_ || kp_.size() != n) {
    ManipulatorData data(model);
    const JointMatrix& M = massMatrix(model, data, model.getHomePosition(), true);
    kp_.setZero(n);
    kd_.setZero(n);
    ki_.setZero(n);
    const double w = kDefaultBandwidth;
    for (int i = 0; i < n; ++i) {
      kp_(i) = M(i, i) * w * w;
      kd_(i) = 2 * M(i, i) * w;
      ki_(i) = kp_(i) * w / 10;
    }
    gainsSet_ = true;
  }
}

void DefaultPositionControl::setGains(const JointVector& kp, const JointVector& kd, const JointVector& ki) {
  if (kp.size() != kd.size() || kp.size() != ki.size() ||
      (d_manipulator != nullptr && kp.size() != d_manipulator->getNumberOfJoints())) {
    throw std::invalid_argument("DefaultPositionControl::setGains: one gain per joint");
  }
  if (kp.minCoeff() < 0 || kd.minCoeff() < 0 || ki.minCoeff() < 0) {
    throw std::invalid_argument("DefaultPositionControl::setGains: gains must not be negative");
  }
  kp_ = kp;
  kd_ = kd;
  ki_ = ki;
  gainsSet_ = true;
}

void DefaultPositionControl::activate() {
  integral_.setZero();
  if (d_manipulator != nullptr) period_ = d_manipulator->getServoPeriod();  // the rate may have changed since attach()
}

void DefaultPositionControl::calculate() {
  Manipulator& m = *d_manipulator;
  const Setpoint& sp = m.getSetpoint();
  const JointVector q = m.getJointPosition();
  const JointVector qd = m.getJointVelocity();
  const int n = static_cast<int>(q.size());
  constexpr double kSmoothing = 0.01;  // [rad/s]
  for (int i = 0; i < n; ++i) {
    const double e = sp.position(i) - q(i);
    // Anti-windup: the integral term stays within 20 % of the torque limit.
    if (ki_(i) > 0) {
      const double bound = 0.2 * limit_(i) / ki_(i);
      integral_(i) = std::clamp(integral_(i) + e * period_, -bound, bound);
    }
    const double v = sp.velocity(i);
    // (tanh is +-1 exactly from 22 on: glibc's tanh returns that there without computing)
    const double x = v / kSmoothing;
    const double coulomb = (std::abs(x) >= 22 ? std::copysign(1.0, x) : std::tanh(x)) * (v >= 0 ? coulombPos_(i) : -coulombNeg_(i));
    const double t = kp_(i) * e + kd_(i) * (v - qd(i)) + ki_(i) * integral_(i) + viscous_(i) * v + coulomb;
    tau_(i) = std::clamp(t, -limit_(i), limit_(i));
  }
  m.setControlOutput(tau_);
}

}  // namespace rp
