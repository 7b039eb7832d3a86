// ManipulatorModel and ManipulatorData (rp/model/ManipulatorModel.hpp, ManipulatorData.hpp).
#include "rp/model/ManipulatorModel.hpp"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
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

// The rotation of `P` as a signed permutation of the axes, if every entry is 0 or +-1 to within
// 8 machine epsilons (cos(pi/2) is 6e-17, not 0) with one +-1 in each column.
PlacementAxes signedPermutation(const Transform& P) {
  constexpr double kTolerance = 8 * std::numeric_limits<double>::epsilon();
  PlacementAxes axes;
  for (int k = 0; k < 3; ++k) {
    int found = -1;
    for (int r = 0; r < 3; ++r) {
      const double v = P(r, k);
      if (std::abs(v) <= kTolerance) continue;
      if (found >= 0 || std::abs(std::abs(v) - 1) > kTolerance) return PlacementAxes{};
      found = r;
      axes.sign[static_cast<std::size_t>(k)] = v > 0 ? 1.0 : -1.0;
    }
    if (found < 0) return PlacementAxes{};
    axes.axis[static_cast<std::size_t>(k)] = found;
  }
  axes.permutation = true;  // a rigid transform's rotation: the three columns are distinct axes
  return axes;
}

}  // namespace

namespace {

// Whether two links are the same in every parameter (names included: they are the model's).
bool sameLink(const LinkParameters& x, const LinkParameters& y) {
  return x.a == y.a && x.alpha == y.alpha && x.d == y.d && x.offset == y.offset && x.mass == y.mass && x.com == y.com &&
         x.inertia == y.inertia && x.motorInertia == y.motorInertia && x.gearRatio == y.gearRatio &&
         x.viscousFriction == y.viscousFriction && x.coulombFrictionPositive == y.coulombFrictionPositive &&
         x.coulombFrictionNegative == y.coulombFrictionNegative && x.positionMin == y.positionMin &&
         x.positionMax == y.positionMax && x.velocityLimit == y.velocityLimit &&
         x.accelerationLimit == y.accelerationLimit && x.jerkLimit == y.jerkLimit && x.torqueLimit == y.torqueLimit &&
         x.type == y.type && x.placement == y.placement && x.jointName == y.jointName && x.linkName == y.linkName;
}

}  // namespace

// Everything in Links follows from the links and the convention, so two models with equal links
// and convention can share one. The registry holds weak references: a set of links no model uses
// any more is freed with its last model. Only constructors call this (never a servo cycle).
std::shared_ptr<const ManipulatorModel::Links> ManipulatorModel::internLinks(std::shared_ptr<Links> links,
                                                                             DHConvention convention) {
  static auto* mutex = new std::mutex;  // never destroyed: models may be made during static destruction
  static auto* known = new std::vector<std::pair<DHConvention, std::weak_ptr<const Links>>>;
  std::lock_guard<std::mutex> lock(*mutex);
  known->erase(std::remove_if(known->begin(), known->end(), [](const auto& k) { return k.second.expired(); }), known->end());
  for (const auto& [c, weak] : *known) {
    if (c != convention) continue;
    std::shared_ptr<const Links> other = weak.lock();
    if (!other || other->links.size() != links->links.size()) continue;
    if (std::equal(other->links.begin(), other->links.end(), links->links.begin(), sameLink)) return other;
  }
  known->emplace_back(convention, links);
  return links;
}

ManipulatorModel::ManipulatorModel(std::string name, std::vector<LinkParameters> links, const Transform& base,
                                   const Transform& tool, const Vector<3>& gravity, DHConvention convention)
    : name_(std::move(name)),
      base_(base),
      tool_(tool),
      gravity_(gravity),
      convention_(convention) {
  auto shared = std::make_shared<Links>();
  Links& m = *shared;
  m.links = std::move(links);
  const int n = static_cast<int>(m.links.size());
  if (n < 1 || n > kMaxJoints) {
    throw std::invalid_argument("ManipulatorModel '" + name_ + "': " + std::to_string(n) +
                                " links; a model has 1 to " + std::to_string(kMaxJoints));
  }
  for (JointVector* v : {&m.qmin, &m.qmax, &m.vmax, &m.amax, &m.jmax, &m.taumax, &m.armature, &home_, &m.cosAlpha, &m.sinAlpha})
    v->setZero(n);
  if (!base_.allFinite() || !tool_.allFinite() || !gravity_.allFinite())
    throw std::invalid_argument("ManipulatorModel '" + name_ + "': the base, tool or gravity is not finite");
  toolIsIdentity_ = tool_.isIdentity(0.0);
  m.placements.assign(static_cast<std::size_t>(n), Transform::unit());
  m.placementAxes.assign(static_cast<std::size_t>(n), PlacementAxes{});
  std::unordered_set<std::string> jointNames, linkNames;
  for (int i = 0; i < n; ++i) {
    LinkParameters& l = m.links[static_cast<std::size_t>(i)];
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
      m.placements[static_cast<std::size_t>(i)] = l.placement;
    } else {
      if (!l.placement.isIdentity(0.0))
        throw std::invalid_argument(joint + "a placement given with DH parameters (use DHConvention::Placement)");
      if (convention_ == DHConvention::Modified) m.placements[static_cast<std::size_t>(i)] = modifiedPlacement(l);
    }
    m.placementAxes[static_cast<std::size_t>(i)] = signedPermutation(m.placements[static_cast<std::size_t>(i)]);
    if (l.mass < 0) throw std::invalid_argument(joint + "negative mass");
    if (!(l.positionMin <= l.positionMax)) throw std::invalid_argument(joint + "position limits have min > max");
    if (!(l.velocityLimit > 0) || !(l.accelerationLimit > 0) || !(l.jerkLimit > 0) || !(l.torqueLimit > 0)) {
      throw std::invalid_argument(joint + "velocity, acceleration, jerk and torque limits must be positive");
    }
    m.qmin(i) = l.positionMin;
    m.qmax(i) = l.positionMax;
    m.vmax(i) = l.velocityLimit;
    m.amax(i) = l.accelerationLimit;
    m.jmax(i) = l.jerkLimit;
    m.taumax(i) = l.torqueLimit;
    m.armature(i) = l.gearRatio * l.gearRatio * l.motorInertia;
    home_(i) = std::clamp(0.0, l.positionMin, l.positionMax);
    m.cosAlpha(i) = std::cos(l.alpha);
    m.sinAlpha(i) = std::sin(l.alpha);
    // The factor is used only where it gives the inertia back to rounding: a positive definite
    // tensor (Eigen's LLT does not check symmetry; the lower triangle is the one it reads).
    const Eigen::LLT<Eigen::Matrix3d> llt(l.inertia);
    Eigen::Matrix3d L = Eigen::Matrix3d::Zero();
    bool valid = llt.info() == Eigen::Success;
    if (valid) {
      L = llt.matrixL();
      const double scale = l.inertia.cwiseAbs().maxCoeff();
      valid = L.allFinite() && (L * L.transpose() - l.inertia).cwiseAbs().maxCoeff() <= 1e-14 * scale;
    }
    m.inertiaFactors.push_back(L);
    m.inertiaFactorValid.push_back(valid);
  }
  links_ = internLinks(std::move(shared), convention_);
}

namespace {

const ManipulatorModel& checkedChain(const std::shared_ptr<const ManipulatorModel>& chain) {
  if (!chain) throw std::invalid_argument("ManipulatorModel: no chain for the mimic joints");
  if (chain->hasMimicJoints())
    throw std::invalid_argument("ManipulatorModel '" + chain->getName() + "': the chain of a model with mimic joints has mimic joints");
  return *chain;
}

// The model's links: the chain's independent joints, with what the mimic joints following each
// allow (limits) and reflect onto it (friction, motor inertia).
std::vector<LinkParameters> independentLinks(const ManipulatorModel& chain, const std::vector<JointCoupling>& coupling) {
  const int m = chain.getNumberOfJoints();
  const std::string model = "ManipulatorModel '" + chain.getName() + "': ";
  if (static_cast<int>(coupling.size()) != m)
    throw std::invalid_argument(model + std::to_string(coupling.size()) + " couplings for a chain of " + std::to_string(m) + " joints");
  std::vector<LinkParameters> links;
  for (int k = 0; k < m; ++k) {
    const JointCoupling& c = coupling[static_cast<std::size_t>(k)];
    if (c.mimic) continue;
    if (c.joint != static_cast<int>(links.size()) || c.multiplier != 1 || c.offset != 0)
      throw std::invalid_argument(model + "chain joint " + std::to_string(k + 1) + " is independent but coupled as joint " +
                                  std::to_string(c.joint + 1) + " (the independent joints are numbered in chain order, multiplier 1, offset 0)");
    links.push_back(chain.getLink(k));
  }
  if (links.empty()) throw std::invalid_argument(model + "every joint of the chain is a mimic joint");
  for (int k = 0; k < m; ++k) {
    const JointCoupling& c = coupling[static_cast<std::size_t>(k)];
    if (!c.mimic) continue;
    const LinkParameters& f = chain.getLink(k);
    const std::string joint = model + "mimic joint '" + f.jointName + "': ";
    if (c.joint < 0 || c.joint >= static_cast<int>(links.size()))
      throw std::invalid_argument(joint + "follows joint " + std::to_string(c.joint + 1) + ", which does not exist");
    if (!std::isfinite(c.multiplier) || !std::isfinite(c.offset)) throw std::invalid_argument(joint + "a multiplier or offset that is not finite");
    LinkParameters& l = links[static_cast<std::size_t>(c.joint)];
    const double a = c.multiplier, aa = std::abs(a);
    if (a != 0) {
      double lo = (f.positionMin - c.offset) / a, hi = (f.positionMax - c.offset) / a;
      if (a < 0) std::swap(lo, hi);
      l.positionMin = std::max(l.positionMin, lo);
      l.positionMax = std::min(l.positionMax, hi);
      if (!(l.positionMin <= l.positionMax))
        throw std::invalid_argument(joint + "its position limits leave joint '" + l.jointName + "' no position");
      l.velocityLimit = std::min(l.velocityLimit, f.velocityLimit / aa);
      l.accelerationLimit = std::min(l.accelerationLimit, f.accelerationLimit / aa);
      l.jerkLimit = std::min(l.jerkLimit, f.jerkLimit / aa);
    } else if (c.offset < f.positionMin || c.offset > f.positionMax) {
      throw std::invalid_argument(joint + "its offset lies outside its position limits");
    }
    // Joint side, tau_master += a tau_mimic(a qd): viscous a^2 B_f G_f^2, Coulomb a G_f Tc_f(sign(a qd)),
    // armature a^2 G_f^2 Jm_f, written on the motor side of the master's gear ratio G.
    const double G = std::abs(l.gearRatio), Gf = std::abs(f.gearRatio);
    const bool friction = f.viscousFriction != 0 || f.coulombFrictionPositive != 0 || f.coulombFrictionNegative != 0;
    if ((friction || f.motorInertia != 0) && a != 0 && Gf != 0) {
      if (G == 0) throw std::invalid_argument(joint + "its friction or motor inertia cannot act through joint '" + l.jointName + "' (gear ratio 0)");
      l.viscousFriction += a * a * Gf * Gf * f.viscousFriction / (G * G);
      l.coulombFrictionPositive += aa * Gf * (a > 0 ? f.coulombFrictionPositive : -f.coulombFrictionNegative) / G;
      l.coulombFrictionNegative -= aa * Gf * (a > 0 ? -f.coulombFrictionNegative : f.coulombFrictionPositive) / G;
      l.motorInertia += a * a * Gf * Gf * f.motorInertia / (G * G);
    }
  }
  return links;
}

}  // namespace

ManipulatorModel::ManipulatorModel(std::shared_ptr<const ManipulatorModel> chain, std::vector<JointCoupling> coupling)
    : ManipulatorModel(checkedChain(chain).getName(), independentLinks(*chain, coupling), chain->getBaseTransform(),
                       chain->getToolTransform(), chain->getGravity(), chain->getConvention()) {
  for (int k = 0; k < chain->getNumberOfJoints(); ++k)
    if (!coupling[static_cast<std::size_t>(k)].mimic) chainIndex_.push_back(k);
  chain_ = std::move(chain);
  coupling_ = std::move(coupling);
}

void ManipulatorModel::toChain(const JointVector& q, JointVector& chainQ, bool offsets) const {
  if (!chain_) {
    chainQ = q;
    return;
  }
  const int m = static_cast<int>(coupling_.size());
  chainQ.resize(m);
  for (int k = 0; k < m; ++k) {
    const JointCoupling& c = coupling_[static_cast<std::size_t>(k)];
    chainQ(k) = c.multiplier * q(c.joint) + (offsets ? c.offset : 0.0);
  }
}

int ManipulatorModel::findJoint(const std::string& name) const {
  for (int i = 0; i < getNumberOfJoints(); ++i)
    if (getJointName(i) == name) return i;
  return -1;
}

bool ManipulatorModel::isWithinLimits(const JointVector& q) const {
  const JointVector& qmin = links_->qmin;
  const JointVector& qmax = links_->qmax;
  if (q.size() != qmin.size()) return false;
  for (Eigen::Index i = 0; i < q.size(); ++i) {
    if (!(q(i) >= qmin(i) && q(i) <= qmax(i))) return false;
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
  if (model.hasMimicJoints()) {
    const ManipulatorModel& c = model.getChain();
    chain = std::make_unique<ManipulatorData>(c);
    for (JointVector* v : {&chainQ, &chainQd, &chainQdd, &chainTau}) v->setZero(c.getNumberOfJoints());
  }
}

}  // namespace rp
