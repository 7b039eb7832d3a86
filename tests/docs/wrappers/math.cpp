// Wrapper of docs/math.md's fragments: "RoboticPlatform.hpp" (the paper's names), in main(), with
// `raw`, a sample to filter.
#include "RoboticPlatform.hpp"

int main() {
  Vector<6> raw;
  raw = 1, 2, 3, 4, 5, 6;
@FRAGMENT@
  return 0;
}
