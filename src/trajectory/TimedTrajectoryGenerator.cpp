// Timed joint trajectories executed one after another (rp/trajectory/TimedTrajectoryGenerator.hpp).
#include "rp/trajectory/TimedTrajectoryGenerator.hpp"

#include <atomic>
#include <cmath>
#include <deque>
#include <mutex>
#include <stdexcept>

#include "../manipulator/SeqlockHandover.hpp"
#include "rp/manipulator/Manipulator.hpp"

namespace rp {

namespace {

// A trajectory handed over, numbered in the order of execute().
struct Item {
  std::unique_ptr<TimedJointTrajectory> trajectory;
  std::uint64_t number = 0;
  double delay = 0;
};

}  // namespace

// Freeing without the servo thread: every Item belongs to `owned` (the callers' side, under
// `producer`). The servo thread publishes `oldestInUse`, the smallest number it may still use:
// its current trajectory's, or (when it has none) one more than the last it took. Items with a
// smaller number are neither used nor can they be taken (`incoming` only ever holds a newer one),
// so the callers' side frees them.
struct TimedTrajectoryGenerator::Shared {
  std::mutex producer;
  std::deque<std::unique_ptr<Item>> owned;
  std::uint64_t nextNumber = 1;
  std::atomic<Item*> incoming{nullptr};
  std::atomic<std::uint64_t> oldestInUse{0};
  std::atomic<std::uint64_t> handedOver{0};  // number of the last execute()
  std::atomic<std::uint64_t> finished{0};    // number of the last trajectory run to its end
  std::atomic<std::uint64_t> started{0};
  internal::SeqlockHandover<2 * kMaxJoints> last;  // position, velocity of the last setpoint
  std::atomic<int> lastJoints{0};

  // The servo thread's own.
  Item* current = nullptr;
  double currentStart = 0;
  Item* pending = nullptr;
  double pendingStart = 0;
  std::uint64_t lastTaken = 0;
  Setpoint state;
};

TimedTrajectoryGenerator::TimedTrajectoryGenerator(const std::string& name)
    : TrajectoryGenerator(name), shared_(std::make_unique<Shared>()) {}

TimedTrajectoryGenerator::~TimedTrajectoryGenerator() { releaseFromManipulators(); }

void TimedTrajectoryGenerator::attach(Manipulator& manipulator) {
  for (Manipulator* m : getManipulators())
    if (m != &manipulator)
      throw std::invalid_argument(getName() + ": drives '" + m->getName() + "' already; it cannot drive '" +
                                  manipulator.getName() + "' too");
}

void TimedTrajectoryGenerator::execute(std::unique_ptr<TimedJointTrajectory> trajectory, double delay) {
  if (!trajectory) throw std::invalid_argument(getName() + ": execute() without a trajectory");
  if (!(delay >= 0) || !std::isfinite(delay)) throw std::invalid_argument(getName() + ": a delay must be finite and >= 0 s");
  Shared& s = *shared_;
  std::lock_guard<std::mutex> lock(s.producer);
  auto item = std::make_unique<Item>();
  item->trajectory = std::move(trajectory);
  item->number = s.nextNumber++;
  item->delay = delay;
  Item* raw = item.get();
  s.owned.push_back(std::move(item));
  s.handedOver.store(raw->number, std::memory_order_release);
  s.incoming.store(raw, std::memory_order_release);  // one not taken yet is dropped: freed below
  const std::uint64_t oldest = s.oldestInUse.load(std::memory_order_acquire);
  while (!s.owned.empty() && s.owned.front()->number < oldest) s.owned.pop_front();
}

bool TimedTrajectoryGenerator::getCurrentSetpoint(double time, Setpoint& setpoint) {
  Shared& s = *shared_;
  if (Item* in = s.incoming.exchange(nullptr, std::memory_order_acq_rel)) {
    s.pending = in;  // a newer one replaces a pending one that has not started
    s.pendingStart = time + in->delay;
    s.lastTaken = in->number;
  }
  if (s.pending != nullptr && time >= s.pendingStart &&
      s.pending->trajectory->getNumberOfJoints() == static_cast<int>(setpoint.position.size())) {
    // Continuous with what the arm is given now: the trajectory under way, or the hold.
    if (s.current != nullptr) {
      s.current->trajectory->evaluate(time - s.currentStart, s.state);
    } else {
      s.state.position = setpoint.position;
      s.state.velocity = setpoint.velocity;
      s.state.acceleration = setpoint.acceleration;
    }
    s.pending->trajectory->start(s.state);
    s.current = s.pending;
    s.currentStart = time;
    s.pending = nullptr;
    s.started.fetch_add(1, std::memory_order_acq_rel);
  }
  s.oldestInUse.store(s.current != nullptr ? s.current->number : s.lastTaken + 1, std::memory_order_release);
  bool given = false;
  if (s.current != nullptr) {
    const TimedJointTrajectory& t = *s.current->trajectory;
    t.evaluate(time - s.currentStart, setpoint);
    if (time - s.currentStart >= t.getDuration()) s.finished.store(s.current->number, std::memory_order_release);
    given = true;
  }
  const auto n = static_cast<std::size_t>(setpoint.position.size());
  s.last.store(0, setpoint.position.data(), n);
  s.last.store(n, setpoint.velocity.data(), n);
  s.lastJoints.store(static_cast<int>(n), std::memory_order_release);
  return given;
}

bool TimedTrajectoryGenerator::isDone() const noexcept {
  return shared_->finished.load(std::memory_order_acquire) == shared_->handedOver.load(std::memory_order_acquire);
}

std::uint64_t TimedTrajectoryGenerator::getStartedCount() const noexcept {
  return shared_->started.load(std::memory_order_acquire);
}

bool TimedTrajectoryGenerator::getLastSetpoint(JointVector& position, JointVector& velocity) const noexcept {
  const int n = shared_->lastJoints.load(std::memory_order_acquire);
  if (n <= 0) return false;
  std::array<double, 2 * kMaxJoints> values{};
  if (!shared_->last.tryLoad(values.data(), 2 * static_cast<std::size_t>(n))) return false;
  position.resize(n);
  velocity.resize(n);
  for (int i = 0; i < n; ++i) {
    position(i) = values[static_cast<std::size_t>(i)];
    velocity(i) = values[static_cast<std::size_t>(n + i)];
  }
  return true;
}

std::size_t TimedTrajectoryGenerator::getHeldCount() const {
  std::lock_guard<std::mutex> lock(shared_->producer);
  return shared_->owned.size();
}

}  // namespace rp
