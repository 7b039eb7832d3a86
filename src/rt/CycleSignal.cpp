// The end of every executor's cycle as an event (CycleSignal.hpp): a futex on the low 32 bits of
// a process-wide cycle count.
#include "CycleSignal.hpp"

#include <linux/futex.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <ctime>

namespace rp::internal {

namespace {
std::atomic<std::uint64_t> ended{0};
std::atomic<std::uint32_t> word{0};   // the futex: incremented with `ended` (wrapping)
std::atomic<int> waiters{0};

long futex(std::atomic<std::uint32_t>* address, int op, std::uint32_t value, const timespec* timeout) noexcept {
  static_assert(sizeof(std::atomic<std::uint32_t>) == sizeof(std::uint32_t));
  return syscall(SYS_futex, reinterpret_cast<std::uint32_t*>(address), op, value, timeout, nullptr, 0);
}
}  // namespace

void cycleEnded() noexcept {
  ended.fetch_add(1);
  word.fetch_add(1);
  if (waiters.load() > 0) futex(&word, FUTEX_WAKE_PRIVATE, 0x7fffffff, nullptr);
}

std::uint64_t cyclesEnded() noexcept { return ended.load(); }

std::uint64_t waitForCycleEnd(std::uint64_t seen, double timeoutSeconds) noexcept {
  std::uint64_t now = ended.load();
  if (now != seen || timeoutSeconds <= 0) return now;
  waiters.fetch_add(1);
  // Registered as a waiter, then the word read: a cycle that ends from here on either changes the
  // word before the futex call (which then returns at once) or wakes it.
  const std::uint32_t expected = word.load();
  if (ended.load() == seen) {
    timespec t{};
    t.tv_sec = static_cast<time_t>(timeoutSeconds);
    t.tv_nsec = static_cast<long>((timeoutSeconds - std::floor(timeoutSeconds)) * 1e9);
    futex(&word, FUTEX_WAIT_PRIVATE, expected, &t);
  }
  waiters.fetch_sub(1);
  return ended.load();
}

}  // namespace rp::internal
