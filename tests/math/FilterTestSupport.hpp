#pragma once
// Helpers for the filter tests: the steady-state amplitude a filter gives a sine of frequency f.
#include <cmath>
#include <numbers>

namespace rp::test {

// Feeds sin(2 pi f t) sampled every T (a whole number of samples per period) for `periods`
// periods and returns the amplitude of the output over the last ten periods, by projecting it on
// sin and cos (exact for a sinusoid of any phase; the transient has died out by then).
template <typename Filter>
double steadyStateAmplitude(Filter& filter, double f, double T, int periods = 60) {
  const int perPeriod = static_cast<int>(std::lround(1.0 / (f * T)));
  const int n = periods * perPeriod, window = 10 * perPeriod;
  double a = 0, b = 0;
  for (int i = 0; i < n; ++i) {
    const double phase = 2 * std::numbers::pi * f * i * T;
    const double y = filter.filter(std::sin(phase));
    if (i >= n - window) {
      a += y * std::sin(phase);
      b += y * std::cos(phase);
    }
  }
  return 2.0 / window * std::hypot(a, b);
}

}  // namespace rp::test
