#pragma once
/// @file
/// Butterworth filters of order 1 or 2: the common implementation of LowpassFilter and HighpassFilter.

#include <cmath>
#include <numbers>
#include <string>
#include <type_traits>

#include "rp/math/MathException.hpp"

namespace rp {
/// Which response a ButterworthFilter has.
enum class FilterKind {
  kLowpass,  ///< passes frequencies below the cutoff
  kHighpass  ///< passes frequencies above the cutoff
};

namespace internal {

// A value of the same shape as `x`, all zeros: scalars, fixed and dynamic Eigen matrices.
template <typename T>
T zeroLike(const T& x) {
  if constexpr (std::is_arithmetic_v<T>) {
    (void)x;
    return T(0);
  } else {
    return T(T::Zero(x.rows(), x.cols()));
  }
}

// Coefficients of y[n] = b0 x[n] + b1 x[n-1] + b2 x[n-2] - a1 y[n-1] - a2 y[n-2].
struct FilterCoefficients {
  double b0 = 1, b1 = 0, b2 = 0, a1 = 0, a2 = 0;
};

// Butterworth low- or high-pass of order 1 or 2, discretised by the bilinear transform with the
// frequency pre-warped at the cutoff, so the discrete gain at the cutoff is exactly 1/sqrt(2).
inline FilterCoefficients butterworth(FilterKind kind, double cutoffHz, double samplePeriod, int order,
                                      const char* who) {
  if (!(samplePeriod > 0) || !std::isfinite(samplePeriod)) {
    throw MathException(std::string(who) + ": sample period must be positive, got " + std::to_string(samplePeriod) +
                        " s");
  }
  const double nyquist = 0.5 / samplePeriod;
  if (!(cutoffHz > 0) || !(cutoffHz < nyquist)) {
    throw MathException(std::string(who) + ": cutoff " + std::to_string(cutoffHz) +
                        " Hz must be above 0 and below the Nyquist frequency " + std::to_string(nyquist) + " Hz");
  }
  if (order != 1 && order != 2) {
    throw MathException(std::string(who) + ": order must be 1 or 2, got " + std::to_string(order));
  }
  const double k = std::tan(std::numbers::pi * cutoffHz * samplePeriod);  // pre-warped wc*T/2
  FilterCoefficients c;
  if (order == 1) {
    const double n = 1.0 / (1.0 + k);
    c.a1 = (k - 1.0) * n;
    if (kind == FilterKind::kLowpass) {
      c.b0 = c.b1 = k * n;
    } else {
      c.b0 = n;
      c.b1 = -n;
    }
  } else {
    const double s2 = std::numbers::sqrt2;
    const double n = 1.0 / (1.0 + s2 * k + k * k);
    c.a1 = 2.0 * (k * k - 1.0) * n;
    c.a2 = (1.0 - s2 * k + k * k) * n;
    if (kind == FilterKind::kLowpass) {
      c.b0 = k * k * n;
      c.b1 = 2.0 * c.b0;
      c.b2 = c.b0;
    } else {
      c.b0 = n;
      c.b1 = -2.0 * n;
      c.b2 = n;
    }
  }
  return c;
}

}  // namespace internal

/// A Butterworth filter of order 1 or 2 for scalars, vectors or matrices: every element is
/// filtered independently. Use it through `LowpassFilter` and `HighpassFilter`.
///
/// The continuous low-pass \f$H(s) = \omega_c / (s + \omega_c)\f$ (order 1) or
/// \f$H(s) = \omega_c^2 / (s^2 + \sqrt{2}\,\omega_c s + \omega_c^2)\f$ (order 2), and the high-pass
/// \f$s / (s + \omega_c)\f$ or \f$s^2 / (s^2 + \sqrt{2}\,\omega_c s + \omega_c^2)\f$, are discretised
/// by the bilinear transform pre-warped at the cutoff, so the discrete gain at the cutoff is exactly
/// \f$1/\sqrt{2}\f$ (-3 dB). The state starts at zero; `reset(value)` starts it at rest instead.
///
/// @tparam T     value type: `double`, `rp::Vector<n>`, `rp::Matrix<r, c>`, ...
/// @tparam kKind low-pass or high-pass
template <typename T, FilterKind kKind>
class ButterworthFilter {
 public:
  /// An unconfigured filter; call `setup()` before `filter()`.
  ButterworthFilter() = default;
  /// A filter with cutoff `cutoffHz` [Hz] for samples every `samplePeriod` [s].
  /// @param[in] cutoffHz      cutoff frequency [Hz], below the Nyquist frequency
  /// @param[in] samplePeriod  time between two samples [s]
  /// @param[in] order         1 or 2
  /// @throws MathException unless 0 < cutoffHz < 1/(2 samplePeriod) and order is 1 or 2.
  ButterworthFilter(double cutoffHz, double samplePeriod, int order = 1) { setup(cutoffHz, samplePeriod, order); }
  /// Sets cutoff [Hz], sample period [s] and order, and resets the state.
  /// @param[in] cutoffHz      cutoff frequency [Hz], below the Nyquist frequency
  /// @param[in] samplePeriod  time between two samples [s]
  /// @param[in] order         1 or 2
  /// @throws MathException as the constructor does. Real-time safe: yes (throws only on bad input).
  void setup(double cutoffHz, double samplePeriod, int order = 1) {
    c_ = internal::butterworth(kKind, cutoffHz, samplePeriod, order, name());
    configured_ = true;
    started_ = false;
  }
  /// Filters the next sample `x` and returns the filtered value.
  /// @throws MathException if the filter was never set up.
  /// Real-time safe: yes for scalars and fixed-size types (dynamic sizes allocate on the first sample).
  const T& filter(const T& x) {
    if (!configured_) throw MathException(std::string(name()) + ": filter used before it was set up");
    if (!started_) {
      x1_ = x2_ = y1_ = y2_ = y0_ = internal::zeroLike(x);
      started_ = true;
    }
    y0_ = c_.b0 * x + c_.b1 * x1_ + c_.b2 * x2_ - c_.a1 * y1_ - c_.a2 * y2_;
    x2_ = x1_;
    x1_ = x;
    y2_ = y1_;
    y1_ = y0_;
    return y0_;
  }
  /// The last filtered value. Real-time safe: yes.
  const T& getOutput() const { return y0_; }
  /// Clears the state: the next sample is filtered as if all earlier ones were zero. Real-time safe: yes.
  void reset() { started_ = false; }
  /// Starts the filter at rest under a constant input `value`: the output is `value` for a
  /// low-pass and zero for a high-pass. Real-time safe: yes.
  void reset(const T& value) {
    x1_ = x2_ = value;
    y0_ = y1_ = y2_ = (kKind == FilterKind::kLowpass) ? value : internal::zeroLike(value);
    started_ = true;
  }

 private:
  static constexpr const char* name() { return kKind == FilterKind::kLowpass ? "LowpassFilter" : "HighpassFilter"; }
  internal::FilterCoefficients c_;
  bool configured_ = false;
  bool started_ = false;
  T x1_{}, x2_{}, y0_{}, y1_{}, y2_{};
};

}  // namespace rp
