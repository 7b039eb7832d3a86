// Math library example: the position equation of the paper's Figure 15.
//
// A chain of homogeneous transforms gives the position of an end-effector: the robot's base
// stands at (0.5, 0, 0) m turned 90 degrees about z; the shoulder (joint 1, about z) is 0.6 m
// above the base; the upper arm (joint 2, about y) is 0.4 m long and the forearm (joint 3, about
// y) 0.3 m; the tool points 0.1 m along the forearm. The program computes
//
//   T_tool = T_base * Rz(q1) * Tz(0.6) * Ry(q2) * Tx(0.4) * Ry(q3) * Tx(0.3) * Tx(0.1)
//
// and prints the transform, the end-effector position and its roll-pitch-yaw angles.
#include "RoboticPlatform.hpp"

#include <iostream>

int main() {
  const double q1 = 30 * M_PI / 180, q2 = -45 * M_PI / 180, q3 = 60 * M_PI / 180;

  Transform base = translation(0.5, 0, 0) * zRotation(M_PI / 2);
  Transform shoulder = zRotation(q1) * translation(0, 0, 0.6);
  Transform upperArm = yRotation(q2) * translation(0.4, 0, 0);
  Transform forearm = yRotation(q3) * translation(0.3, 0, 0);
  Transform tool = translation(0.1, 0, 0);

  Transform endEffector = base * shoulder * upperArm * forearm * tool;

  Vector<3> position = getPosition(endEffector);
  Vector<3> rpy = transformToRPY(endEffector);
  // The same point from the homogeneous position column (the paper counts columns from 1).
  Vector<4> homogeneous = endEffector.getColumn(4);

  std::cout << "End-effector transform:\n" << endEffector << "\n";
  std::cout << "Position [m]: " << RowVector<3>(position.transpose()) << "\n";
  std::cout << "Roll, pitch, yaw [deg]: " << RowVector<3>(rpy.transpose() * (180 / M_PI)) << "\n";
  std::cout << "Distance from the base [m]: " << length(position - getPosition(base)) << "\n";
  std::cout << "Homogeneous position: " << RowVector<4>(homogeneous.transpose()) << "\n";
  return 0;
}
