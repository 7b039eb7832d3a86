#pragma once
/// @file
/// Numeric differentiation by backward difference, optionally low-pass filtered.

#include <optional>

#include "rp/math/LowpassFilter.hpp"

namespace rp {

/// Differentiates a sampled signal by the backward difference
/// \f$\dot x_n \approx (x_n - x_{n-1}) / T\f$ (the paper's `Differentiator`), optionally followed
/// by a Butterworth low-pass filter to tame noise.
///
/// The first sample after construction or `reset()` gives zero (there is no earlier sample).
/// The backward difference estimates the derivative half a sample in the past: for a smooth
/// signal its error is at most \f$\frac{T}{2}\max|\ddot x|\f$.
/// @tparam T  value type: `double`, `rp::Vector<n>`, `rp::Matrix<r, c>`, ...
template <typename T = double>
class Differentiator {
 public:
  /// A differentiator for samples every `samplePeriod` [s]; if `cutoffHz` > 0 its output is
  /// low-pass filtered at that cutoff [Hz] with a filter of order `filterOrder` (1 or 2).
  /// @throws MathException if the period is not positive or the filter cannot be set up.
  explicit Differentiator(double samplePeriod, double cutoffHz = 0.0, int filterOrder = 1) : period_(samplePeriod) {
    if (!(samplePeriod > 0) || !std::isfinite(samplePeriod)) {
      throw MathException("Differentiator: sample period must be positive, got " + std::to_string(samplePeriod) +
                          " s");
    }
    if (cutoffHz > 0) filter_.emplace(cutoffHz, samplePeriod, filterOrder);
  }
  /// Takes the next sample `x` and returns the derivative estimate [units of x per second].
  /// Real-time safe: yes for scalars and fixed-size types.
  const T& differentiate(const T& x) {
    if (!started_) {
      previous_ = x;
      derivative_ = internal::zeroLike(x);
      started_ = true;
    } else {
      derivative_ = (x - previous_) / period_;
      previous_ = x;
    }
    if (filter_) return filter_->filter(derivative_);
    return derivative_;
  }
  /// Takes the next sample `x`, taken `elapsed` seconds after the previous one instead of one
  /// sample period (a late sample, e.g. after a stalled cycle), and returns the derivative
  /// estimate: the difference is divided by the time that really passed, so a late sample is no
  /// spike. Real-time safe: yes for scalars and fixed-size types.
  /// @param[in] x        the sample
  /// @param[in] elapsed  time since the previous sample [s], > 0 (else the sample period is used)
  const T& differentiate(const T& x, double elapsed) {
    if (!(elapsed > 0) || !std::isfinite(elapsed) || !started_) return differentiate(x);
    derivative_ = (x - previous_) / elapsed;
    previous_ = x;
    if (filter_) return filter_->filter(derivative_);
    return derivative_;
  }
  /// Forgets all earlier samples. Real-time safe: yes.
  void reset() {
    started_ = false;
    if (filter_) filter_->reset();
  }
  /// The sample period [s].
  double getSamplePeriod() const { return period_; }

 private:
  double period_;
  bool started_ = false;
  T previous_{}, derivative_{};
  std::optional<LowpassFilter<T>> filter_;
};

}  // namespace rp
