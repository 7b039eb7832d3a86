// Simple pick and place operation: the paper's Figure 21.
//
// A Puma 560 with a gripper moves to a work piece, closes the gripper, carries the piece over a
// via point to the target and drops it. The trajectory generator queues the motions; stop(1)
// waits until the arm has come to rest and then one second more, so the gripper acts only when
// the arm is there. The program exits when the task is done.
//
// Run: build/bin/pick_and_place [-simclock] [-log pick_and_place.csv]
//
// Changes from the paper's Figure 21:
// - `int main(int argc, char* argv[])` instead of `void main`;
// - the three positions: the paper's (0, 0.5, 0), (0.5, 0.5, 1) and (1, 1, 0) m are partly out
//   of reach of a Puma 560 at the origin with the gripper pointing down (its shoulder is 0.67 m
//   up, the arm reaches 0.86 m, and joint 5 turns at most 100 degrees); here they are
//   (0, 0.5, 0.2), (0.5, 0.5, 0.3) and (0.6, 0.2, 0.2) m;
// - a line at the end says that the task is done, or that a system shutdown (a fault, Ctrl-C)
//   stopped it (then the exit status is not 0).
#include "RoboticPlatform.hpp"

#include <iostream>

int main(int argc, char* argv[]) {
  // Initialize the Robotic Platform framework
  RoboticPlatform::init(argc, argv);

  // Create the objects required for the task
  Puma560 puma;
  DefaultGripper gripper;

  // Create the trajectory generator and connect it
  // to the Puma object
  DefaultTrajectoryGenerator<6> tragen;
  puma.setTrajectoryGenerator(tragen);

  // Create a transform that represents the end-effector
  // orientation
  Transform down = xRotation(M_PI);  // End-effector
                                     // pointing down

  // Move to the object and pick it up
  gripper.open();
  tragen.moveTo(translation(0, 0.5, 0.2) * down);
  tragen.stop(1);
  gripper.close();
  tragen.stop(1);

  // Move to the target position and drop the object
  tragen.moveTo(translation(0.5, 0.5, 0.3) * down);
  tragen.moveTo(translation(0.6, 0.2, 0.2) * down);
  tragen.stop(1);
  gripper.open();
  tragen.stop(1);

  if (ObjectManager::isShutdownRequested()) {  // a fault, an emergency stop or Ctrl-C ended the motion
    std::cerr << "pick_and_place: stopped by a system shutdown: " << ObjectManager::getShutdownReason() << std::endl;
    return RoboticPlatform::kExitAfterShutdown;
  }
  std::cout << "pick_and_place: done, end-effector at " << RowVector<3>(getPosition(puma.getEndEffectorTransform()).transpose())
            << std::endl;
  return 0;
}
