// A trajectory generator for the ROS 2 tests' allocation checks: it holds a position and counts,
// in the loop's thread, the allocations between two of its calls (everything else the loop does).
#pragma once

#include <atomic>
#include <cstddef>

#include "AllocationCounter.hpp"
#include "rp/trajectory/TrajectoryGenerator.hpp"

namespace rp::test {

// A generator that holds `q` and counts, in the loop's thread, the allocations between two of its
// calls: everything else the loop does in a cycle.
class CountingHold : public TrajectoryGenerator {
 public:
  explicit CountingHold(const JointVector& q) : q_(q) {}
  ~CountingHold() override { withdrawObject(); }  // first: other threads (a shutdown) keep off from here on
  bool getCurrentSetpoint(double time, Setpoint& setpoint) override {
    (void)time;
    const std::size_t now = test::allocationCount();
    if (calls_ > 2) allocations_ += now - last_;
    ++calls_;
    setpoint.position = q_;
    last_ = test::allocationCount();
    allocations.store(allocations_);
    calls.store(calls_);
    return true;
  }
  std::atomic<std::size_t> allocations{0};
  std::atomic<long> calls{0};

 private:
  const JointVector q_;
  std::size_t allocations_ = 0, last_ = 0;
  long calls_ = 0;
};

}  // namespace rp::test
