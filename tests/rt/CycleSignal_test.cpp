// The end of every executor cycle as an event (src/rt/CycleSignal.hpp): a thread waiting for it
// wakes when a cycle ends, and otherwise after its timeout with the count unchanged.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "CycleSignal.hpp"
#include "rp/rt/Clock.hpp"
#include "rp/rt/ControlProgram.hpp"

namespace rp {
namespace {

class Idle : public ControlProgram {
 public:
  Idle() : ControlProgram("idle") {}
  ~Idle() override { stop(); }

 protected:
  void control() override {}
};

TEST(CycleSignal, AWaiterWakesWhenACycleEndsAndOtherwiseTimesOut) {
  SimulatedClock clock(1e-3, true);  // paused: no cycle ends until resume()
  Idle program;
  program.setClock(clock);
  constexpr std::uint64_t kCycles = 1000000;  // seconds of simulated cycles, stopped before
  program.setCycleLimit(kCycles);
  program.start();
  const std::uint64_t before = internal::cyclesEnded();  // tick 0 waits for resume() too
  // No cycle while the clock is paused: the wait ends by its timeout with the count unchanged.
  EXPECT_EQ(internal::waitForCycleEnd(before, 0.05), before);
  // A waiter with a long timeout wakes at one of the next cycles: long before the last one (it
  // would return only after all of them, by its timeout, if the cycles did not wake it).
  std::atomic<std::uint64_t> woke{0};
  std::thread waiter([&] { woke = internal::waitForCycleEnd(before, 30); });
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // most likely waiting by now
  clock.resume();
  waiter.join();
  EXPECT_GT(woke.load(), before);
  EXPECT_LT(woke.load(), before + kCycles - 1);
  program.stop();
  // A count already passed returns at once.
  EXPECT_EQ(internal::waitForCycleEnd(before, 30), internal::cyclesEnded());
}

}  // namespace
}  // namespace rp
