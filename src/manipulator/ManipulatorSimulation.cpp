// Dynamic simulation of a manipulator arm (rp/manipulator/ManipulatorSimulation.hpp).
#include "rp/manipulator/ManipulatorSimulation.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace rp {

ManipulatorSimulation::ManipulatorSimulation(const ManipulatorModel& model) : model_(model), data_(model) {
  const int n = model.getNumberOfJoints();
  q_ = model.getHomePosition();
  for (JointVector* v : {&qd_, &qdd_, &tauTotal_, &tauExt_, &coulombPos_, &coulombNeg_}) v->setZero(n);
  brakeTorque_ = model.getTorqueLimit();
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

void ManipulatorSimulation::setBrakeTorque(const JointVector& torque) {
  if (torque.size() != model_.getNumberOfJoints())
    throw std::invalid_argument("ManipulatorSimulation::setBrakeTorque: " + std::to_string(torque.size()) +
                                " torques for " + std::to_string(model_.getNumberOfJoints()) + " joints");
  for (int i = 0; i < torque.size(); ++i)
    if (!(torque(i) > 0) || !std::isfinite(torque(i)))
      throw std::invalid_argument("ManipulatorSimulation::setBrakeTorque: joint " + std::to_string(i + 1) +
                                  ": the braking torque must be positive and finite");
  brakeTorque_ = torque;
}

void ManipulatorSimulation::step(const JointVector& tau, double dt) {
  const int n = model_.getNumberOfJoints();
  externalTorque();  // constant over the step
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

void ManipulatorSimulation::setExternalLinkWrench(int link, const Vector<3>& point, const Vector<6>& wrench) {
  const int n = model_.getNumberOfJoints();
  if (link < 1 || link > n) {
    throw std::out_of_range("ManipulatorSimulation::setExternalLinkWrench: link " + std::to_string(link) +
                            " is not in 1.." + std::to_string(n));
  }
  const auto k = static_cast<std::size_t>(link - 1);
  const bool was = linkWrench_[k].squaredNorm() > 0;
  linkPoint_[k] = point;
  linkWrench_[k] = wrench;
  linkWrenches_ += (wrench.squaredNorm() > 0 ? 1 : 0) - (was ? 1 : 0);
}

void ManipulatorSimulation::clearExternalLinkWrenches() {
  for (Vector<6>& w : linkWrench_) w.setZero();
  linkWrenches_ = 0;
}

void ManipulatorSimulation::externalTorque() {
  tauExt_.setZero();
  if (linkWrenches_ == 0 && !(wrench_.squaredNorm() > 0)) return;
  // One Jacobian J at the end-effector's origin e (it also computes the link frames). For a point
  // p moving with joints 1..k, column j <= k of its Jacobian is (Jv_j + Jw_j x (p - e), Jw_j), so
  // that column's torque is Jv_j . f + Jw_j . (m + (p - e) x f): the wrench moved to e.
  const Jacobian& J = jacobian(model_, data_, q_, ReferenceFrame::Base);
  if (wrench_.squaredNorm() > 0) tauExt_.noalias() = J.transpose() * wrench_;
  if (linkWrenches_ == 0) return;
  const Eigen::Vector3d e = data_.endEffector.topRightCorner<3, 1>();
  const int n = model_.getNumberOfJoints();
  for (int k = 0; k < n; ++k) {
    const Vector<6>& w = linkWrench_[static_cast<std::size_t>(k)];
    if (!(w.squaredNorm() > 0)) continue;
    const Transform& T = data_.linkTransforms[static_cast<std::size_t>(k)];
    const Eigen::Vector3d p =
        T.topLeftCorner<3, 3>() * Eigen::Vector3d(linkPoint_[static_cast<std::size_t>(k)]) + T.topRightCorner<3, 1>();
    const Eigen::Vector3d f = w.head<3>();
    const Eigen::Vector3d m = w.tail<3>() + (p - e).cross(f);
    for (int j = 0; j <= k; ++j) tauExt_(j) += J.col(j).head<3>().dot(f) + J.col(j).tail<3>().dot(m);
  }
}

void ManipulatorSimulation::integrate(const JointVector& tau, double h) {
  const int n = model_.getNumberOfJoints();
  const double stopDamping = 2.0 * std::sqrt(stopStiffness_ * 0.1);
  for (int i = 0; i < n; ++i) {
    const LinkParameters& l = model_.getLink(i);
    // With the brakes on the amplifiers are off: no motor torque.
    double t = brakes_ ? 0.0 : std::clamp(tau(i), -model_.getTorqueLimit()(i), model_.getTorqueLimit()(i));
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
    // Coulomb friction (and an engaged brake, which acts the same way with its braking torque):
    // an impulse against the motion that stops the joint but never reverses it.
    const double m = data_.massMatrix(i, i);
    const double brake = brakes_ ? brakeTorque_(i) : 0.0;
    const double friction = (v > 0 ? std::abs(coulombPos_(i)) : (v < 0 ? std::abs(coulombNeg_(i)) : 0.0)) + brake;
    const double dv = h * friction / m;  // a magnitude
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
