// Assigning a 4-vector to a 3-vector must not compile (the paper's Figure 22 size bug).
#include "RoboticPlatform.hpp"
int main() {
  Vector<4> wall;
  Vector<3> force = 2.0 * wall;
  return static_cast<int>(force(0));
}
