// The executors' tick clock (src/rt/Ticks.hpp): ticks never go back on a thread, and ticks times
// nanosecondsPerTick() measure a stretch of time as CLOCK_MONOTONIC does (the independent
// reference: the clock the deadlines run on).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "Ticks.hpp"

namespace rp::internal {
namespace {

TEST(Ticks, NeverGoBackOnAThread) {
  std::int64_t last = ticks();
  for (int i = 0; i < 100000; ++i) {
    const std::int64_t now = ticks();
    ASSERT_GE(now, last) << "reading " << i;
    last = now;
  }
}

// A busy wait of 20 ms of CLOCK_MONOTONIC, bracketed by tick readings (so the ticks span at
// least the clock's stretch; the two differ by the time between adjacent readings). The best of
// five tries is taken: a preemption between two adjacent readings widens one try only.
TEST(Ticks, TimesTheConversionMeasureWhatTheMonotonicClockMeasures) {
  double best = 1e9;
  for (int attempt = 0; attempt < 5; ++attempt) {
    const std::int64_t t0 = ticks();
    const std::int64_t ns0 = monotonicNanoseconds();
    std::int64_t ns1 = ns0;
    while (ns1 - ns0 < 20000000) ns1 = monotonicNanoseconds();
    const std::int64_t t1 = ticks();
    const double measured = static_cast<double>(t1 - t0) * nanosecondsPerTick();
    const double reference = static_cast<double>(ns1 - ns0);
    best = std::min(best, std::abs(measured / reference - 1.0));
  }
  EXPECT_LT(best, 1e-3) << (ticksAreTimeStampCounter ? "time-stamp counter" : "CLOCK_MONOTONIC");
}

}  // namespace
}  // namespace rp::internal
