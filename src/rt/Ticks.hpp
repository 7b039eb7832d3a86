#pragma once
// A cheap clock for timing stretches of a cycle: the executors charge each program the ticks its
// phases took (three readings per program and cycle, hundreds of programs per cycle) and convert
// them to nanoseconds once per cycle. On x86 with an invariant time-stamp counter (constant rate,
// never stopped: CPUID 0x80000007 EDX bit 8) a tick is a count of that counter, read with RDTSC
// (about a tenth of a clock_gettime() through the vDSO, which orders and scales the same
// counter); elsewhere a tick is a nanosecond of CLOCK_MONOTONIC. Deadlines and wake-ups stay on
// CLOCK_MONOTONIC: only durations are measured in ticks.

#include <cstdint>

#if defined(__x86_64__) || defined(__i386__)
#include <x86intrin.h>
#endif

namespace rp::internal {

/// CLOCK_MONOTONIC in nanoseconds. Real-time safe: yes.
std::int64_t monotonicNanoseconds() noexcept;

/// Whether ticks() reads the time-stamp counter (decided once, when the library is loaded).
extern const bool ticksAreTimeStampCounter;

/// A monotonic count for durations on one thread (see the file's comment for its unit).
/// Real-time safe: yes (one instruction, or clock_gettime()).
inline std::int64_t ticks() noexcept {
#if defined(__x86_64__) || defined(__i386__)
  if (ticksAreTimeStampCounter) return static_cast<std::int64_t>(__rdtsc());
#endif
  return monotonicNanoseconds();
}

/// Nanoseconds per tick: 1 without the time-stamp counter; with it, the ratio of
/// CLOCK_MONOTONIC's and the counter's advances since the library was loaded (two readings of
/// each clock, so about 0.1 us of skew over the time since loading: 1e-4 after a millisecond).
/// Real-time safe: yes (two clock readings).
double nanosecondsPerTick() noexcept;

}  // namespace rp::internal
