#pragma once
// A few numbers handed from any thread to a real-time one without a lock or an allocation in the
// real-time thread (internal to the library).

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>

namespace rp::internal {

/// `N` numbers written by non-real-time threads (one at a time: the writers serialise
/// themselves) and read by a real-time thread: a sequence lock over atomics. A read never waits:
/// tryLoad() fails while a write is under way, and the reader keeps the values it had (it takes
/// the new ones at its next attempt, the next servo cycle). All accesses are atomic, so there is no
/// data race for ThreadSanitizer to see.
template <std::size_t N>
class PayloadHandover {
 public:
  /// Publishes `values`. Real-time safe: yes (but only one writer at a time).
  /// @param[in] values  the numbers
  void store(const std::array<double, N>& values) noexcept {
    const std::uint64_t s = seq_.load(std::memory_order_relaxed);
    seq_.store(s + 1, std::memory_order_relaxed);  // odd: a write is under way
    // Release: a reader that sees any new value also sees the odd sequence number above.
    for (std::size_t i = 0; i < N; ++i) values_[i].store(values[i], std::memory_order_release);
    seq_.store(s + 2, std::memory_order_release);
  }
  /// Reads the numbers if no write is under way. Real-time safe: yes (wait-free).
  /// @param[out] out  receives the numbers; unchanged when the read fails
  /// @return true if `out` has a consistent set of values
  bool tryLoad(std::array<double, N>& out) const noexcept {
    const std::uint64_t before = seq_.load(std::memory_order_acquire);
    if ((before & 1U) != 0) return false;
    std::array<double, N> v{};
    for (std::size_t i = 0; i < N; ++i) v[i] = values_[i].load(std::memory_order_acquire);
    if (seq_.load(std::memory_order_relaxed) != before) return false;
    out = v;
    return true;
  }

 private:
  std::atomic<std::uint64_t> seq_{0};
  std::array<std::atomic<double>, N> values_{};
};

}  // namespace rp::internal
