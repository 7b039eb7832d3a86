// Dynamic simulation of a manipulator arm (rp/manipulator/ManipulatorSimulation.hpp).
#include "rp/manipulator/ManipulatorSimulation.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdint>
#include <mutex>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "../model/ThreadWorkspace.hpp"
#include "../rt/ThreadLocalSlot.hpp"
#include "SeqlockHandover.hpp"
#include "rp/core/Configuration.hpp"

namespace rp {

namespace {

constexpr int kMaxFrictionSweeps = 200;  // coordinate-descent sweeps of the friction problem
constexpr double kFrictionTolerance = 1e-13;  // [rad/s] largest change in the last sweep
constexpr int kMaxStopSubsteps = 100;

// Whether an external wrench acts: any component not zero, a NaN included (a wrench that is not
// a number is not "no wrench": it makes the state non-finite, which the servo loop stops on).
bool acts(const Vector<6>& wrench) {
  for (int i = 0; i < 6; ++i)
    if (!(wrench(i) == 0.0)) return true;
  return false;
}

// A model that keeps another's home position (ManipulatorModel::setHomePosition is protected).
class PlantModel : public ManipulatorModel {
 public:
  PlantModel(const ManipulatorModel& nominal, std::vector<LinkParameters> links)
      : ManipulatorModel(nominal.getName(), std::move(links), nominal.getBaseTransform(), nominal.getToolTransform(),
                         nominal.getGravity(), nominal.getConvention()) {
    setHomePosition(nominal.getHomePosition());
  }
  // With mimic joints: `chain` coupled as the nominal model's chain is.
  PlantModel(const ManipulatorModel& nominal, std::shared_ptr<const ManipulatorModel> chain)
      : ManipulatorModel(std::move(chain), nominal.getCoupling()) {
    setHomePosition(nominal.getHomePosition());
  }
};

// `v` with n entries (an empty one: all `fallback`), each checked.
JointVector perJoint(const JointVector& v, int n, double fallback, bool zeroAllowed, const char* what) {
  if (v.size() == 0) return JointVector::Constant(n, fallback);
  if (v.size() != n)
    throw std::invalid_argument(std::string("ManipulatorSimulation: ") + what + ": " + std::to_string(v.size()) +
                                " values for " + std::to_string(n) + " joints");
  for (int i = 0; i < n; ++i)
    if (!std::isfinite(v(i)) || v(i) < 0 || (!zeroAllowed && v(i) == 0))
      throw std::invalid_argument(std::string("ManipulatorSimulation: ") + what + " of joint " + std::to_string(i + 1) +
                                  (zeroAllowed ? " must be finite and not negative" : " must be positive and finite"));
  return v;
}

// A model of `nominal`'s chain with each link's parameters passed through `edit(link, joint, l)`
// (joint: the model's joint that moves the link; with mimic joints the link of a mimic joint takes
// the values of the joint it follows).
template <typename Edit>
std::unique_ptr<const ManipulatorModel> rebuild(const ManipulatorModel& nominal, const Edit& edit) {
  const ManipulatorModel& chain = nominal.getChain();
  std::vector<LinkParameters> links;
  for (int k = 0; k < chain.getNumberOfJoints(); ++k) {
    const int i = nominal.hasMimicJoints() ? nominal.getCoupling()[static_cast<std::size_t>(k)].joint : k;
    LinkParameters l = chain.getLink(k);
    edit(k, i, l);
    links.push_back(l);
  }
  if (nominal.hasMimicJoints())
    return std::make_unique<PlantModel>(
        nominal, std::make_shared<const ManipulatorModel>(chain.getName(), std::move(links), chain.getBaseTransform(),
                                                          chain.getToolTransform(), chain.getGravity(), chain.getConvention()));
  return std::make_unique<PlantModel>(nominal, std::move(links));
}

std::unique_ptr<const ManipulatorModel> buildPlant(const ManipulatorModel& nominal, const PlantDeviations& d) {
  const int n = nominal.getNumberOfJoints();
  const JointVector mass = perJoint(d.massScale, n, 1.0, false, "mass scale");
  const JointVector inertia = perJoint(d.inertiaScale, n, 1.0, false, "inertia scale");
  const JointVector friction = perJoint(d.frictionScale, n, 1.0, true, "friction scale");
  if (!std::isfinite(d.payload) || d.payload < 0)
    throw std::invalid_argument("ManipulatorSimulation: the payload must be finite and not negative");
  const int last = nominal.getChain().getNumberOfJoints() - 1;
  // A point mass at the tool frame's origin, in the last link's frame.
  const Eigen::Vector3d p = nominal.getToolTransform().topRightCorner<3, 1>();
  return rebuild(nominal, [&](int k, int i, LinkParameters& l) {
    l.mass *= mass(i);
    l.inertia = Matrix<3, 3>(Eigen::Matrix3d(l.inertia) * inertia(i));
    const double f = d.friction ? friction(i) : 0.0;
    l.viscousFriction *= f;
    l.coulombFrictionPositive *= f;
    l.coulombFrictionNegative *= f;
    if (!d.motorInertia) l.motorInertia = 0;
    if (k != last || d.payload <= 0) return;
    // The point mass and the link's mass, centre of mass and inertia about it combine (parallel-axis
    // theorem).
    const Eigen::Vector3d c = l.com;
    const double m = l.mass + d.payload;
    const Eigen::Vector3d cNew = (l.mass * c + d.payload * p) / m;
    auto shift = [](double mass, const Eigen::Vector3d& r) -> Eigen::Matrix3d {
      return mass * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
    };
    l.inertia = Matrix<3, 3>(Eigen::Matrix3d(l.inertia) + shift(l.mass, c - cNew) + shift(d.payload, p - cNew));
    l.com = Vector<3>(cNew);
    l.mass = m;
  });
}

// The chain of `plant` with massless, frictionless links but for 1 kg at `centre` (end-effector
// frame) on the last link: the dynamics of a unit payload there.
std::unique_ptr<const ManipulatorModel> buildUnitPayload(const ManipulatorModel& plant, const Vector<3>& centre) {
  const int last = plant.getChain().getNumberOfJoints() - 1;
  const Transform& tool = plant.getToolTransform();
  const Eigen::Vector3d p = tool.topLeftCorner<3, 3>() * Eigen::Vector3d(centre) + tool.topRightCorner<3, 1>();
  return rebuild(plant, [&](int k, int, LinkParameters& l) {
    l.mass = k == last ? 1.0 : 0.0;
    l.com = k == last ? Vector<3>(p) : Vector<3>::Zero();
    l.inertia = Matrix<3, 3>::Zero();
    l.motorInertia = 0;
    l.viscousFriction = l.coulombFrictionPositive = l.coulombFrictionNegative = 0;
  });
}

// Solves A x = b for a symmetric positive definite A by Cholesky (A = L L^T), without allocation.
// Each diagonal entry of L is inverted once: n divisions instead of n (n + 3) / 2 (a division
// takes as long as a dozen multiplications in a row). b is read once, into x, after the
// factorization: x may be b.
void choleskySolve(const JointMatrix& A, const JointVector& b, JointMatrix& L, JointVector& x) {
  const auto n = static_cast<int>(A.rows());
  std::array<double, kMaxJoints> inverse;  // 1 / L(j, j) (each written before read)
  for (int j = 0; j < n; ++j) {
    double d = A(j, j);
    for (int m = 0; m < j; ++m) d -= L(j, m) * L(j, m);
    const double ljj = std::sqrt(d);
    const double r = 1.0 / ljj;
    L(j, j) = ljj;
    inverse[static_cast<std::size_t>(j)] = r;
    for (int i = j + 1; i < n; ++i) {
      double s = A(i, j);
      for (int m = 0; m < j; ++m) s -= L(i, m) * L(j, m);
      L(i, j) = s * r;
    }
  }
  x = b;
  for (int i = 0; i < n; ++i) {
    double s = x(i);
    for (int m = 0; m < i; ++m) s -= L(i, m) * x(m);
    x(i) = s * inverse[static_cast<std::size_t>(i)];
  }
  for (int i = n - 1; i >= 0; --i) {
    double s = x(i);
    for (int m = i + 1; m < n; ++m) s -= L(m, i) * x(m);
    x(i) = s * inverse[static_cast<std::size_t>(i)];
  }
}

// y = M x for a symmetric n x n M (the mass matrix, a friction problem's matrix), row by row as
// columns (M is column-major): plain loops over n, where Eigen's product on sizes known only at run
// time took its general matrix-vector kernel, three times the instructions for n = 6.
void symmetricTimes(const JointMatrix& M, const JointVector& x, JointVector& y) noexcept {
  const auto n = static_cast<int>(x.size());
  y.resize(n);
  for (int i = 0; i < n; ++i) {
    const double* column = M.data() + static_cast<std::ptrdiff_t>(i) * M.rows();  // = row i
    double sum = 0;
    for (int k = 0; k < n; ++k) sum += column[k] * x(k);
    y(i) = sum;
  }
}

// The contact mode of the velocities v of solveFriction(): two bits per joint, sliding forward,
// sliding backward (neither: at rest).
std::uint64_t contactMode(const JointVector& v) noexcept {
  std::uint64_t mode = 0;
  for (int i = 0; i < v.size(); ++i)
    mode |= (v(i) > 0 ? std::uint64_t{1} : v(i) < 0 ? std::uint64_t{2} : std::uint64_t{0}) << (2 * i);
  return mode;
}

// The friction problem of ManipulatorSimulation::solveFriction() (A, rhs, friction bounds upper
// and lower) solved exactly in the contact mode of v, which it replaces if that solution is the
// minimiser. Its scratch is on the stack, which stays in the level-1 cache from one arm to the
// next (an arm's own memory is cold by its next cycle). Real-time safe: yes.
bool solveContactMode(const JointMatrix& A, const JointVector& rhs, const JointVector& upper,
                      const JointVector& lower, JointVector& v) noexcept {
  // In the mode of v, the sliding joints s feel their friction c_s (upper forward, -lower
  // backward) and the others are at rest, so A_ss v_s = rhs_s - c_s. That v is the minimiser if
  // it keeps the mode (each v_s strictly in its direction) and the torque that holds each joint
  // at rest, rhs_i - (A v)_i, is within its friction [-lower_i, upper_i]: the optimality
  // conditions of the (strictly convex) problem. Otherwise nothing changes.
  const int n = static_cast<int>(v.size());
  std::array<int, kMaxJoints> s;  // the sliding joints, s[0..m)
  int m = 0;
  for (int i = 0; i < n; ++i)
    if (v(i) != 0) s[static_cast<std::size_t>(m++)] = i;
  JointMatrix As(m, m);  // A_ss (fixed capacity: no allocation)
  JointVector bs(m);     // rhs_s - c_s
  JointMatrix L(m, m);   // A_ss = L L^T
  JointVector x(m);      // v_s
  for (int a = 0; a < m; ++a) {
    const int i = s[static_cast<std::size_t>(a)];
    bs(a) = rhs(i) - (v(i) > 0 ? upper(i) : -lower(i));
    for (int c = 0; c < m; ++c) As(a, c) = A(i, s[static_cast<std::size_t>(c)]);
  }
  choleskySolve(As, bs, L, x);  // A_ss is positive definite (A is)
  for (int a = 0; a < m; ++a)
    if (!(x(a) * v(s[static_cast<std::size_t>(a)]) > 0)) return false;  // (a NaN fails too)
  for (int i = 0, a = 0; i < n; ++i) {
    if (a < m && s[static_cast<std::size_t>(a)] == i) {
      ++a;
      continue;
    }
    double hold = rhs(i);
    for (int b = 0; b < m; ++b) hold -= A(i, s[static_cast<std::size_t>(b)]) * x(b);
    if (!(hold <= upper(i) && hold >= -lower(i))) return false;
  }
  v.setZero();
  for (int a = 0; a < m; ++a) v(s[static_cast<std::size_t>(a)]) = x(a);
  return true;
}

// A step's scratch: the integrators', the friction problem's and the payload's vectors and
// matrices, written and read within one step() (none carries anything to the next). One per
// thread: with many arms in one executor an arm's own memory is cold by its next step, and scratch
// kept there cost every step a cache line fetched and one written back for each vector; this
// thread's stays in its caches from one arm to the next. It owns no heap memory.
struct StepScratch {
  JointVector tauTotal, diag, rhs, residual, upper, lower, q0, v0, kq, kv, sumQ, sumV, payloadBias;
  JointVector start;  // the velocities the step starts from: their contact mode is tried first
  JointMatrix A, L;
  bool eulerSweeps = false;  // the friction sweeps start from the Euler step's v + h qdd0 (made on need)
};
thread_local internal::ThreadLocalSlot<StepScratch> tStepScratch;
static_assert(std::is_trivially_destructible_v<internal::ThreadLocalSlot<StepScratch>>);

// This thread's step scratch. Real-time safe: yes (no allocation).
StepScratch& stepScratch() noexcept { return tStepScratch.getOrMake(); }

}  // namespace

// The unit payload models by centre, kept for the simulation's life (the stepping thread may use
// any of them), and the hand-over of (mass, centre index) to the stepping thread.
struct ManipulatorSimulation::Payload {
  struct Unit {
    Vector<3> centre;
    std::unique_ptr<const ManipulatorModel> model;
    std::unique_ptr<ManipulatorData> data;  // the stepping thread's
  };
  std::mutex mutex;  // serialises setPayload()
  std::array<Unit, kMaxPayloadCentres> units;
  int count = 0;
  internal::SeqlockHandover<2> handover;  // mass [kg], centre index
};

ManipulatorSimulation::ManipulatorSimulation(const ManipulatorModel& model) : model_(model), data_(model) { init(); }

ManipulatorSimulation::ManipulatorSimulation(const ManipulatorModel& nominal, const PlantDeviations& deviations)
    : own_(buildPlant(nominal, deviations)), model_(*own_), data_(*own_) {
  init();
}

ManipulatorSimulation::~ManipulatorSimulation() = default;

void ManipulatorSimulation::init() {
  const int n = model_.getNumberOfJoints();
  q_ = model_.getHomePosition();
  for (JointVector* v : {&qd_, &qdd_, &tauExt_, &tauApplied_, &coulombPos_, &coulombNeg_, &viscous_}) v->setZero(n);
  zero_.setZero(n);
  payload_ = std::make_unique<Payload>();
  brakeTorque_ = model_.getTorqueLimit();
  encoderOffset_.setZero(n);
  for (int i = 0; i < n; ++i) {
    const LinkParameters& l = model_.getLink(i);
    coulombPos_(i) = std::abs(l.gearRatio * l.coulombFrictionPositive);
    coulombNeg_(i) = std::abs(l.gearRatio * l.coulombFrictionNegative);
    viscous_(i) = l.viscousFriction * l.gearRatio * l.gearRatio;
  }
  hasCoulomb_ = coulombPos_.maxCoeff() > 0 || coulombNeg_.maxCoeff() > 0;
  options_.gravity = true;
  options_.motorInertia = true;
  options_.friction = false;  // viscous friction implicit (Euler) or explicit (RK4), Coulomb as a constraint
  setState(q_, qd_);
}

void ManipulatorSimulation::setPayload(double mass, const Vector<3>& centre) {
  if (!std::isfinite(mass) || mass < 0)
    throw std::invalid_argument("ManipulatorSimulation::setPayload: the mass must be finite and not negative");
  if (!centre.allFinite()) throw std::invalid_argument("ManipulatorSimulation::setPayload: the centre must be finite");
  Payload& p = *payload_;
  std::lock_guard<std::mutex> lock(p.mutex);
  int index = -1;
  for (int i = 0; i < p.count; ++i)
    if (p.units[static_cast<std::size_t>(i)].centre == centre) index = i;
  if (index < 0 && mass > 0) {
    if (p.count == kMaxPayloadCentres)
      throw std::length_error("ManipulatorSimulation::setPayload: more than " + std::to_string(kMaxPayloadCentres) +
                              " different payload centres");
    Payload::Unit& u = p.units[static_cast<std::size_t>(p.count)];
    u.centre = centre;
    u.model = buildUnitPayload(model_, centre);
    u.data = std::make_unique<ManipulatorData>(*u.model);
    index = p.count++;  // complete before the hand-over below publishes it
  }
  p.handover.store({mass, static_cast<double>(index)});
  payloadsSet_.fetch_add(1, std::memory_order_release);  // after the store: a step that sees it loads it
}

void ManipulatorSimulation::takePayload() noexcept {
  const std::uint64_t set = payloadsSet_.load(std::memory_order_acquire);
  if (set == payloadsTaken_) return;  // nothing new since the last payload taken
  std::array<double, 2> v{};
  if (!payload_->handover.tryLoad(v)) return;  // being changed: the next step takes it
  payloadsTaken_ = set;  // (the values are set's or a later call's: a later one is loaded again)
  stepCentre_ = static_cast<int>(v[1]);
  stepMass_ = stepCentre_ < 0 ? 0.0 : v[0];
}

// The step's dynamics go to this thread's workspace (ThreadWorkspace.hpp: with many arms in one
// thread, an arm's own data is cold by its next step), or with mimic joints to the simulation's
// own data: internal::workspaceOr(model_, data_) says which, to the step that reads the results
// right after.
void ManipulatorSimulation::dynamics(const JointVector& q, const JointVector& qd, const JointVector& tau, bool solve) {
  ManipulatorData& d = internal::workspaceOr(model_, data_);
  if (stepMass_ == 0) {
    if (solve) {
      forwardDynamics(model_, d, q, qd, tau, options_);
      return;
    }
    massMatrixAndBias(model_, d, q, qd, options_);
    for (int i = 0; i < d.n; ++i) d.qdd(i) = tau(i) - d.bias(i);  // forwardDynamics()'s right-hand side
    return;
  }
  // (M + m M_u) qdd = tau - m h_u - h, with the unit payload's M_u and h_u.
  Payload::Unit& u = payload_->units[static_cast<std::size_t>(stepCentre_)];
  StepScratch& s = stepScratch();
  s.payloadBias = tau - stepMass_ * inverseDynamics(*u.model, *u.data, q, qd, zero_);
  massMatrixAndBias(model_, d, q, qd, options_);
  for (int i = 0; i < d.n; ++i) d.qdd(i) = s.payloadBias(i) - d.bias(i);
  d.massMatrix += stepMass_ * massMatrix(*u.model, *u.data, q);
  if (!solve) return;
  s.L.resize(d.massMatrix.rows(), d.massMatrix.cols());
  choleskySolve(d.massMatrix, d.qdd, s.L, d.qdd);
}

const JointVector& ManipulatorSimulation::getAcceleration() const {
  if (accelerationPending_) {
    // Pending only after an Euler step, which a const object cannot have taken: the object is
    // not const, and the cast is defined.
    auto& self = const_cast<ManipulatorSimulation&>(*this);
    const int n = model_.getNumberOfJoints();
    const JointVector q = stepStart_.col(0).head(n), qd = stepStart_.col(1).head(n), tau = stepStart_.col(2).head(n);
    self.dynamics(q, qd, tau, true);
    self.qdd_ = internal::workspaceOr(model_, self.data_).qdd;
    self.accelerationPending_ = false;
  }
  return qdd_;
}

const JointMatrix& ManipulatorSimulation::plantMassMatrix() {
  const JointMatrix& M = massMatrix(model_, data_, q_, true);
  if (stepMass_ == 0) return M;
  data_.massMatrix += stepMass_ * massMatrix(*payload_->units[static_cast<std::size_t>(stepCentre_)].model,
                                             *payload_->units[static_cast<std::size_t>(stepCentre_)].data, q_);
  return data_.massMatrix;
}

void ManipulatorSimulation::setState(const JointVector& q, const JointVector& qd) {
  q_ = q;
  qd_ = qd;
  qdd_.setZero();
  accelerationPending_ = false;
  head_ = delay_;  // the ring filled with this state, the newest in slot delay_
  for (int k = 0; k <= delay_; ++k) pushReading(q_, qd_);
}

void ManipulatorSimulation::setSensor(const JointVector& countsPerRadian, int delay) {
  const int n = model_.getNumberOfJoints();
  if (countsPerRadian.size() != 0) {
    if (countsPerRadian.size() != n)
      throw std::invalid_argument("ManipulatorSimulation::setSensor: " + std::to_string(countsPerRadian.size()) +
                                  " resolutions for " + std::to_string(n) + " joints");
    for (int i = 0; i < n; ++i)
      if (!(countsPerRadian(i) > 0))
        throw std::invalid_argument("ManipulatorSimulation::setSensor: joint " + std::to_string(i + 1) +
                                    ": the encoder resolution must be positive");
  }
  if (delay < 0 || delay > kMaxSensorDelay)
    throw std::invalid_argument("ManipulatorSimulation::setSensor: the delay " + std::to_string(delay) +
                                " is not in 0.." + std::to_string(kMaxSensorDelay));
  countsPerRadian_ = countsPerRadian;
  delay_ = delay;
  setState(q_, qd_);
}

void ManipulatorSimulation::setEncoderOffset(const JointVector& offset) {
  const int n = model_.getNumberOfJoints();
  if (offset.size() != n)
    throw std::invalid_argument("ManipulatorSimulation::setEncoderOffset: " + std::to_string(offset.size()) +
                                " offsets for " + std::to_string(n) + " joints");
  for (int i = 0; i < n; ++i)
    if (!std::isfinite(offset(i)))
      throw std::invalid_argument("ManipulatorSimulation::setEncoderOffset: joint " + std::to_string(i + 1) +
                                  ": the offset must be finite");
  encoderOffset_ = offset;
  setState(q_, qd_);
}

void ManipulatorSimulation::pushReading(const JointVector& q, const JointVector& qd) {
  head_ = head_ == delay_ ? 0 : head_ + 1;
  Reading& r = readings_[static_cast<std::size_t>(head_)];
  r.position = q + encoderOffset_;
  r.velocity = qd;
  // An encoder counts whole increments: the reading is the count below the position.
  for (int i = 0; i < countsPerRadian_.size(); ++i)
    if (std::isfinite(countsPerRadian_(i)))
      r.position(i) = std::floor(r.position(i) * countsPerRadian_(i)) / countsPerRadian_(i);
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
  integrate(tau, dt);
  pushReading(q_, qd_);
}

void ManipulatorSimulation::integrate(const JointVector& tau, double dt) {
  const int n = model_.getNumberOfJoints();
  takePayload();
  externalTorque();  // constant over the step
  // With the brakes on the amplifiers are off: no motor torque.
  for (int i = 0; i < n; ++i)
    tauApplied_(i) = (brakes_ ? 0.0 : std::clamp(tau(i), -model_.getTorqueLimit()(i), model_.getTorqueLimit()(i))) + tauExt_(i);
  // Sub-steps while a joint is at a stop: the stop's stiffness against that joint's inertia gives
  // the frequency to resolve (the implicit stop is stable without them; they keep it accurate).
  int substeps = 1;
  bool atStop = false;
  auto nearStop = [&](int i) {
    const double lo = model_.getPositionMin()(i), hi = model_.getPositionMax()(i), next = q_(i) + dt * qd_(i);
    return q_(i) < lo || q_(i) > hi || next < lo || next > hi;
  };
  for (int i = 0; i < n; ++i) atStop = atStop || nearStop(i);
  if (atStop) {
    const JointMatrix& M = plantMassMatrix();
    for (int i = 0; i < n; ++i) {
      if (!nearStop(i)) continue;
      const double omega = std::sqrt(stopStiffness_ / M(i, i));
      substeps = std::max(substeps, std::min(kMaxStopSubsteps, static_cast<int>(std::ceil(omega * dt / 0.5))));
    }
  }
  lastSubsteps_ = substeps;
  if (!atStop && integrator_ == SimulationIntegrator::RK4) {
    rk4Step(dt);
  } else {
    const double h = dt / substeps;
    for (int s = 0; s < substeps; ++s) eulerStep(h);
  }
}

int ManipulatorSimulation::advance(const JointVector& tau, double elapsed, double period) {
  if (!(period > 0) || !std::isfinite(period))
    throw std::invalid_argument("ManipulatorSimulation::advance: the period must be positive and finite");
  if (!(elapsed >= 1.5 * period)) {  // on time (and a time that is not a number)
    step(tau, period);
    return 1;
  }
  const double span = std::min(elapsed, kMaxCatchUpPeriods * period);
  const int periods = static_cast<int>(std::lround(span / period));  // 2 or more
  // (A gap of whole periods measured on a clock of large times is off by rounding: 4 periods
  // may come out a hair over 4.)
  const int steps = static_cast<int>(std::ceil(span / (kCatchUpStepPeriods * period) - 1e-6));  // at most `periods`
  const double h = span / steps;
  int read = 0;  // readings taken, one per period
  for (int k = 1; k <= steps; ++k) {
    const JointVector q0 = q_, v0 = qd_;  // the step's start, for the readings within it
    integrate(tau, h);
    // The periods this step covers (the steps share them out evenly), each with a reading: the
    // state interpolated between the step's ends, the last one the step's end.
    const int within = periods * k / steps - read;
    for (int j = 1; delay_ > 0 && j < within; ++j) {  // (without a delay only the last reading is kept)
      const double f = static_cast<double>(j) / within;
      pushReading(q0 + f * (q_ - q0), v0 + f * (qd_ - v0));
    }
    pushReading(q_, qd_);
    read += within;
  }
  return steps;
}

void ManipulatorSimulation::setExternalLinkWrench(int link, const Vector<3>& point, const Vector<6>& wrench) {
  const int n = model_.getNumberOfJoints();
  if (link < 1 || link > n) {
    throw std::out_of_range("ManipulatorSimulation::setExternalLinkWrench: link " + std::to_string(link) +
                            " is not in 1.." + std::to_string(n));
  }
  const auto k = static_cast<std::size_t>(link - 1);
  const bool was = acts(linkWrench_[k]);
  linkPoint_[k] = point;
  linkWrench_[k] = wrench;
  linkWrenches_ += (acts(wrench) ? 1 : 0) - (was ? 1 : 0);
}

void ManipulatorSimulation::clearExternalLinkWrenches() {
  for (Vector<6>& w : linkWrench_) w.setZero();
  linkWrenches_ = 0;
}

void ManipulatorSimulation::externalTorque() {
  tauExt_.setZero();
  if (linkWrenches_ == 0 && !acts(wrench_)) return;
  // One Jacobian J at the end-effector's origin e (it also computes the link frames). For a point
  // p moving with joints 1..k, column j <= k of its Jacobian is (Jv_j + Jw_j x (p - e), Jw_j), so
  // that column's torque is Jv_j . f + Jw_j . (m + (p - e) x f): the wrench moved to e.
  const Jacobian& J = jacobian(model_, data_, q_, ReferenceFrame::Base);
  if (acts(wrench_)) tauExt_.noalias() = J.transpose() * wrench_;
  if (linkWrenches_ == 0) return;
  const Eigen::Vector3d e = data_.endEffector.topRightCorner<3, 1>();
  const int n = model_.getNumberOfJoints();
  for (int k = 0; k < n; ++k) {
    const Vector<6>& w = linkWrench_[static_cast<std::size_t>(k)];
    if (!acts(w)) continue;
    const Transform& T = data_.linkTransforms[static_cast<std::size_t>(k)];
    const Eigen::Vector3d p =
        T.topLeftCorner<3, 3>() * Eigen::Vector3d(linkPoint_[static_cast<std::size_t>(k)]) + T.topRightCorner<3, 1>();
    const Eigen::Vector3d f = w.head<3>();
    const Eigen::Vector3d m = w.tail<3>() + (p - e).cross(f);
    for (int j = 0; j <= k; ++j) tauExt_(j) += J.col(j).head<3>().dot(f) + J.col(j).tail<3>().dot(m);
  }
}

void ManipulatorSimulation::eulerStep(double h) {
  // Semi-implicit Euler with the viscous friction and the joint stops implicit in the velocity:
  // M (v+ - v) = h (tau - bias - k (q + h v+ - limit) - (b + c) v+), that is
  // (M + h diag(b + c + h k)) v+ = M (v + h qdd0) with qdd0 = M^-1 (tau - bias - k (q - limit)).
  const int n = model_.getNumberOfJoints();
  const double k = stopStiffness_;
  StepScratch& sc = stepScratch();
  // A stop acts on the penetration at the end of the step, so it engages in the step in which the
  // joint would cross its limit (q + h v beyond it): a joint never enters a stop by a whole step's
  // travel unopposed (that would store spring energy it never had).
  sc.tauTotal = tauApplied_ - viscous_.cwiseProduct(qd_);
  bool implicit = hasCoulomb_ || brakes_;  // a term implicit in v+ (else v+ = v + h qdd0)
  for (int i = 0; i < n; ++i) {
    const double lo = model_.getPositionMin()(i), hi = model_.getPositionMax()(i), next = q_(i) + h * qd_(i);
    engaged_[static_cast<std::size_t>(i)] = q_(i) < lo || q_(i) > hi || next < lo || next > hi;
    implicit = implicit || viscous_(i) != 0 || engaged_[static_cast<std::size_t>(i)];
    if (!engaged_[static_cast<std::size_t>(i)]) continue;
    sc.tauTotal(i) += k * ((q_(i) > hi || next > hi ? hi : lo) - q_(i));
  }
  const ManipulatorData& d = internal::workspaceOr(model_, data_);
  if (!implicit) {  // no friction, no stop: the explicit step, from the forward dynamics solved
    dynamics(q_, qd_, sc.tauTotal, true);
    qdd_ = d.qdd;
    accelerationPending_ = false;
    qd_ += h * qdd_;
    q_ += h * qd_;
    return;
  }
  dynamics(q_, qd_, sc.tauTotal, false);  // M, and r = tauTotal - h in d.qdd (not solved)
  const JointMatrix& M = d.massMatrix;
  sc.diag.resize(n);
  for (int i = 0; i < n; ++i) {
    sc.diag(i) = viscous_(i);
    // A stop critically damped for the joint's inertia at the stop.
    if (engaged_[static_cast<std::size_t>(i)]) sc.diag(i) += 2.0 * std::sqrt(k * M(i, i)) + h * k;
  }
  // The accelerations at the start of the step, M^-1 r (getAcceleration()), are solved for only
  // when asked: the step below needs M and r, not them.
  stepStart_.resize(n, 3);
  stepStart_.col(0) = q_;
  stepStart_.col(1) = qd_;
  stepStart_.col(2) = sc.tauTotal;
  accelerationPending_ = true;
  // With qdd0 = M^-1 r (the viscous torque in r at the start of the step, so the right-hand side
  // adds it back): M (v + h qdd0) + h b v = M v + h (r + b v).
  symmetricTimes(M, qd_, sc.rhs);
  for (int i = 0; i < n; ++i) sc.rhs(i) += h * (d.qdd(i) + viscous_(i) * qd_(i));
  sc.A = M;
  for (int i = 0; i < n; ++i) sc.A(i, i) += h * sc.diag(i);
  if (hasCoulomb_ || brakes_) {
    // The contact mode of the step's start velocities is tried first; the sweeps, if it is not
    // the minimiser's, start from v + h qdd0 (solveFriction()).
    sc.start = qd_;
    sc.eulerSweeps = true;
    solveFriction(h);
  } else {
    // v+ = A^-1 rhs by Cholesky (A is positive definite).
    sc.L.resize(n, n);
    choleskySolve(sc.A, sc.rhs, sc.L, qd_);
  }
  q_ += h * qd_;
}

void ManipulatorSimulation::rk4Step(double h) {
  // The classical Runge-Kutta method on q' = v, v' = M^-1 (tau - bias - b v), the applied and
  // external torques held over the step; then Coulomb friction and brakes as the same constraint
  // as in the Euler step, taken over the step (the position moves by half the velocity change, as
  // under a constant friction torque; a joint at rest that stays at rest does not move at all).
  const int n = model_.getNumberOfJoints();
  StepScratch& sc = stepScratch();
  sc.q0 = q_;
  sc.v0 = qd_;
  sc.sumQ.setZero(n);
  sc.sumV.setZero(n);
  const ManipulatorData& d = internal::workspaceOr(model_, data_);  // where dynamics() leaves its results
  for (int s = 0; s < 4; ++s) {
    sc.tauTotal = tauApplied_ - viscous_.cwiseProduct(qd_);
    dynamics(q_, qd_, sc.tauTotal, true);
    sc.kq = qd_;
    sc.kv = d.qdd;
    if (s == 0) {
      qdd_ = sc.kv;
      accelerationPending_ = false;
    }
    const double w = (s == 0 || s == 3) ? 1.0 : 2.0;
    sc.sumQ += w * sc.kq;
    sc.sumV += w * sc.kv;
    if (s < 3) {
      const double c = s < 2 ? 0.5 * h : h;
      q_ = sc.q0 + c * sc.kq;
      qd_ = sc.v0 + c * sc.kv;
    }
  }
  q_ = sc.q0 + (h / 6.0) * sc.sumQ;
  qd_ = sc.v0 + (h / 6.0) * sc.sumV;
  if (hasCoulomb_ || brakes_) {
    // The mass matrix at the last stage (q0 + h v3), the end of the step to first order.
    sc.A = d.massMatrix;
    symmetricTimes(sc.A, qd_, sc.rhs);
    sc.residual.setZero(n);  // A qd - rhs
    sc.kv = qd_;
    sc.start = sc.v0;
    sc.eulerSweeps = false;
    solveFriction(h);
    for (int i = 0; i < n; ++i)
      q_(i) = (sc.v0(i) == 0 && qd_(i) == 0) ? sc.q0(i) : q_(i) + 0.5 * h * (qd_(i) - sc.kv(i));
  }
}

void ManipulatorSimulation::solveFriction(double h) {
  // Minimise 1/2 v^T A v - rhs^T v + h sum_i f_i(v_i), f_i(v) = F+ v (v > 0), -F- v (v < 0), by
  // exact coordinate descent from a start in qd_ with its residual A qd_ - rhs in the scratch's
  // residual (the RK4 step sets both; the Euler step's are made below, if the sweeps run): each
  // coordinate's minimiser is a soft threshold. The objective is strictly convex, so the sweeps
  // converge to its minimiser; a joint whose holding torque is within its friction comes out
  // exactly at rest.
  const int n = model_.getNumberOfJoints();
  StepScratch& sc = stepScratch();
  const JointMatrix& A = sc.A;
  sc.upper.resize(n);
  sc.lower.resize(n);
  for (int i = 0; i < n; ++i) {
    const double brake = brakes_ ? brakeTorque_(i) : 0.0;
    sc.upper(i) = h * (coulombPos_(i) + brake);
    sc.lower(i) = h * (coulombNeg_(i) + brake);
  }
  // The contact mode of the velocities the step started from (which joints stuck, which way the
  // others slid) is usually the minimiser's: that mode's exact solution, if it is optimal, needs
  // no sweep (and is the sweeps' result too: the minimiser is unique, and a mode's solution
  // depends on the mode alone). solveContactMode() replaces `start` by it then.
  const std::uint64_t startMode = contactMode(sc.start);
  if (solveContactMode(A, sc.rhs, sc.upper, sc.lower, sc.start)) {
    qd_ = sc.start;
    return;
  }
  if (sc.eulerSweeps) {
    // The Euler step's sweeps start from its velocity without the implicit terms, v + h qdd0
    // (qdd0 = M^-1 r: M and r = tau - h in the workspace), closer to the minimiser than v: its
    // residual A (v + h qdd0) - rhs = h (diag (v + h qdd0) - b v) takes no product with A, and
    // M is factorized only here, when the start's mode was not the minimiser's.
    const ManipulatorData& d = internal::workspaceOr(model_, data_);
    sc.L.resize(n, n);
    choleskySolve(d.massMatrix, d.qdd, sc.L, sc.v0);  // qdd0
    sc.residual.resize(n);
    for (int i = 0; i < n; ++i) {
      sc.v0(i) = qd_(i) + h * sc.v0(i);
      sc.residual(i) = h * (sc.diag(i) * sc.v0(i) - viscous_(i) * qd_(i));
    }
    qd_ = sc.v0;
  }
  std::uint64_t lastMode = contactMode(qd_), triedMode = startMode;
  for (int sweep = 0; sweep < kMaxFrictionSweeps; ++sweep) {
    double change = 0;
    for (int i = 0; i < n; ++i) {
      const double a = A(i, i);
      const double p = a * qd_(i) - sc.residual(i);  // a times the coordinate's unconstrained minimiser
      double x = 0;
      if (!std::isfinite(p)) {
        x = p;  // a force that is not finite (e.g. from the environment) is no friction problem:
                // the state becomes non-finite, which the servo loop sees and stops on
      } else if (p > sc.upper(i)) {
        x = (p - sc.upper(i)) / a;
      } else if (p < -sc.lower(i)) {
        x = (p + sc.lower(i)) / a;
      }
      const double d = x - qd_(i);
      if (d == 0) continue;
      qd_(i) = x;
      sc.residual += A.col(i) * d;
      change = std::max(change, std::abs(d));
    }
    if (change <= kFrictionTolerance) break;
    // The contact mode the sweep has reached is usually the minimiser's after one sweep: that
    // mode's exact solution, if it is optimal, ends the sweeps. Later, a mode is tried once a
    // sweep leaves it unchanged, and never again after failing (its solution depends on the mode
    // alone).
    const std::uint64_t mode = contactMode(qd_);
    if ((sweep == 0 || mode == lastMode) && mode != triedMode) {
      if (solveContactMode(A, sc.rhs, sc.upper, sc.lower, qd_)) break;
      triedMode = mode;
    }
    lastMode = mode;
  }
}


void ManipulatorSimulation::declareSettings(SettingSchema& schema) {
  schema.addChoice("integrator", {"euler", "rk4"}, "integrator of the simulated arm (semi-implicit Euler or RK4)");
  auto perJointNumbers = [&schema](const char* name, const char* unit, const char* description, double lo, double hi) {
    SettingSpec spec;
    spec.name = name;
    spec.kind = SettingKind::Number;
    spec.minValues = 1;
    spec.maxValues = kMaxJoints;
    spec.unit = unit;
    spec.description = description;
    spec.minValue = lo;
    spec.maxValue = hi;
    schema.add(spec);
  };
  perJointNumbers("simMassScale", "", "simulated plant: factor on the link masses (one for all links, or one per link)",
                  0.1, 10);
  perJointNumbers("simInertiaScale", "",
                  "simulated plant: factor on the link inertias (one for all links, or one per link)", 0.1, 10);
  perJointNumbers("simFrictionScale", "",
                  "simulated plant: factor on the joint friction (one for all joints, or one per joint)", 0, 10);
  schema.addNumbers("simPayload", 1, "kg", "simulated plant: point mass at the tool frame's origin", 0, 1000);
  perJointNumbers("simEncoderOffset", "deg or mm",
                  "simulated encoders: reading minus the joint's true position (one per joint; revolute in deg, "
                  "prismatic in mm)",
                  -10, 10);
  perJointNumbers("simCountsPerRadian", "counts/rad",
                  "simulated encoders: resolution (one for all joints, or one per joint)", 1, 1e12);
  schema.addInteger("simSensorDelay", "simulated sensors: delay of the joint readings [servo cycles]", 0,
                    ManipulatorSimulation::kMaxSensorDelay);
  schema.addChoice("simFriction", {"on", "off"}, "simulated plant: joint friction");
  schema.addChoice("simMotorInertia", {"on", "off"}, "simulated plant: reflected motor inertia");
  perJointNumbers("simInitialPosition", "deg or mm",
                  "simulated arm: initial joint positions (one per joint; revolute in deg, prismatic in mm)", -1e6, 1e6);
  perJointNumbers("simInitialVelocity", "deg/s or mm/s",
                  "simulated arm: initial joint velocities (one per joint; revolute in deg/s, prismatic in mm/s)",
                  -1e6, 1e6);
  schema.setDefault("integrator", "rk4");
  schema.setDefault("simMassScale", "1");
  schema.setDefault("simInertiaScale", "1");
  schema.setDefault("simFrictionScale", "1");
  schema.setDefault("simPayload", "0");
  schema.setDefault("simEncoderOffset", "0");
  schema.setDefault("simCountsPerRadian", "(none: exact readings)");
  schema.setDefault("simSensorDelay", "0");
  schema.setDefault("simFriction", "on");
  schema.setDefault("simMotorInertia", "on");
  schema.setDefault("simInitialPosition", "(the model's home position)");
  schema.setDefault("simInitialVelocity", "0");
}

std::unique_ptr<ManipulatorSimulation> makeSimulation(const ManipulatorModel& nominal, const ConfigSection* section) {
  if (section == nullptr) return std::make_unique<ManipulatorSimulation>(nominal);
  const int n = nominal.getNumberOfJoints();
  // A setting of one value for all joints or one per joint, as a joint vector (empty if absent).
  auto joints = [&](const char* name, bool perJointOnly) -> JointVector {
    const ConfigSetting* s = section->find(name);
    if (s == nullptr) return JointVector();
    const std::vector<double> values = section->getNumbers(name);
    const auto count = static_cast<int>(values.size());
    if (count != n && (perJointOnly || count != 1)) {
      throw section->errorAt(*s, std::string(name) + ": " + std::to_string(count) + " values for an arm of " +
                                     std::to_string(n) + " joints (give " +
                                     (perJointOnly ? std::to_string(n) : "1 for all joints or " + std::to_string(n)) +
                                     ")");
    }
    JointVector v(n);
    for (int i = 0; i < n; ++i) v(i) = values[static_cast<std::size_t>(count == 1 ? 0 : i)];
    return v;
  };
  auto onOff = [&](const char* name) {
    const ConfigSetting* s = section->find(name);
    return s == nullptr || section->getWord(name) != "off";
  };
  // Each deviation is checked where it is read, so that an error names its line.
  auto check = [&](const char* name, auto&& f) {
    try {
      f();
    } catch (const std::invalid_argument& e) {
      throw section->errorAt(*section->find(name), e.what());
    }
  };
  PlantDeviations d;
  d.massScale = joints("simMassScale", false);
  d.inertiaScale = joints("simInertiaScale", false);
  d.frictionScale = joints("simFrictionScale", false);
  if (section->has("simPayload")) d.payload = section->getNumbers("simPayload").at(0);
  d.friction = onOff("simFriction");
  d.motorInertia = onOff("simMotorInertia");
  // Each deviation alone, so that an error names the line of the setting at fault.
  for (const char* name : {"simMassScale", "simInertiaScale", "simFrictionScale", "simPayload"}) {
    if (!section->has(name)) continue;
    PlantDeviations one;
    const std::string setting = name;
    if (setting == "simMassScale") one.massScale = d.massScale;
    if (setting == "simInertiaScale") one.inertiaScale = d.inertiaScale;
    if (setting == "simFrictionScale") one.frictionScale = d.frictionScale;
    if (setting == "simPayload") one.payload = d.payload;
    check(name, [&] { (void)buildPlant(nominal, one); });
  }
  const bool deviates = d.massScale.size() > 0 || d.inertiaScale.size() > 0 || d.frictionScale.size() > 0 ||
                        d.payload > 0 || !d.friction || !d.motorInertia;
  auto sim = deviates ? std::make_unique<ManipulatorSimulation>(nominal, d) : std::make_unique<ManipulatorSimulation>(nominal);

  if (section->has("integrator"))
    sim->setIntegrator(section->getWord("integrator") == "euler" ? SimulationIntegrator::Euler : SimulationIntegrator::RK4);
  const JointVector counts = joints("simCountsPerRadian", false);
  int delay = 0;
  if (section->has("simSensorDelay")) delay = static_cast<int>(section->getNumbers("simSensorDelay").at(0));
  if (counts.size() > 0) check("simCountsPerRadian", [&] { sim->setSensor(counts, 0); });
  if (delay != 0) check("simSensorDelay", [&] { sim->setSensor(counts, delay); });
  if (JointVector offset = joints("simEncoderOffset", true); offset.size() > 0) {
    for (int i = 0; i < n; ++i) offset(i) *= nominal.isPrismatic(i) ? 1e-3 : 3.14159265358979323846 / 180.0;
    sim->setEncoderOffset(offset);
  }

  // Initial state: revolute joints in degrees, prismatic ones in millimetres.
  JointVector q = joints("simInitialPosition", true), qd = joints("simInitialVelocity", true);
  if (q.size() > 0 || qd.size() > 0) {
    const double deg = 3.14159265358979323846 / 180.0;
    for (JointVector* v : {&q, &qd})
      for (int i = 0; i < v->size(); ++i) (*v)(i) *= nominal.isPrismatic(i) ? 1e-3 : deg;
    if (q.size() > 0) {
      for (int i = 0; i < n; ++i)
        if (q(i) < nominal.getPositionMin()(i) || q(i) > nominal.getPositionMax()(i))
          throw section->errorAt(*section->find("simInitialPosition"),
                                 "simInitialPosition: joint " + std::to_string(i + 1) + " is outside its limits");
    } else {
      q = sim->getTruePosition();
    }
    if (qd.size() == 0) qd = JointVector::Zero(n);
    // A start beyond a velocity limit is a shutdown in the first cycle (and 1e6 deg/s gave NaN
    // joints): refused here, at the setting's line, as a start outside the position limits is.
    for (int i = 0; i < n; ++i)
      if (std::abs(qd(i)) > nominal.getVelocityLimit()(i)) {
        char detail[160];
        std::snprintf(detail, sizeof detail, "simInitialVelocity: joint %d: %g %s is beyond its velocity limit %g %s",
                      i + 1, qd(i) / (nominal.isPrismatic(i) ? 1e-3 : deg), nominal.isPrismatic(i) ? "mm/s" : "deg/s",
                      nominal.getVelocityLimit()(i) / (nominal.isPrismatic(i) ? 1e-3 : deg),
                      nominal.isPrismatic(i) ? "mm/s" : "deg/s");
        throw section->errorAt(*section->find("simInitialVelocity"), detail);
      }
    sim->setState(q, qd);
  }
  return sim;
}

}  // namespace rp
