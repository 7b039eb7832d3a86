#pragma once
/// @file
/// Numeric integration by the trapezoidal rule.

#include <cmath>
#include <string>

#include "rp/math/ButterworthFilter.hpp"

namespace rp {

/// Integrates a sampled signal by the trapezoidal rule
/// \f$y_n = y_{n-1} + \frac{T}{2}(x_n + x_{n-1})\f$ (the paper's `Integrator`).
///
/// The first sample after construction or `reset()` only starts the integral (at zero, or at the
/// value given to `reset(initial)`). For a smooth signal the error after time \f$t\f$ is at most
/// \f$\frac{T^2}{12}\, t \max|\ddot x|\f$.
/// @tparam T  value type: `double`, `rp::Vector<n>`, `rp::Matrix<r, c>`, ...
template <typename T = double>
class Integrator {
 public:
  /// An integrator for samples every `samplePeriod` [s].
  /// @throws MathException if the period is not positive.
  explicit Integrator(double samplePeriod) : period_(samplePeriod) {
    if (!(samplePeriod > 0) || !std::isfinite(samplePeriod)) {
      throw MathException("Integrator: sample period must be positive, got " + std::to_string(samplePeriod) + " s");
    }
  }
  /// Takes the next sample `x` and returns the integral so far [units of x times seconds].
  /// Real-time safe: yes for scalars and fixed-size types.
  const T& integrate(const T& x) {
    if (!started_) {
      if (!hasInitial_) integral_ = internal::zeroLike(x);
      started_ = true;
    } else {
      integral_ += (0.5 * period_) * (x + previous_);
    }
    previous_ = x;
    return integral_;
  }
  /// The integral so far. Real-time safe: yes.
  const T& getIntegral() const { return integral_; }
  /// Starts again from zero. Real-time safe: yes.
  void reset() {
    started_ = false;
    hasInitial_ = false;
  }
  /// Starts again from `initial`. Real-time safe: yes.
  void reset(const T& initial) {
    integral_ = initial;
    started_ = false;
    hasInitial_ = true;
  }
  /// The sample period [s].
  double getSamplePeriod() const { return period_; }

 private:
  double period_;
  bool started_ = false;
  bool hasInitial_ = false;
  T previous_{}, integral_{};
};

}  // namespace rp
