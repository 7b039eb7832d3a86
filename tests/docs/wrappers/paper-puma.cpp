// Wrapper of fragments that use a simulated Puma 560 called `puma` (docs/manipulators.md:
// "Pushing the simulated arm"): "RoboticPlatform.hpp", the platform initialised, `Puma560 puma;`.
#include "RoboticPlatform.hpp"

int main(int argc, char** argv) {
  RoboticPlatform::init(argc, argv);
  Puma560 puma;
@FRAGMENT@
  return 0;
}
