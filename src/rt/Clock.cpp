// Real and simulated clocks.
#include "rp/rt/Clock.hpp"

#include <time.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace rp {

namespace internal {
std::int64_t monotonicNanoseconds() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000LL + ts.tv_nsec;
}
}  // namespace internal

RealClock::RealClock() : epoch_(internal::monotonicNanoseconds()) {}

RealClock& RealClock::instance() {
  static RealClock* c = new RealClock;  // never destroyed
  return *c;
}

double RealClock::getTime() const noexcept {
  return static_cast<double>(internal::monotonicNanoseconds() - epoch_) * 1e-9;
}

SimulatedClock::SimulatedClock(double step, bool startPaused)
    : step_(step > 0 ? step : 1e-4), paused_(startPaused), neverResumed_(startPaused) {}

SimulatedClock::~SimulatedClock() = default;

double SimulatedClock::getTime() const noexcept { return tickTime(tick_.load()); }

// tick / (steps per second) when that is a whole number, so that times print as short decimals.
double SimulatedClock::tickTime(std::uint64_t tick) const noexcept {
  const double perSecond = 1.0 / step_;
  const double rounded = std::round(perSecond);
  if (std::abs(perSecond - rounded) < 1e-9 * rounded) return static_cast<double>(tick) / rounded;
  return static_cast<double>(tick) * step_;
}

std::uint64_t SimulatedClock::getTick() const noexcept { return tick_.load(); }

void SimulatedClock::pause() {
  std::lock_guard<std::mutex> lock(mutex_);
  paused_ = true;
}

void SimulatedClock::resume() {
  std::lock_guard<std::mutex> lock(mutex_);
  paused_ = false;
  if (neverResumed_) {  // the programs held at tick 0 begin
    neverResumed_ = false;
    cv_.notify_all();
  }
  advanceIfAllWaiting();
}

bool SimulatedClock::isPaused() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return paused_;
}

int SimulatedClock::getNumberOfPrograms() const {
  std::lock_guard<std::mutex> lock(mutex_);
  int n = 0;
  for (const Participant* p : participants_) n += p->programs.load();
  return n;
}

void SimulatedClock::attach(Participant& p) {
  std::lock_guard<std::mutex> lock(mutex_);
  p.waiting = false;
  participants_.push_back(&p);
}

void SimulatedClock::detach(Participant& p) {
  std::lock_guard<std::mutex> lock(mutex_);
  participants_.erase(std::remove(participants_.begin(), participants_.end(), &p), participants_.end());
  advanceIfAllWaiting();
}

// Time jumps to the earliest tick any program waits for, once every program waits for a tick
// that has not come yet (a program whose tick has come but that has not run yet blocks it).
void SimulatedClock::advanceIfAllWaiting() {
  if (paused_ || participants_.empty()) return;
  const std::uint64_t now = tick_.load();
  std::uint64_t next = std::numeric_limits<std::uint64_t>::max();
  for (const Participant* q : participants_) {
    if (!q->waiting || q->nextTick <= now) return;
    next = std::min(next, q->nextTick);
  }
  tick_.store(next);
  cv_.notify_all();
}

// A tick that has come runs, paused or not (pause() stops time, not a tick that some executors
// have run and others not yet), except on a clock made paused and not resumed yet: there the
// programs started one after another all wait, and begin together in tick 0's cycle.
bool SimulatedClock::waitForTick(Participant& p, std::uint64_t tick, const std::atomic<bool>& stopFlag) {
  std::unique_lock<std::mutex> lock(mutex_);
  p.nextTick = tick;
  p.waiting = true;
  advanceIfAllWaiting();
  cv_.wait(lock, [&] { return (tick_.load() >= tick && !neverResumed_) || stopFlag.load(); });
  p.waiting = false;
  return !stopFlag.load();
}

void SimulatedClock::interrupt() {
  std::lock_guard<std::mutex> lock(mutex_);
  cv_.notify_all();
}

}  // namespace rp
