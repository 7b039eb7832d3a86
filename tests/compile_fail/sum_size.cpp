// Adding a 3-vector to a 4-vector must not compile.
#include "RoboticPlatform.hpp"
int main() {
  Vector<3> a;
  Vector<4> b;
  auto c = a + b;
  return static_cast<int>(c(0));
}
