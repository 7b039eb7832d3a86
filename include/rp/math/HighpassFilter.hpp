#pragma once
/// @file
/// Butterworth highpass filter of first or second order.

#include "rp/math/ButterworthFilter.hpp"

namespace rp {

/// A Butterworth highpass filter of order 1 or 2 (the paper's `HighpassFilter`):
/// \f$s/(s+\omega_c)\f$ or \f$s^2/(s^2+\sqrt{2}\omega_c s+\omega_c^2)\f$: zero gain at DC, gain \f$1/\sqrt{2}\f$ at the cutoff.
///
/// Example: `HighpassFilter<Vector<6>> f(10.0, 0.001, 2); auto y = f.filter(x);` filters a
/// 6-vector sampled at 1 kHz with a 10 Hz cutoff. See ButterworthFilter for the discretisation.
/// @tparam T  value type: `double`, `rp::Vector<n>`, `rp::Matrix<r, c>`, ...
template <typename T = double>
class HighpassFilter : public ButterworthFilter<T, FilterKind::kHighpass> {
 public:
  using ButterworthFilter<T, FilterKind::kHighpass>::ButterworthFilter;
};

}  // namespace rp
