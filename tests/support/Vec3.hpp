// Shared by the tests: a Vector<3> from three numbers.
#pragma once

#include "rp/math/Matrix.hpp"

namespace rp::test {

// The vector (x, y, z).
inline Vector<3> vec3(double x, double y, double z) {
  Vector<3> v;
  v << x, y, z;
  return v;
}

}  // namespace rp::test
