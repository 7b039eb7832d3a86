// Simple pick and place operation: the paper's Figure 21.
//
// A Puma 560 with a gripper on its end-effector moves to a work piece lying on the table, closes
// the gripper around it, carries it over a via point (blending there, without stopping) to the
// target and drops it: the piece falls to the table. The trajectory generator queues the motions;
// stop(1) waits until the arm has come to rest and then one second more, so the gripper acts only
// when the arm is there. While the gripper holds the piece, its mass is the arm's payload (in the
// simulated plant and in the gravity compensation). The program prints where the end-effector and
// the work piece ended and exits.
//
// Run: build/bin/pick_and_place [-simclock] [-log pick_and_place.csv]
//
// Changes from the paper's Figure 21:
// - `int main(int argc, char* argv[])` instead of `void main`;
// - a work piece (`WorkPiece piece;`, a 40 mm cube of 0.5 kg) lies on the table (z = 0) under the
//   pick point, and the gripper is mounted on the arm's end-effector
//   (`gripper.setConnection(puma, "endEffector")`): the paper's program leaves both to the work
//   cell; its tool point (between the fingertips) is 0.1 m beyond the end-effector;
// - the three positions: the paper's (0, 0.5, 0), (0.5, 0.5, 1) and (1, 1, 0) m are partly out
//   of reach of a Puma 560 at the origin with the gripper pointing down (its shoulder is 0.67 m
//   up, the arm reaches 0.86 m, and joint 5 turns at most 100 degrees); here they are
//   (0, 0.5, 0.12) (the tool point at the piece's centre, 0.02 m up), (0.5, 0.5, 0.3) and
//   (0.6, 0.2, 0.3) m (the piece is let go 0.2 m up and falls 0.18 m);
// - the motions blend at the via point (0.5, 0.5, 0.3) (the trajectory generator's default
//   Cartesian blend radius, 0.02 m; `tragen.setCartesianBlendRadius(0)` stops there);
// - a line at the end says that the task is done, with where the end-effector and the work piece
//   ended, or that a system shutdown (a fault, Ctrl-C) stopped it (then the exit status is not 0).
#include "RoboticPlatform.hpp"

#include <iostream>

int main(int argc, char* argv[]) {
  // Initialize the Robotic Platform framework
  RoboticPlatform::init(argc, argv);

  // Create the objects required for the task
  Puma560 puma;
  DefaultGripper gripper;
  WorkPiece piece;                                 // (added) the work piece on the table
  gripper.setConnection(puma, "endEffector");      // (added) the gripper on the end-effector
  piece.setTransform(translation(0, 0.5, 0.02));  // (added) under the pick point

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
  tragen.moveTo(translation(0, 0.5, 0.12) * down);
  tragen.stop(1);
  gripper.close();
  tragen.stop(1);

  // Move to the target position and drop the object
  tragen.moveTo(translation(0.5, 0.5, 0.3) * down);
  tragen.moveTo(translation(0.6, 0.2, 0.3) * down);
  tragen.stop(1);
  gripper.open();
  tragen.stop(1);

  if (ObjectManager::isShutdownRequested()) {  // a fault, an emergency stop or Ctrl-C ended the motion
    std::cerr << "pick_and_place: stopped by a system shutdown: " << ObjectManager::getShutdownReason() << std::endl;
    return RoboticPlatform::kExitAfterShutdown;
  }
  piece.waitUntilLanded();
  std::cout << "pick_and_place: done, end-effector at " << RowVector<3>(getPosition(puma.getEndEffectorTransform()).transpose())
            << "; work piece at " << RowVector<3>(getPosition(piece.getWorldTransform()).transpose()) << std::endl;
  return 0;
}
