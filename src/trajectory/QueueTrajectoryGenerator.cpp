// The queue of motion segments (rp/trajectory/QueueTrajectoryGenerator.hpp).
#include "rp/trajectory/QueueTrajectoryGenerator.hpp"

#include <chrono>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <thread>

#include "rp/core/ObjectManager.hpp"
#include "rp/manipulator/Manipulator.hpp"
#include "rp/rt/ControlProgram.hpp"

namespace rp {

namespace {
bool anyRunning(const std::vector<Manipulator*>& manipulators) {
  for (Manipulator* m : manipulators) {
    ControlProgram* p = m->getControlProgram();
    if (p != nullptr && p->isRunning()) return true;
  }
  return false;
}
}  // namespace

QueueTrajectoryGenerator::QueueTrajectoryGenerator(const std::string& name) : TrajectoryGenerator(name) {}

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
      const double deg = 180 / std::numbers::pi;
      throw std::invalid_argument(getName() + ": target joint " + std::to_string(i + 1) + " = " +
                                  std::to_string(target(i) * deg) + " deg is outside the limits [" +
                                  std::to_string(model.getPositionMin()(i) * deg) + ", " +
                                  std::to_string(model.getPositionMax()(i) * deg) + "] deg of '" + m.getName() + "'");
    }
  }
  const JointVector start = getLastTarget();
  const JointVector delta = target - start;
  // One path parameter s in [0, 1] for all joints: the straight joint-space line, with the
  // tightest of the joints' limits scaled to s.
  double vs = INFINITY, as = INFINITY, js = INFINITY;
  for (int i = 0; i < n; ++i) {
    const double d = std::abs(delta(i));
    if (d == 0) continue;
    vs = std::min(vs, speedFraction_ * model.getVelocityLimit()(i) / d);
    as = std::min(as, speedFraction_ * model.getAccelerationLimit()(i) / d);
    js = std::min(js, speedFraction_ * model.getJerkLimit()(i) / d);
  }
  if (!std::isfinite(vs)) return;  // already there
  const JerkLimitedProfile profile(1.0, vs, as, js);
  push(start, delta, profile, profile.getDuration());
}

void QueueTrajectoryGenerator::setSpeedFraction(double fraction) {
  if (!(fraction > 0 && fraction <= 1)) {
    throw std::invalid_argument(getName() + ": the speed fraction must lie in (0, 1], got " + std::to_string(fraction));
  }
  speedFraction_ = fraction;
}

void QueueTrajectoryGenerator::queueDwell(double seconds) {
  if (!(seconds >= 0) || !std::isfinite(seconds)) {
    throw std::invalid_argument(getName() + ": a dwell must last a finite time >= 0 s");
  }
  const JointVector at = getLastTarget();
  push(at, JointVector(at.size()), JerkLimitedProfile(), seconds);
}

void QueueTrajectoryGenerator::push(const JointVector& start, const JointVector& delta,
                                    const JerkLimitedProfile& profile, double duration) {
  std::lock_guard<std::mutex> lock(producerMutex_);
  // Wait for room; two slots stay free so that no servo thread ever reads a slot being refilled.
  while (tail_.load() - head_.load() >= static_cast<std::uint64_t>(kCapacity - 2)) {
    if (ObjectManager::isShutdownRequested() || !anyRunning(getManipulators())) {
      throw std::runtime_error(getName() + ": the queue is full and no manipulator is running");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  const std::uint64_t t = tail_.load(std::memory_order_relaxed);
  Segment& s = ring_[t % kCapacity];
  s.start = start;
  s.delta = delta;
  s.profile = profile;
  s.duration = duration;
  s.startTime.store(0, std::memory_order_relaxed);
  s.state.store(0, std::memory_order_relaxed);
  tail_.store(t + 1, std::memory_order_release);
  lastTarget_ = start + delta;
  haveTarget_ = true;
}

double QueueTrajectoryGenerator::startOf(Segment& segment, double time) {
  int expected = 0;
  if (segment.state.compare_exchange_strong(expected, 1, std::memory_order_acq_rel)) {
    segment.startTime.store(time, std::memory_order_relaxed);
    segment.state.store(2, std::memory_order_release);
    return time;
  }
  while (segment.state.load(std::memory_order_acquire) != 2) {
    // Another servo thread is between its two stores above: a few instructions.
  }
  return segment.startTime.load(std::memory_order_relaxed);
}

bool QueueTrajectoryGenerator::getCurrentSetpoint(double time, Setpoint& setpoint) {
  for (int guard = 0; guard < kCapacity; ++guard) {
    const std::uint64_t h = head_.load(std::memory_order_acquire);
    if (h == tail_.load(std::memory_order_acquire)) {
      if (h == 0) return false;  // nothing was ever queued: the manipulator holds
      const Segment& last = ring_[(h - 1) % kCapacity];
      setpoint.position = last.start + last.delta;
      setpoint.velocity.setZero();
      setpoint.acceleration.setZero();
      return true;
    }
    Segment& seg = ring_[h % kCapacity];
    const double start = startOf(seg, time);
    const double elapsed = time - start;
    if (elapsed >= seg.duration) {
      // Finished: the next segment, if already queued, starts exactly when this one ends.
      std::uint64_t expected = h;
      if (head_.compare_exchange_strong(expected, h + 1, std::memory_order_acq_rel) &&
          h + 1 < tail_.load(std::memory_order_acquire)) {
        Segment& next = ring_[(h + 1) % kCapacity];
        int waiting = 0;
        if (next.state.compare_exchange_strong(waiting, 1, std::memory_order_acq_rel)) {
          next.startTime.store(start + seg.duration, std::memory_order_relaxed);
          next.state.store(2, std::memory_order_release);
        }
      }
      continue;
    }
    const ProfileState s = seg.profile.evaluate(elapsed);
    setpoint.position = seg.start + seg.delta * s.position;
    setpoint.velocity = seg.delta * s.velocity;
    setpoint.acceleration = seg.delta * s.acceleration;
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
