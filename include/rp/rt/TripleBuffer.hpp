#pragma once
/// @file
/// TripleBuffer: passes the latest value of a trivially copyable type from one real-time writer
/// to readers without the writer ever blocking.

#include <atomic>
#include <cstdint>
#include <mutex>
#include <type_traits>
#include <utility>

namespace rp {

/// Latest-value channel from one writer thread to any number of readers (state snapshots of a
/// servo thread read by the GUI). The writer never waits or allocates; readers take a mutex
/// only among themselves, except the one reader of readAsOnlyReader(), which takes none.
/// @tparam T  trivially copyable value type (e.g. StateSnapshot)
template <typename T>
class TripleBuffer {
  static_assert(std::is_trivially_copyable_v<T>, "TripleBuffer needs a trivially copyable type");

 public:
  /// Creates the buffer with value-initialised contents.
  TripleBuffer() = default;

  /// Publishes `value` as the latest. Only one thread may write.
  /// @param[in] value  new value
  /// Real-time safe: yes.
  void write(const T& value) noexcept {
    buffers_[back_] = value;
    publishBack();
  }

  /// Publishes a value written in place: `fill(T& value)` sets the fields of the buffer that goes
  /// out next, which holds an older value (one written before the last, or the value-initialised
  /// one), not a fresh one, so it must set every field it means to publish. For a large value of
  /// which the writer sets only a part (an arm's joint arrays sized for the most joints any arm
  /// has): no copy of the whole, no cache lines written that did not change. Only one thread may
  /// write (write() or update()).
  /// @param[in] fill  called once with the buffer to fill
  /// Real-time safe: yes, if `fill` is.
  template <typename Fill>
  void update(Fill&& fill) noexcept(noexcept(fill(std::declval<T&>()))) {
    fill(buffers_[back_]);
    publishBack();
  }
  /// Copies the latest value into `out`.
  /// @param[out] out  receives the value
  /// @return false if nothing has been written yet (out unchanged)
  /// Real-time safe: no (readers share a mutex).
  bool read(T& out) const {
    if (!written_.load(std::memory_order_acquire)) return false;
    std::lock_guard<std::mutex> lock(readMutex_);
    if (middle_.load(std::memory_order_acquire) & kFresh) {
      unsigned old = middle_.exchange(front_, std::memory_order_acq_rel);
      front_ = old & kIndex;
    }
    out = buffers_[front_];
    return true;
  }
  /// read() for a buffer that only one thread ever reads, and only with this function (a servo
  /// thread taking the latest input an I/O thread wrote): no lock.
  /// @param[out] out  receives the value
  /// @return false if nothing has been written yet (out unchanged)
  /// Real-time safe: yes.
  bool readAsOnlyReader(T& out) const noexcept {
    if (!written_.load(std::memory_order_acquire)) return false;
    if (middle_.load(std::memory_order_acquire) & kFresh) {
      unsigned old = middle_.exchange(front_, std::memory_order_acq_rel);
      front_ = old & kIndex;
    }
    out = buffers_[front_];
    return true;
  }

 private:
  static constexpr unsigned kFresh = 4, kIndex = 3;

  // Swaps the back buffer with the middle one and marks it fresh.
  void publishBack() noexcept {
    unsigned old = middle_.exchange(back_ | kFresh, std::memory_order_acq_rel);
    back_ = old & kIndex;
    written_.store(true, std::memory_order_release);
  }
  mutable T buffers_[3]{};
  unsigned back_ = 0;                           // writer's
  mutable std::atomic<unsigned> middle_{1};     // shared
  mutable unsigned front_ = 2;                  // readers' (under readMutex_)
  std::atomic<bool> written_{false};
  mutable std::mutex readMutex_;
};

}  // namespace rp
