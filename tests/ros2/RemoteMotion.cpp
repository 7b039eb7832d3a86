// The motions of the paper's Figure 21 (examples/pick_and_place.cpp) without the gripper and the
// work piece, written generically as section 3.6 writes programs: the arm is rp.cfg's [leader],
// whatever its class (a Puma560 here, or a RemoteManipulator driving a Puma in another process).
// Prints "moving" once the first motion is queued, then "final q1 ... qn" (the leader's joint positions once at rest [rad]) and ends with 0, or
// with RoboticPlatform::kExitAfterShutdown (3) after a system shutdown (a fault, a vanished remote arm).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <thread>

#include "RoboticPlatform.hpp"

int main(int argc, char* argv[]) {
  RoboticPlatform::init(argc, argv);
  ObjectManager om;
  Manipulator* arm = om.createDerivedObject<Manipulator>("leader");
  DefaultTrajectoryGenerator<6> tragen;
  arm->setTrajectoryGenerator(tragen);
  Transform down = xRotation(M_PI);
  tragen.moveTo(translation(0, 0.5, 0.12) * down);
  std::printf("moving\n");  // (for the test that kills the remote arm mid-motion)
  std::fflush(stdout);
  tragen.stop(1);
  tragen.moveTo(translation(0.5, 0.5, 0.3) * down);
  tragen.moveTo(translation(0.6, 0.2, 0.3) * down);
  tragen.stop(1);
  const bool done = tragen.waitUntilDone();
  if (!done || ObjectManager::isShutdownRequested()) {
    std::cerr << "remote_motion: stopped: " << ObjectManager::getShutdownReason() << std::endl;
    return RoboticPlatform::kExitAfterShutdown;
  }
  // At rest (the servo settles after the last setpoint).
  for (int still = 0, k = 0; still < 30 && k < 500; ++k) {
    still = arm->getJointVelocity().cwiseAbs().maxCoeff() < 1e-4 ? still + 1 : 0;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  const JointVector q = arm->getJointPosition();
  std::printf("final");
  for (int i = 0; i < q.size(); ++i) std::printf(" %.9g", q(i));
  std::printf("\n");
  return 0;
}
