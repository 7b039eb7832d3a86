// The ControlProgram cycle does not allocate: waiting for the clock, applying tuned parameters,
// control(), and log sampling into the ring buffer, on both clocks.
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

}  // namespace
}  // namespace rp
