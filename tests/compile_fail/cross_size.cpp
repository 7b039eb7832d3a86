// The cross product of 4-vectors must not compile.
#include "RoboticPlatform.hpp"
int main() {
  Vector<4> a, b;
  auto c = crossProduct(a, b);
  return static_cast<int>(c(0));
}
