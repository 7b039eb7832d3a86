#pragma once
/// @file
/// Butterworth lowpass filter of first or second order.

#include "rp/math/ButterworthFilter.hpp"

namespace rp {

/// A Butterworth lowpass filter of order 1 or 2 (the paper's `LowpassFilter`):
/// \f$\omega_c/(s+\omega_c)\f$ or \f$\omega_c^2/(s^2+\sqrt{2}\omega_c s+\omega_c^2)\f$: DC gain 1, gain \f$1/\sqrt{2}\f$ at the cutoff.
///
/// Example: `LowpassFilter<Vector<6>> f(10.0, 0.001, 2); auto y = f.filter(x);` filters a
/// 6-vector sampled at 1 kHz with a 10 Hz cutoff. See ButterworthFilter for the discretisation.
/// @tparam T  value type: `double`, `rp::Vector<n>`, `rp::Matrix<r, c>`, ...
template <typename T = double>
class LowpassFilter : public ButterworthFilter<T, FilterKind::kLowpass> {
 public:
  using ButterworthFilter<T, FilterKind::kLowpass>::ButterworthFilter;
};

}  // namespace rp
