// Dynamic simulation of a manipulator arm (rp/manipulator/ManipulatorSimulation.hpp).
#include "rp/manipulator/ManipulatorSimulation.hpp"

#include <algorithm>
#include <cmath>

namespace rp {

ManipulatorSimulation::ManipulatorSimulation(const ManipulatorModel& model) : model_(model), data_(model) {
  const int n = model.getNumberOfJoints();
  q_ = model.getHomePosition();
  for (JointVector* v : {&qd_, &qdd_, &tauTotal_, &tauExt_, &coulombPos_, &coulombNeg_}) v->setZero(n);
  for (int i = 0; i < n; ++i) {
    const LinkParameters& l = model.getLink(i);
    coulombPos_(i) = std::abs(l.gearRatio) * l.coulombFrictionPositive;
    coulombNeg_(i) = std::abs(l.gearRatio) * l.coulombFrictionNegative;
  }
  options_.gravity = true;
  options_.motorInertia = true;
  options_.friction = false;  // viscous part added below; Coulomb as an impulse
}

void ManipulatorSimulation::setState(const JointVector& q, const JointVector& qd) {
  q_ = q;
  qd_ = qd;
  qdd_.setZero();
}

void ManipulatorSimulation::step(const JointVector& tau, double dt) {
  const int n = model_.getNumberOfJoints();
  if (brakes_) {
    qd_.setZero();
    qdd_.setZero();
    lastSubsteps_ = 1;
    return;
  }
  // External wrench: J^T F, constant over the step.
  if (wrench_.squaredNorm() > 0) {
    endEffectorForceToJointTorque(model_, data_, q_, wrench_, tauExt_, ReferenceFrame::Base);
  } else {
    tauExt_.setZero();
  }
  // Sub-steps while a joint is at a stop: the stop's stiffness k against the joint's inertia
  // (at least its armature) gives the frequency to resolve.
  bool atStop = false;
  for (int i = 0; i < n; ++i) {
    if (q_(i) < model_.getPositionMin()(i) || q_(i) > model_.getPositionMax()(i)) atStop = true;
  }
  int substeps = 1;
  if (atStop) {
    const double inertia = std::max(1e-3, model_.getArmatureInertia().minCoeff());
    const double omega = std::sqrt(stopStiffness_ / inertia);
    substeps = std::clamp(static_cast<int>(std::ceil(omega * dt / 0.2)), 1, 200);
  }
  lastSubsteps_ = substeps;
  const double h = dt / substeps;
  for (int s = 0; s < substeps; ++s) integrate(tau, h);
}

void ManipulatorSimulation::integrate(const JointVector& tau, double h) {
  const int n = model_.getNumberOfJoints();
  const double stopDamping = 2.0 * std::sqrt(stopStiffness_ * 0.1);
  for (int i = 0; i < n; ++i) {
    const LinkParameters& l = model_.getLink(i);
    double t = std::clamp(tau(i), -model_.getTorqueLimit()(i), model_.getTorqueLimit()(i));
    t += tauExt_(i);
    t -= l.viscousFriction * l.gearRatio * l.gearRatio * qd_(i);
    if (q_(i) < l.positionMin) t += stopStiffness_ * (l.positionMin - q_(i)) - stopDamping * std::min(qd_(i), 0.0);
    if (q_(i) > l.positionMax) t += stopStiffness_ * (l.positionMax - q_(i)) - stopDamping * std::max(qd_(i), 0.0);
    tauTotal_(i) = t;
  }
  forwardDynamics(model_, data_, q_, qd_, tauTotal_, options_);
  qdd_ = data_.qdd;
  for (int i = 0; i < n; ++i) {
    double v = qd_(i) + h * qdd_(i);
    // Coulomb friction: an impulse against the motion that stops the joint but never reverses it.
    const double m = data_.massMatrix(i, i);
    const double friction = v > 0 ? coulombPos_(i) : (v < 0 ? -coulombNeg_(i) : 0.0);
    const double dv = h * friction / m;
    if (std::abs(v) <= dv) {
      v = 0;
    } else {
      v -= std::copysign(dv, v);
    }
    qd_(i) = v;
    q_(i) += h * v;
  }
}

}  // namespace rp
