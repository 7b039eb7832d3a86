// A number in a message (internal): as short as its value allows, "11", "0.25", "1e-09", "1e+300".
// std::to_string prints 1e300 with 300 digits, 1e-9 as 0.000000 and 0.1 as 0.100000.
#pragma once

#include <cstdio>
#include <string>

namespace rp::internal {

// `v` with at most `digits` significant digits ("%.*g").
inline std::string shortNumber(double v, int digits = 10) {
  char text[40];
  std::snprintf(text, sizeof text, "%.*g", digits, v);
  return text;
}

}  // namespace rp::internal
