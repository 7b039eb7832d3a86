#pragma once
/// @file
/// Barrier: a meeting point for a fixed number of threads (paper section 3.7).

#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <stdexcept>

namespace rp {

/// Blocks each of `count` threads in wait() until all of them have arrived, then releases them
/// together; reusable for any number of rounds.
class Barrier {
 public:
  /// Creates a barrier for `count` threads.
  /// @param[in] count  number of threads, >= 1
  /// @throws std::invalid_argument if count is 0
  explicit Barrier(unsigned count) : count_(count) {
    if (count == 0) throw std::invalid_argument("Barrier: the thread count must be at least 1");
  }
  /// Waits until `count` threads have called wait() in this round.
  /// @return true in exactly one thread per round (the last to arrive)
  /// Real-time safe: no (blocks).
  bool wait() {
    std::unique_lock<std::mutex> lock(mutex_);
    const std::uint64_t round = round_;
    if (++arrived_ == count_) {
      arrived_ = 0;
      ++round_;
      cv_.notify_all();
      return true;
    }
    cv_.wait(lock, [&] { return round_ != round; });
    return false;
  }
  /// The number of threads per round.
  unsigned getCount() const noexcept { return count_; }

 private:
  const unsigned count_;
  unsigned arrived_ = 0;
  std::uint64_t round_ = 0;
  std::mutex mutex_;
  std::condition_variable cv_;
};

}  // namespace rp
