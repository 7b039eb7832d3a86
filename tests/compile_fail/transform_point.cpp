// A Transform times a 3-vector must not compile (use transformPoint or a homogeneous 4-vector).
#include "RoboticPlatform.hpp"
int main() {
  Transform t;
  Vector<3> p;
  Vector<3> q = t * p;
  return static_cast<int>(q(0));
}
