// A 3x3 matrix times a 4x4 matrix must not compile.
#include "RoboticPlatform.hpp"
int main() {
  Matrix<3, 3> a;
  Matrix<4, 4> b;
  Matrix<3, 4> c = a * b;
  return static_cast<int>(c(0, 0));
}
