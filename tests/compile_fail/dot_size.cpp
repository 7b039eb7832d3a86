// The dot product of a 3-vector and a 4-vector must not compile.
#include "RoboticPlatform.hpp"
int main() {
  Vector<3> a;
  Vector<4> b;
  return static_cast<int>(dotProduct(a, b));
}
