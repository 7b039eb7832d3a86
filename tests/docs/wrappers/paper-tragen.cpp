// Wrapper of docs/trajectories.md's fragments: "RoboticPlatform.hpp", the platform initialised, a
// simulated Puma 560 and its trajectory generator `tragen`, as in the paper's Figure 21.
#include "RoboticPlatform.hpp"

int main(int argc, char** argv) {
  RoboticPlatform::init(argc, argv);
  Puma560 puma;
  DefaultTrajectoryGenerator<6> tragen;
  puma.setTrajectoryGenerator(tragen);
@FRAGMENT@
  return 0;
}
