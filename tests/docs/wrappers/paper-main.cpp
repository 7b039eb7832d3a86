// Wrapper of fragments written as in the paper (docs/core.md, docs/manipulators.md): the
// umbrella header "RoboticPlatform.hpp" (names unqualified), inside main(argc, argv).
#include "RoboticPlatform.hpp"

int main(int argc, char** argv) {
@FRAGMENT@
  return 0;
}
