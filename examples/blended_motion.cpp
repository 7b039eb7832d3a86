// Blended motion: a Puma 560 passes through via points without stopping.
//
// The trajectory generator blends consecutive motions: with a joint blend radius of 20 degrees
// the arm leaves the straight line towards a via point 20 degrees (at most half a segment) before
// it, and joins the next line as far after it, without stopping; position, velocity and
// acceleration stay continuous. Then two Cartesian straight lines meet at a corner blended within
// 5 cm. The program prints how many via points were blended and where the arm ended.
//
// Run: build/bin/blended_motion [-simclock] [-log blended_motion.csv]
// The log holds the setpoints (qdes, qddes, qdddes) that scripts/plot-trajectory draws; docs/
// trajectories.md shows the plot.
#include "RoboticPlatform.hpp"

#include <iostream>

int main(int argc, char* argv[]) {
  RoboticPlatform::init(argc, argv);

  Puma560 puma("puma");
  DefaultTrajectoryGenerator<6> tragen;
  puma.setTrajectoryGenerator(tragen);

  // Joint space: four via points and a target, in degrees; blend radius 20 degrees.
  tragen.setJointBlendRadius(20 * M_PI / 180);
  Vector<6> q;
  q = 30, 60, -120, 0, 30, 0;
  tragen.move(q);
  q = 60, 30, -90, 40, 60, 30;
  tragen.move(q);
  q = 20, 50, -130, -20, 40, 60;
  tragen.move(q);
  q = -20, 40, -100, 10, 70, 0;
  tragen.move(q);
  q = 0, 45, -120, 0, 60, 0;
  tragen.move(q);
  tragen.waitUntilDone();

  // Cartesian space: two straight lines with the gripper pointing down, corner blended within 5 cm.
  tragen.setJointBlendRadius(0);
  tragen.setCartesianBlendRadius(0.05);
  const Transform down = xRotation(M_PI);
  tragen.moveToThroughJointSpace(translation(0.5, 0.5, 0.3) * down);  // to the start of the lines
  tragen.waitUntilDone();
  tragen.moveTo(translation(0.6, 0.2, 0.2) * down);
  tragen.moveTo(translation(0.3, 0.4, 0.2) * down);
  tragen.stop(0.5);

  if (ObjectManager::isShutdownRequested()) {  // a fault, an emergency stop or Ctrl-C ended the motion
    std::cerr << "blended_motion: stopped by a system shutdown: " << ObjectManager::getShutdownReason() << std::endl;
    return RoboticPlatform::kExitAfterShutdown;
  }
  std::cout << "blended_motion: " << tragen.getBlendCount() << " via points blended, end-effector at "
            << RowVector<3>(getPosition(puma.getEndEffectorTransform()).transpose()) << std::endl;
  return 0;
}
