// Inverting a 3x4 matrix must not compile.
#include "RoboticPlatform.hpp"
int main() {
  Matrix<3, 4> a;
  auto b = a.inverse();
  return static_cast<int>(b(0, 0));
}
