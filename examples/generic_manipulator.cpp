// Generic manipulator code: the excerpt of the paper's section 3.6.
//
// The program creates the manipulator that rp.cfg describes under the name "leader" and prints
// its end-effector frame. Change `class Puma560` to `class WAM` in rp.cfg and the same binary
// drives a WAM: generic code through the Manipulator interface.
//
// Run: build/bin/generic_manipulator -config examples/rp.cfg
//
// Changes from the paper's excerpt:
// - wrapped in `int main(int argc, char* argv[])` with `RoboticPlatform::init(argc, argv)` first;
// - `robot->getEndEffectorTransform()` reads `manipulator->...` (the excerpt's `robot` is a typo);
// - `std::endl` added around the transform, which prints as four rows.
#include "RoboticPlatform.hpp"

#include <iostream>

using namespace std;

int main(int argc, char* argv[]) {
  RoboticPlatform::init(argc, argv);

  Manipulator* manipulator;  // Any manipulator
  ObjectManager om;          // The object manager

  manipulator = om.createDerivedObject<Manipulator>("leader");
  // Creates either a Puma or a WAM object, depending on
  // what is specified in the global configuration file under the name "leader"

  // Now, we can do generic operations
  manipulator->enableArmPower();
  cout << "Current End-Effector Coordinate Frame: " << endl << manipulator->getEndEffectorTransform() << endl;
  return 0;
}
