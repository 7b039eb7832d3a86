// The tick clock of the executors' per-program timing (Ticks.hpp).
#include "Ticks.hpp"

#if defined(__x86_64__) || defined(__i386__)
#include <cpuid.h>
#endif

namespace rp::internal {

namespace {

bool invariantTimeStampCounter() noexcept {
#if defined(__x86_64__) || defined(__i386__)
  unsigned a = 0, b = 0, c = 0, d = 0;
  if (__get_cpuid_max(0x80000000u, nullptr) < 0x80000007u) return false;
  if (__get_cpuid(0x80000007u, &a, &b, &c, &d) == 0) return false;
  return (d & (1u << 8)) != 0;
#else
  return false;
#endif
}

// The readings the ratio is taken from: both clocks once, when the library is loaded.
struct Origin {
  std::int64_t nanoseconds, ticks;
};

}  // namespace

const bool ticksAreTimeStampCounter = invariantTimeStampCounter();

namespace {
// After ticksAreTimeStampCounter (same file: initialized in order).
const Origin origin{monotonicNanoseconds(), ticks()};
}  // namespace

double nanosecondsPerTick() noexcept {
  if (!ticksAreTimeStampCounter) return 1.0;
  const std::int64_t ns = monotonicNanoseconds() - origin.nanoseconds;
  const std::int64_t t = ticks() - origin.ticks;
  if (ns <= 0 || t <= 0) return 1.0;  // within the same nanosecond as loading: nothing measured yet
  return static_cast<double>(ns) / static_cast<double>(t);
}

}  // namespace rp::internal
