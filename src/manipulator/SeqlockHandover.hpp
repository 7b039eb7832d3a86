#pragma once
// Numbers handed from any thread to a real-time one without a lock or an allocation in the
// real-time thread (internal to the library): the payload, the external wrenches.

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
class SeqlockHandover {
 public:
  /// Publishes `count` numbers at `offset` (the others keep their values). Real-time safe: yes
  /// (but only one writer at a time).
  /// @param[in] offset  the first number written
  /// @param[in] values  `count` numbers
  /// @param[in] count   how many (offset + count <= N)
  void store(std::size_t offset, const double* values, std::size_t count) noexcept {
    const std::uint64_t s = seq_.load(std::memory_order_relaxed);
    seq_.store(s + 1, std::memory_order_relaxed);  // odd: a write is under way
    // Release: a reader that sees any new value also sees the odd sequence number above.
    for (std::size_t i = 0; i < count; ++i) values_[offset + i].store(values[i], std::memory_order_release);
    seq_.store(s + 2, std::memory_order_release);
  }
  /// Publishes all `N` numbers. Real-time safe: yes (one writer at a time).
  /// @param[in] values  the numbers
  void store(const std::array<double, N>& values) noexcept { store(0, values.data(), N); }
  /// Reads the first `count` numbers if no write is under way. Real-time safe: yes (wait-free).
  /// @param[out] out    receives `count` numbers; unchanged when the read fails
  /// @param[in]  count  how many (<= N)
  /// @param[out] at     if not null, receives the version() the numbers are of
  /// @return true if `out` has a consistent set of values
  bool tryLoad(double* out, std::size_t count, std::uint64_t* at = nullptr) const noexcept {
    const std::uint64_t before = seq_.load(std::memory_order_acquire);
    if ((before & 1U) != 0) return false;
    std::array<double, N> v{};
    for (std::size_t i = 0; i < count; ++i) v[i] = values_[i].load(std::memory_order_acquire);
    if (seq_.load(std::memory_order_relaxed) != before) return false;
    for (std::size_t i = 0; i < count; ++i) out[i] = v[i];
    if (at != nullptr) *at = before;
    return true;
  }
  /// Reads all `N` numbers if no write is under way. Real-time safe: yes (wait-free).
  /// @param[out] out  receives the numbers; unchanged when the read fails
  /// @return true if `out` has a consistent set of values
  bool tryLoad(std::array<double, N>& out) const noexcept { return tryLoad(out.data(), N); }
  /// Changes with every store(): a reader that kept the version of its last read skips the copy
  /// while this is unchanged. Real-time safe: yes.
  std::uint64_t version() const noexcept { return seq_.load(std::memory_order_acquire); }

 private:
  std::atomic<std::uint64_t> seq_{0};
  std::array<std::atomic<double>, N> values_{};
};

}  // namespace rp::internal
