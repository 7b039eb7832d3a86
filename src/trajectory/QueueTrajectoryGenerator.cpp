// The queue of motion segments (rp/trajectory/QueueTrajectoryGenerator.hpp).
#include "rp/trajectory/QueueTrajectoryGenerator.hpp"

#include <chrono>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <thread>

#include "../core/ShortNumber.hpp"
#include "Blend.hpp"
#include "CartesianPath.hpp"
#include "rp/core/ObjectManager.hpp"
#include "rp/manipulator/Manipulator.hpp"
#include "rp/rt/ControlProgram.hpp"

namespace rp {

// One place of the ring. The producer (the user's thread, under producerMutex_) writes `plan`
// before publishing the slot through tail_; servo threads then only read it.
struct QueueTrajectoryGenerator::Slot {
  internal::SegmentPlan plan;
  std::atomic<double> startTime{0};  // clock time of local time 0
  std::atomic<int> state{0};         // 0 waiting, 1 being started, 2 started
  std::atomic<int> successor{0};     // blend into the next slot: 0 undecided, 1 accepted, 2 refused
  std::atomic<double> acceptedExit{0};  // where an accepted blend begins (local time), set before accepting
};

struct QueueTrajectoryGenerator::Limits {
  JointVector velocity, acceleration, jerk;
};

namespace {

bool anyRunning(const std::vector<Manipulator*>& manipulators) {
  for (Manipulator* m : manipulators) {
    ControlProgram* p = m->getControlProgram();
    if (p != nullptr && p->isRunning()) return true;
  }
  return false;
}

constexpr double kDeg = 180 / std::numbers::pi;

}  // namespace

QueueTrajectoryGenerator::QueueTrajectoryGenerator(const std::string& name)
    : TrajectoryGenerator(name), ring_(std::make_unique<std::array<Slot, kCapacity>>()) {}

QueueTrajectoryGenerator::~QueueTrajectoryGenerator() { waitUntilDone(); }

void QueueTrajectoryGenerator::attach(Manipulator& manipulator) {
  std::lock_guard<std::mutex> lock(producerMutex_);
  const std::vector<Manipulator*> connected = getManipulators();
  if (!connected.empty() && connected.front()->getNumberOfJoints() != manipulator.getNumberOfJoints()) {
    throw std::invalid_argument(getName() + ": cannot drive '" + manipulator.getName() + "' (" +
                                std::to_string(manipulator.getNumberOfJoints()) + " joints) together with '" +
                                connected.front()->getName() + "' (" +
                                std::to_string(connected.front()->getNumberOfJoints()) + " joints)");
  }
}

Manipulator& QueueTrajectoryGenerator::getPlanningManipulator() const {
  const std::vector<Manipulator*> connected = getManipulators();
  if (connected.empty()) {
    throw std::logic_error(getName() + ": no manipulator is connected; call setTrajectoryGenerator() first");
  }
  return *connected.front();
}

JointVector QueueTrajectoryGenerator::getLastTarget() const {
  std::lock_guard<std::mutex> lock(producerMutex_);
  if (haveTarget_) return lastTarget_;  // the generator holds its last target when done
  return getPlanningManipulator().getJointPosition();
}

QueueTrajectoryGenerator::Limits QueueTrajectoryGenerator::planningLimits(const ManipulatorModel& model) const {
  std::lock_guard<std::mutex> lock(producerMutex_);
  const int n = model.getNumberOfJoints();
  const bool user = userVelocity_.size() == n;
  Limits l;
  l.velocity = speedFraction_ * (user ? userVelocity_ : model.getVelocityLimit());
  l.acceleration = speedFraction_ * (user ? userAcceleration_ : model.getAccelerationLimit());
  l.jerk = speedFraction_ * (user ? userJerk_ : model.getJerkLimit());
  return l;
}

void QueueTrajectoryGenerator::queueJointMotion(const JointVector& target) {
  Manipulator& m = getPlanningManipulator();
  const ManipulatorModel& model = m.getModel();
  const int n = model.getNumberOfJoints();
  if (target.size() != n) {
    throw std::invalid_argument(getName() + ": a target of " + std::to_string(target.size()) + " joint values for '" +
                                m.getName() + "', which has " + std::to_string(n) + " joints");
  }
  for (int i = 0; i < n; ++i) {
    if (!(target(i) >= model.getPositionMin()(i) && target(i) <= model.getPositionMax()(i))) {
      throw std::invalid_argument(getName() + ": target joint " + std::to_string(i + 1) + " = " +
                                  std::to_string(target(i) * kDeg) + " deg is outside the limits [" +
                                  std::to_string(model.getPositionMin()(i) * kDeg) + ", " +
                                  std::to_string(model.getPositionMax()(i) * kDeg) + "] deg of '" + m.getName() + "'");
    }
  }
  if (userVelocity_.size() != 0 && userVelocity_.size() != n) {
    throw std::invalid_argument(getName() + ": the joint limits set have " + std::to_string(userVelocity_.size()) +
                                " values for '" + m.getName() + "', which has " + std::to_string(n) + " joints");
  }
  const JointVector start = getLastTarget();
  if (start == target) return;  // already there
  const Limits l = planningLimits(model);
  internal::SegmentPlan plan;
  plan.kind = internal::SegmentKind::Line;
  plan.line = SynchronizedJointMotion(start, target, l.velocity, l.acceleration, l.jerk, getSynchronization());
  plan.duration = plan.line.getDuration();
  plan.end = target;
  plan.exitTime = plan.duration;
  const double radius = getJointBlendRadius(), distance = (target - start).norm();
  if (radius > 0 && distance > 0) {
    // Within the radius of either end, at most half-way (for a straight line: the fractions
    // 1 - radius / distance and radius / distance, each capped at 0.5).
    const double r = std::min(radius, 0.5 * distance);
    plan.exitTime = plan.line.timeWithinOfTarget(r);
    plan.entryTime = plan.line.timeWithinOfStart(r);
  }
  pushPlanned(std::move(plan));
}

void QueueTrajectoryGenerator::queueCartesianMotion(const Transform& pose) {
  Manipulator& m = getPlanningManipulator();
  const ManipulatorModel& model = m.getModel();
  const std::string who = getName() + ": '" + m.getName() + "': ";
  if (model.getNumberOfJoints() < 6) {
    throw std::invalid_argument(who + "a straight-line Cartesian motion needs at least six joints, the arm has " +
                                std::to_string(model.getNumberOfJoints()));
  }
  const Limits l = planningLimits(model);
  internal::SegmentPlan plan =
      internal::planCartesianLine(model, getLastTarget(), pose, getCartesianLimits(), l.velocity, l.acceleration, l.jerk, who);
  if (plan.kind == internal::SegmentKind::Dwell) return;  // already there
  const double radius = getCartesianBlendRadius();
  if (radius > 0 && plan.length > 0) {
    plan.exitTime = plan.timeAtFraction(std::max(0.5, 1 - radius / plan.length));
    plan.entryTime = plan.timeAtFraction(std::min(0.5, radius / plan.length));
  }
  pushPlanned(std::move(plan));
}

void QueueTrajectoryGenerator::queueDwell(double seconds) {
  if (!(seconds >= 0) || !std::isfinite(seconds)) {
    throw std::invalid_argument(getName() + ": a dwell must last a finite time >= 0 s");
  }
  internal::SegmentPlan plan;
  plan.kind = internal::SegmentKind::Dwell;
  plan.hold = getLastTarget();
  plan.end = plan.hold;
  plan.duration = plan.exitTime = seconds;
  pushPlanned(std::move(plan));
}

void QueueTrajectoryGenerator::waitForRoom(int slots) {
  // Two slots stay free so that no servo thread ever reads a slot being refilled (nor the slot
  // before the one it reads).
  while (tail_.load() + static_cast<std::uint64_t>(slots) - head_.load() > static_cast<std::uint64_t>(kCapacity - 2)) {
    if (ObjectManager::isShutdownRequested() || !anyRunning(getManipulators())) {
      throw std::runtime_error(getName() + ": the queue is full and no manipulator is running");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

void QueueTrajectoryGenerator::publish(std::uint64_t index, internal::SegmentPlan&& plan) {
  Slot& s = (*ring_)[index % kCapacity];
  s.plan = std::move(plan);
  s.startTime.store(0, std::memory_order_relaxed);
  s.state.store(0, std::memory_order_relaxed);
  s.successor.store(0, std::memory_order_relaxed);
  s.acceptedExit.store(s.plan.duration, std::memory_order_relaxed);
}

void QueueTrajectoryGenerator::pushPlanned(internal::SegmentPlan&& plan) {
  Manipulator& m = getPlanningManipulator();
  const Limits l = planningLimits(m.getModel());
  std::lock_guard<std::mutex> lock(producerMutex_);
  const bool motion = plan.kind == internal::SegmentKind::Line || plan.kind == internal::SegmentKind::Path;
  const JointVector end = plan.end;
  if (motion && lastMotion_ != 0 && plan.entryTime > 0) {
    Slot& prev = (*ring_)[(lastMotion_ - 1) % kCapacity];
    internal::SegmentPlan blend;
    double entry = 0;
    if (prev.plan.exitTime < prev.plan.duration && prev.successor.load(std::memory_order_acquire) == 0 &&
        internal::planBlend(prev.plan, plan, l.velocity, l.acceleration, l.jerk, blend, entry)) {
      plan.entryTime = entry;
      const bool overlap = blend.from != nullptr;
      waitForRoom(2);
      const std::uint64_t t = tail_.load(std::memory_order_relaxed);
      publish(t, std::move(blend));
      publish(t + 1, std::move(plan));
      Slot& b = (*ring_)[t % kCapacity];
      if (overlap) {
        b.plan.from = &prev.plan;
        b.plan.to = &(*ring_)[(t + 1) % kCapacity].plan;
      }
      prev.acceptedExit.store(b.plan.fromStart, std::memory_order_relaxed);
      tail_.store(t + 2, std::memory_order_release);
      // Too late if a servo thread has already passed the exit point: the blend is then skipped.
      int undecided = 0;
      prev.successor.compare_exchange_strong(undecided, 1, std::memory_order_acq_rel);
      ++blends_;
      lastMotion_ = t + 2;
      lastTarget_ = end;
      haveTarget_ = true;
      return;
    }
  }
  waitForRoom(1);
  const std::uint64_t t = tail_.load(std::memory_order_relaxed);
  publish(t, std::move(plan));
  tail_.store(t + 1, std::memory_order_release);
  lastMotion_ = motion ? t + 1 : 0;
  lastTarget_ = end;
  haveTarget_ = true;
}

void QueueTrajectoryGenerator::setSpeedFraction(double fraction) {
  if (!(fraction > 0 && fraction <= 1)) {
    throw std::invalid_argument(getName() + ": the speed fraction must lie in (0, 1], got " + internal::shortNumber(fraction));
  }
  std::lock_guard<std::mutex> lock(producerMutex_);
  speedFraction_ = fraction;
}

void QueueTrajectoryGenerator::setJointLimits(const JointVector& velocity, const JointVector& acceleration,
                                              const JointVector& jerk) {
  if (velocity.size() != acceleration.size() || velocity.size() != jerk.size() || velocity.size() == 0) {
    throw std::invalid_argument(getName() + ": the velocity, acceleration and jerk limits must have one value per joint");
  }
  for (Eigen::Index i = 0; i < velocity.size(); ++i) {
    if (!(velocity(i) > 0 && acceleration(i) > 0 && jerk(i) > 0) || !std::isfinite(velocity(i) + acceleration(i) + jerk(i))) {
      throw std::invalid_argument(getName() + ": the limits of joint " + std::to_string(i + 1) + " must be positive");
    }
  }
  std::lock_guard<std::mutex> lock(producerMutex_);
  userVelocity_ = velocity;
  userAcceleration_ = acceleration;
  userJerk_ = jerk;
}

void QueueTrajectoryGenerator::clearJointLimits() {
  std::lock_guard<std::mutex> lock(producerMutex_);
  userVelocity_ = userAcceleration_ = userJerk_ = JointVector();
}

void QueueTrajectoryGenerator::setCartesianLimits(const CartesianLimits& limits) {
  for (double v : {limits.linearVelocity, limits.linearAcceleration, limits.linearJerk, limits.angularVelocity,
                   limits.angularAcceleration, limits.angularJerk}) {
    if (!(v > 0) || !std::isfinite(v)) throw std::invalid_argument(getName() + ": Cartesian limits must be positive");
  }
  std::lock_guard<std::mutex> lock(producerMutex_);
  cartesianLimits_ = limits;
}

CartesianLimits QueueTrajectoryGenerator::getCartesianLimits() const {
  std::lock_guard<std::mutex> lock(producerMutex_);
  return cartesianLimits_;
}

void QueueTrajectoryGenerator::setJointBlendRadius(double radians) {
  setRadius(jointBlendRadius_, radians, "joint blend radius", "rad");
}

double QueueTrajectoryGenerator::getJointBlendRadius() const {
  std::lock_guard<std::mutex> lock(producerMutex_);
  return jointBlendRadius_;
}

void QueueTrajectoryGenerator::setCartesianBlendRadius(double metres) {
  setRadius(cartesianBlendRadius_, metres, "Cartesian blend radius", "m");
}

void QueueTrajectoryGenerator::setRadius(double& radius, double value, const char* what, const char* unit) {
  if (!(value >= 0) || !std::isfinite(value)) {
    throw std::invalid_argument(getName() + ": the " + what + " must be finite and >= 0 " + unit);
  }
  std::lock_guard<std::mutex> lock(producerMutex_);
  radius = value;
}

double QueueTrajectoryGenerator::getCartesianBlendRadius() const {
  std::lock_guard<std::mutex> lock(producerMutex_);
  return cartesianBlendRadius_;
}

void QueueTrajectoryGenerator::setSynchronization(Synchronization mode) {
  if (mode != Synchronization::Time && mode != Synchronization::Phase && mode != Synchronization::None) {
    throw std::invalid_argument(getName() + ": unknown synchronisation mode " + std::to_string(static_cast<int>(mode)));
  }
  std::lock_guard<std::mutex> lock(producerMutex_);
  synchronization_ = mode;
}

Synchronization QueueTrajectoryGenerator::getSynchronization() const {
  std::lock_guard<std::mutex> lock(producerMutex_);
  return synchronization_;
}

int QueueTrajectoryGenerator::getBlendCount() const {
  std::lock_guard<std::mutex> lock(producerMutex_);
  return blends_;
}

double QueueTrajectoryGenerator::startOf(Slot& slot, double time, double offset) {
  int expected = 0;
  if (slot.state.compare_exchange_strong(expected, 1, std::memory_order_acq_rel)) {
    slot.startTime.store(time - offset, std::memory_order_relaxed);
    slot.state.store(2, std::memory_order_release);
    return time - offset;
  }
  while (slot.state.load(std::memory_order_acquire) != 2) {
    // Another servo thread is between its two stores above: a few instructions.
  }
  return slot.startTime.load(std::memory_order_relaxed);
}

bool QueueTrajectoryGenerator::getCurrentSetpoint(double time, Setpoint& setpoint) {
  std::array<Slot, kCapacity>& ring = *ring_;
  for (int guard = 0; guard < 2 * kCapacity; ++guard) {
    const std::uint64_t h = head_.load(std::memory_order_acquire);
    if (h == tail_.load(std::memory_order_acquire)) {
      if (h == 0) return false;  // nothing was ever queued: the manipulator holds
      setpoint.position = ring[(h - 1) % kCapacity].plan.end;
      setpoint.velocity.setZero();
      setpoint.acceleration.setZero();
      return true;
    }
    Slot& seg = ring[h % kCapacity];
    if (seg.plan.conditional) {
      // A blend runs only if the motion before it accepted it; that decision is final by now.
      const Slot& prev = ring[(h - 1) % kCapacity];
      if (prev.successor.load(std::memory_order_acquire) != 1) {
        std::uint64_t expected = h;
        if (head_.compare_exchange_strong(expected, h + 1, std::memory_order_acq_rel) &&
            h + 1 < tail_.load(std::memory_order_acquire) && seg.state.load(std::memory_order_acquire) == 2) {
          // The skipped blend was timed to start when the motion before ended: so is the next.
          startOf(ring[(h + 1) % kCapacity], seg.startTime.load(std::memory_order_relaxed), 0);
        }
        continue;
      }
    }
    const double start = startOf(seg, time, 0);
    const double local = time - start;
    double end = seg.plan.duration;
    if (local >= seg.plan.exitTime) {
      int decided = 0;
      if (seg.successor.compare_exchange_strong(decided, 2, std::memory_order_acq_rel)) decided = 2;
      if (decided == 1) end = seg.acceptedExit.load(std::memory_order_relaxed);
    }
    if (local >= end) {
      // Finished: the next segment, if already queued, starts exactly when this one ends (a
      // motion entered from a blend at its entry time).
      std::uint64_t expected = h;
      if (head_.compare_exchange_strong(expected, h + 1, std::memory_order_acq_rel) &&
          h + 1 < tail_.load(std::memory_order_acquire)) {
        Slot& next = ring[(h + 1) % kCapacity];
        const double offset = seg.plan.kind == internal::SegmentKind::Blend ? next.plan.entryTime : 0;
        startOf(next, start + end, offset);
      }
      continue;
    }
    seg.plan.evaluate(local, setpoint);
    return true;
  }
  return false;
}

void QueueTrajectoryGenerator::stop(double seconds) {
  queueDwell(seconds);
  waitUntilDone();
}

bool QueueTrajectoryGenerator::isDone() const {
  return head_.load(std::memory_order_acquire) == tail_.load(std::memory_order_acquire);
}

int QueueTrajectoryGenerator::getSegmentsLeft() const {
  return static_cast<int>(tail_.load(std::memory_order_acquire) - head_.load(std::memory_order_acquire));
}

bool QueueTrajectoryGenerator::waitUntilDone(double timeoutSeconds) const {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeoutSeconds);
  while (!isDone()) {
    if (ObjectManager::isShutdownRequested() || !anyRunning(getManipulators())) return false;
    if (timeoutSeconds >= 0 && std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::microseconds(500));
  }
  return true;
}

}  // namespace rp
