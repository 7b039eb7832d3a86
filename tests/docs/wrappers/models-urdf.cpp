// Wrapper of docs/models.md's URDF fragment, as the page says: #include "rp/RoboticPlatform.hpp"
// and `using namespace rp;`, in main(); the program runs in a folder holding my_arm.urdf (a copy
// of tests/docs/fixtures/my_arm.urdf, whose tip link is tool0) and checks the arm it loaded.
#include <cstdlib>
#include <iostream>

#include "rp/RoboticPlatform.hpp"

using namespace rp;

int main() {
@FRAGMENT@
  if (arm->getNumberOfJoints() != 6) {
    std::cerr << "loadUrdf: " << arm->getNumberOfJoints() << " joints, not 6\n";
    return EXIT_FAILURE;
  }
  return 0;
}
