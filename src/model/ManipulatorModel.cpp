// ManipulatorModel and ManipulatorData (rp/model/ManipulatorModel.hpp, ManipulatorData.hpp).
#include "rp/model/ManipulatorModel.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "rp/model/ManipulatorData.hpp"

namespace rp {

ManipulatorModel::ManipulatorModel(std::string name, std::vector<LinkParameters> links, const Transform& base,
                                   const Transform& tool, const Vector<3>& gravity, DHConvention convention)
    : name_(std::move(name)),
      links_(std::move(links)),
      base_(base),
      tool_(tool),
      gravity_(gravity),
      convention_(convention) {
  const int n = static_cast<int>(links_.size());
  if (n < 1 || n > kMaxJoints) {
    throw std::invalid_argument("ManipulatorModel '" + name_ + "': " + std::to_string(n) +
                                " links; a model has 1 to " + std::to_string(kMaxJoints));
  }
  for (JointVector* v : {&qmin_, &qmax_, &vmax_, &amax_, &jmax_, &taumax_, &armature_, &home_, &cosAlpha_, &sinAlpha_}) v->setZero(n);
  for (int i = 0; i < n; ++i) {
    const LinkParameters& l = links_[static_cast<std::size_t>(i)];
    const std::string joint = "ManipulatorModel '" + name_ + "' joint " + std::to_string(i + 1) + ": ";
    if (l.mass < 0) throw std::invalid_argument(joint + "negative mass");
    if (!(l.positionMin <= l.positionMax)) throw std::invalid_argument(joint + "position limits have min > max");
    if (!(l.velocityLimit > 0) || !(l.accelerationLimit > 0) || !(l.jerkLimit > 0) || !(l.torqueLimit > 0)) {
      throw std::invalid_argument(joint + "velocity, acceleration, jerk and torque limits must be positive");
    }
    qmin_(i) = l.positionMin;
    qmax_(i) = l.positionMax;
    vmax_(i) = l.velocityLimit;
    amax_(i) = l.accelerationLimit;
    jmax_(i) = l.jerkLimit;
    taumax_(i) = l.torqueLimit;
    armature_(i) = l.gearRatio * l.gearRatio * l.motorInertia;
    home_(i) = std::clamp(0.0, l.positionMin, l.positionMax);
    cosAlpha_(i) = std::cos(l.alpha);
    sinAlpha_(i) = std::sin(l.alpha);
  }
}

bool ManipulatorModel::isWithinLimits(const JointVector& q) const {
  if (q.size() != qmin_.size()) return false;
  for (Eigen::Index i = 0; i < q.size(); ++i) {
    if (!(q(i) >= qmin_(i) && q(i) <= qmax_(i))) return false;
  }
  return true;
}

void ManipulatorModel::setHomePosition(const JointVector& q) {
  if (q.size() != home_.size()) throw std::invalid_argument("ManipulatorModel::setHomePosition: wrong size");
  home_ = q;
}

ManipulatorData::ManipulatorData(const ManipulatorModel& model) : n(model.getNumberOfJoints()) {
  linkTransforms.fill(Transform::unit());
  endEffector = Transform::unit();
  jacobian = Jacobian(6, n);
  for (JointVector* v : {&tau, &qdd, &scratchTau, &zero, &unitColumn, &abaD, &abaU, &bias}) v->setZero(n);
  massMatrix.setZero(n, n);
  ldl.setZero(n, n);
}

}  // namespace rp
