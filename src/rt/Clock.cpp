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

SimulatedClock::SimulatedClock(double step, bool startPaused) : step_(step > 0 ? step : 1e-4), paused_(startPaused) {}

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
  cv_.notify_all();  // executors held at their first tick (see waitForTick())
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

// A participant's nextTick is kNotRunYet until it has run a tick (only waitForTick() reads it).
constexpr std::uint64_t kNotRunYet = std::numeric_limits<std::uint64_t>::max();

void SimulatedClock::attach(Participant& p) {
  std::lock_guard<std::mutex> lock(mutex_);
  p.waiting = false;
  p.nextTick = kNotRunYet;
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

// An executor's first tick waits for resume() on a paused clock, even when it has come: programs
// started on a paused clock begin together, at the first tick after resume(). Later ticks that
// have come still run when the clock is paused in between (pause() stops time, not a tick that
// some executors have run and others not yet).
bool SimulatedClock::waitForTick(Participant& p, std::uint64_t tick, const std::atomic<bool>& stopFlag) {
  std::unique_lock<std::mutex> lock(mutex_);
  const bool first = p.nextTick == kNotRunYet;
  p.nextTick = tick;
  p.waiting = true;
  advanceIfAllWaiting();
  cv_.wait(lock, [&] { return (tick_.load() >= tick && !(first && paused_)) || stopFlag.load(); });
  p.waiting = false;
  const bool run = !stopFlag.load();
  if (first && !run) p.nextTick = kNotRunYet;  // woken without running: still its first tick
  return run;
}

void SimulatedClock::interrupt() {
  std::lock_guard<std::mutex> lock(mutex_);
  cv_.notify_all();
}

}  // namespace rp
