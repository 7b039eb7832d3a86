// The ControlProgram cycle does not allocate: waiting for the clock, applying tuned parameters,
// control(), log sampling into the ring buffer, and QMotor's log (its trigger, decimation and
// rows; also while the page sets it up again), on both clocks.
#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <thread>

#include "AllocationCounter.hpp"
#include "rp/rt/Clock.hpp"
#include "rp/rt/ControlProgram.hpp"
#include "rp/rt/LogWriter.hpp"
#include "rp/rt/TripleBuffer.hpp"

namespace rp {
namespace {

// Counts the allocations its own thread makes between the first and the last cycle.
class Counted : public ControlProgram {
 public:
  Counted() : ControlProgram("counted") {
    registerLogVariable("x", x_);
    registerLogVariable("q", q_);
    registerParameter("gain", gain_, 0, 100);
    registerParameter("kp", kp_, 0, 100);
  }
  ~Counted() override { stop(); }
  std::atomic<long> allocations{-1};

 protected:
  void control() override {
    if (getCycleCount() == 0) start_ = test::allocationCount();
    x_ = gain_ * static_cast<double>(getCycleCount());
    q_ = kp_ * x_;
    StateSnapshot s{getTime(), getCycleCount(), 1, {x_}};
    snapshots.write(s);
    inputs.write(s);
    inputs.readAsOnlyReader(s);
  }
  void exitControl() override { allocations = static_cast<long>(test::allocationCount() - start_); }

 private:
  struct StateSnapshot {
    double t;
    std::uint64_t cycle;
    int size;
    double values[8];
  };
  TripleBuffer<StateSnapshot> snapshots;
  TripleBuffer<StateSnapshot> inputs;  // read by this thread only (readAsOnlyReader())
  std::size_t start_ = 0;
  double x_ = 0, gain_ = 1;
  Vector<6> q_, kp_ = Vector<6>::Constant(1);
};

void tuneWhileRunning(Counted& c) {
  for (int i = 0; c.isRunning() && i < 50; ++i) {
    c.setParameter("gain", 1.0 + i % 3);
    c.setParameter("kp", 2, 0.5 * (i % 5));
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

std::atomic<int*> sink{nullptr};

TEST(RtRealtime, CounterSeesAllocationsInOtherThreads) {
  std::atomic<std::size_t> n{0};
  std::thread t([&] {
    test::AllocationGuard g;
    sink = new int[100];  // stored in an atomic, so the compiler cannot elide it
    n = g.count();
    delete[] sink.exchange(nullptr);
  });
  t.join();
  EXPECT_GE(n.load(), 1u);
}

TEST(RtRealtime, SimulatedClockCycleDoesNotAllocate) {
  auto file = std::filesystem::temp_directory_path() / ("rp_rt_alloc_" + std::to_string(::getpid()) + ".csv");
  LogWriter writer(file.string());
  SimulatedClock clock(1e-3);
  Counted c;
  c.setClock(clock);
  c.setLogWriter(&writer);
  c.setCycleLimit(20000);
  c.start();
  tuneWhileRunning(c);
  c.waitUntilStopped();
  writer.close();
  std::filesystem::remove(file);
  EXPECT_EQ(c.getCycleCount(), 20000u);
  EXPECT_EQ(c.allocations.load(), 0);
}

TEST(RtRealtime, RealClockCycleDoesNotAllocate) {
  auto file = std::filesystem::temp_directory_path() / ("rp_rt_alloc_real_" + std::to_string(::getpid()) + ".csv");
  LogWriter writer(file.string());
  Counted c;
  c.setClock(RealClock::instance());
  c.setRate(2000);
  c.setLogWriter(&writer);
  c.setCycleLimit(200);
  c.start();
  tuneWhileRunning(c);
  c.waitUntilStopped();
  writer.close();
  std::filesystem::remove(file);
  EXPECT_EQ(c.getCycleCount(), 200u);
  EXPECT_EQ(c.allocations.load(), 0);
}

// QMotor's log in the cycle: the trigger is evaluated every cycle until it fires, then every
// `every`-th cycle writes a row, until the buffer is full; it is set up again while running.
void captureWhileRunning(Counted& c, unsigned every) {
  LogCaptureSettings s;
  s.variables = {"x", "q"};
  s.every = every;
  s.samples = 500;
  s.triggerColumn = "q[2]";
  s.triggerLevel = 5;
  s.triggerRising = true;
  for (int i = 0; c.isRunning() && i < 20; ++i) {
    // Without a trigger rows are written every `every` cycles; falling through 1e9 never fires (q
    // grows): the trigger is evaluated every cycle.
    s.triggerColumn = i % 2 == 0 ? "" : "q[2]";
    s.triggerRising = false;
    s.triggerLevel = 1e9;
    s.every = every + static_cast<unsigned>(i % 3);
    c.setLogCapture(s);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

TEST(RtRealtime, QMotorLogTriggerAndDecimationDoNotAllocate) {
  SimulatedClock clock(1e-3);
  Counted c;
  c.setClock(clock);
  c.setLogWriter(nullptr);
  c.setCycleLimit(20000);
  LogCaptureSettings s;
  s.every = 7;
  s.samples = 1000;
  s.triggerColumn = "x";
  s.triggerLevel = 100.5;
  c.setLogCapture(s);  // armed before the start: the first cycles evaluate the trigger
  c.start();
  c.waitUntilStopped();
  EXPECT_EQ(c.getCycleCount(), 20000u);
  EXPECT_EQ(c.allocations.load(), 0);
  // The trigger fired at x = 101 (cycle 101), then a row every 7 cycles until the buffer was full.
  const LogCaptureStatus st = c.getLogCaptureStatus();
  EXPECT_TRUE(st.triggered);
  EXPECT_NEAR(st.triggerTime, 0.101, 1e-12);
  EXPECT_EQ(st.rows, 1000u);
}

TEST(RtRealtime, QMotorLogOnTheRealClockDoesNotAllocate) {
  Counted c;
  c.setClock(RealClock::instance());
  c.setRate(2000);
  c.setLogWriter(nullptr);
  c.setCycleLimit(400);
  c.start();
  captureWhileRunning(c, 2);
  c.waitUntilStopped();
  EXPECT_EQ(c.getCycleCount(), 400u);
  EXPECT_EQ(c.allocations.load(), 0);
}

}  // namespace
}  // namespace rp
