// ManipulatorModel and ManipulatorData (rp/model/ManipulatorModel.hpp, ManipulatorData.hpp).
#include "rp/model/ManipulatorModel.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_set>

#include "rp/model/InverseKinematics.hpp"
#include "rp/model/ManipulatorData.hpp"

namespace rp {

namespace {

// Whether every number of the link is finite.
bool allFinite(const LinkParameters& l) {
  for (double v : {l.a, l.alpha, l.d, l.offset, l.mass, l.motorInertia, l.gearRatio, l.viscousFriction,
                   l.coulombFrictionPositive, l.coulombFrictionNegative, l.positionMin, l.positionMax, l.velocityLimit,
                   l.accelerationLimit, l.jerkLimit, l.torqueLimit})
    if (!std::isfinite(v)) return false;
  return l.com.allFinite() && l.inertia.allFinite() && l.placement.allFinite();
}

// The fixed part of a modified-DH link transform: Rx(alpha) Tx(a) Rz(offset) Tz(d).
Transform modifiedPlacement(const LinkParameters& l) {
  const double ca = std::cos(l.alpha), sa = std::sin(l.alpha), ct = std::cos(l.offset), st = std::sin(l.offset);
  Transform P;
  P << ct, -st, 0, l.a,              //
      ca * st, ca * ct, -sa, -sa * l.d,  //
      sa * st, sa * ct, ca, ca * l.d,    //
      0, 0, 0, 1;
  return P;
}

}  // namespace

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
  if (!base_.allFinite() || !tool_.allFinite() || !gravity_.allFinite())
    throw std::invalid_argument("ManipulatorModel '" + name_ + "': the base, tool or gravity is not finite");
  placements_.assign(static_cast<std::size_t>(n), Transform::unit());
  std::unordered_set<std::string> jointNames, linkNames;
  for (int i = 0; i < n; ++i) {
    LinkParameters& l = links_[static_cast<std::size_t>(i)];
    std::string joint = "ManipulatorModel '" + name_ + "' joint " + std::to_string(i + 1);
    if (!l.jointName.empty()) {
      joint += " ('";
      joint += l.jointName;
      joint += "')";
    }
    joint += ": ";
    if (l.jointName.empty()) l.jointName = "joint" + std::to_string(i + 1);
    if (l.linkName.empty()) l.linkName = "link" + std::to_string(i + 1);
    if (!jointNames.insert(l.jointName).second) throw std::invalid_argument(joint + "a second joint named '" + l.jointName + "'");
    if (!linkNames.insert(l.linkName).second) throw std::invalid_argument(joint + "a second link named '" + l.linkName + "'");
    if (!allFinite(l)) throw std::invalid_argument(joint + "a parameter is not a finite number");
    if (convention_ == DHConvention::Placement) {
      if (l.a != 0 || l.alpha != 0 || l.d != 0 || l.offset != 0)
        throw std::invalid_argument(joint + "DH parameters (a, alpha, d, offset) given with DHConvention::Placement");
      if (const std::string problem = rigidTransformError(l.placement); !problem.empty())
        throw std::invalid_argument(joint + "the placement is not a rigid transform: it " + problem);
      placements_[static_cast<std::size_t>(i)] = l.placement;
    } else {
      if (!l.placement.isIdentity(0.0))
        throw std::invalid_argument(joint + "a placement given with DH parameters (use DHConvention::Placement)");
      if (convention_ == DHConvention::Modified) placements_[static_cast<std::size_t>(i)] = modifiedPlacement(l);
    }
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

int ManipulatorModel::findJoint(const std::string& name) const {
  for (int i = 0; i < getNumberOfJoints(); ++i)
    if (getJointName(i) == name) return i;
  return -1;
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
