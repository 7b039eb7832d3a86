// Wrapper of class definitions written as in the paper (docs/core.md, docs/manipulators.md): the
// umbrella header "RoboticPlatform.hpp" (names unqualified), at file scope, then a main() that
// only initialises the platform.
#include "RoboticPlatform.hpp"

@FRAGMENT@

int main(int argc, char** argv) {
  RoboticPlatform::init(argc, argv);
  return 0;
}
