// Control case: the same kinds of expressions with matching sizes compile.
#include "RoboticPlatform.hpp"
int main() {
  Matrix<3, 3> a;
  Vector<3> v, w;
  Vector<3> p = a * v + w;
  Vector<3> c = crossProduct(v, w);
  Transform t = xRotation(1.0) * translation(1, 2, 3);
  Vector<4> h = t * t.getColumn(4);
  return static_cast<int>(dotProduct(p, c) + h(0) + a.inverse()(0, 0) * 0);
}
