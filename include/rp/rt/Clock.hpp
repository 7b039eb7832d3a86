#pragma once
/// @file
/// Clocks that drive control programs: the real clock, or a simulated one stepped as fast as
/// the machine allows.

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <vector>

namespace rp {

class ControlProgram;

/// A clock a ControlProgram waits on between cycles.
class Clock {
 public:
  virtual ~Clock() = default;
  /// Whether this is a simulated clock.
  virtual bool isSimulated() const noexcept = 0;
  /// Current time of the clock [s]: since the platform started for the real clock, simulated
  /// time for a simulated clock. Real-time safe: yes.
  virtual double getTime() const noexcept = 0;
};

/// The real clock: CLOCK_MONOTONIC, with absolute deadlines (`clock_nanosleep`, TIMER_ABSTIME).
class RealClock : public Clock {
 public:
  /// The process's real clock.
  static RealClock& instance();
  bool isSimulated() const noexcept override { return false; }
  /// Seconds since the platform's epoch (the first use of the real clock).
  double getTime() const noexcept override;
  /// Nanoseconds of CLOCK_MONOTONIC at the epoch.
  std::int64_t epochNanoseconds() const noexcept { return epoch_; }

 private:
  RealClock();
  std::int64_t epoch_;
};

/// A simulated clock shared by any number of control programs, which run in lockstep: time
/// advances only when every program on the clock has finished its cycle and waits for its next
/// one, and then jumps straight to the earliest next cycle (no sleeping). Programs whose periods
/// are multiples of the clock step run on the same ticks, so several manipulators are simulated
/// deterministically and as fast as the machine allows.
class SimulatedClock : public Clock {
 public:
  /// Creates a clock at time 0.
  /// @param[in] step  resolution [s]; every program period is rounded to a multiple of it
  /// @param[in] startPaused  if true, time does not advance until resume(), and no program runs
  ///                         a cycle before it, not even at tick 0: the programs started
  ///                         meanwhile begin together, in tick 0's cycle after resume()
  explicit SimulatedClock(double step = 1e-4, bool startPaused = false);
  ~SimulatedClock() override;
  bool isSimulated() const noexcept override { return true; }
  /// Simulated time = tick * step [s].
  double getTime() const noexcept override;
  /// Number of steps since time 0.
  std::uint64_t getTick() const noexcept;
  /// The step [s].
  double getStep() const noexcept { return step_; }
  /// Time of tick `tick` [s] (tick / steps-per-second when that is a whole number).
  /// @param[in] tick  a tick number
  double tickTime(std::uint64_t tick) const noexcept;
  /// Stops time from advancing (programs wait at their next cycle).
  void pause();
  /// Lets time advance again.
  void resume();
  /// Whether the clock is paused.
  bool isPaused() const;
  /// Number of programs running on the clock (of every executor on it).
  int getNumberOfPrograms() const;

  /// @cond INTERNAL
  // Used by the executors' threads (one participant per executor).
  struct Participant {
    std::uint64_t nextTick = 0;
    bool waiting = false;
    const void* owner = nullptr;
    std::atomic<int> programs{0};  // programs the executor steps
  };
  void attach(Participant& p);
  void detach(Participant& p);
  bool waitForTick(Participant& p, std::uint64_t tick, const std::atomic<bool>& stopFlag);
  void interrupt();
  /// @endcond

 private:
  void advanceIfAllWaiting();  // with mutex_ held
  double step_;
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::vector<Participant*> participants_;
  std::atomic<std::uint64_t> tick_{0};
  bool paused_ = false;
  bool neverResumed_ = false;  // made paused and not resumed yet: not even the current tick runs
};

}  // namespace rp
