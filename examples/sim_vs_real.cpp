// Comparison of simulation and implementation: the paper's Figure 23.
//
// One trajectory generator feeds the same setpoints to two Puma 560 objects; the second is in
// simulation mode. Without robot hardware both are simulated, and the program prints the largest
// difference between the two arms' joint positions over the motion (0 when both are simulated).
//
// Run: build/bin/sim_vs_real [-simclock] [-log sim_vs_real.csv]
//
// Changes from the paper's Figure 23:
// - `int main(int argc, char* argv[])` instead of `void main`;
// - the first robot is named "puma", so that an rp.cfg section can put it behind a hardware
//   server: `[puma]`, `class Puma560`, `simulationMode off`, `hwserver cell` with
//   `rp-hwserver -name cell -board puma560` running (a Puma 560 wired to an I/O board);
// - after queueing the two motions the program follows them to the end and prints the largest
//   joint-position difference between the arms (the paper's program only queued them).
#include "RoboticPlatform.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <thread>

int main(int argc, char* argv[]) {
  // Initialize the Robotic Platform framework
  RoboticPlatform::init(argc, argv);

  // Create the robot objects
  Puma560 puma("puma");  // named, so that rp.cfg can wire it to hardware
  Puma560 pumaSimulated;

  // The second robot is simulated
  pumaSimulated.setSimulationModeOn();

  // Connect both to the same trajectory generator
  DefaultTrajectoryGenerator tragen;
  puma.setTrajectoryGenerator(tragen);
  pumaSimulated.setTrajectoryGenerator(tragen);

  Vector<6> target;

  // Create the trajectory
  target = 0, 45, -90, 0, 0, 0;
  tragen.move(target);

  target = -50, 0, -70, 50, -80, 0;
  tragen.move(target);

  // Follow the motion and compare the two arms in the same servo cycles (same clock time).
  double largest = 0;
  StateSnapshot a, b;
  while (!tragen.isDone() && !ObjectManager::isShutdownRequested()) {
    if (puma.getStateSnapshot(a) && pumaSimulated.getStateSnapshot(b) && a.time == b.time) {
      for (int i = 0; i < 6; ++i) largest = std::max(largest, std::abs(a.values[i] - b.values[i]));
    }
    std::this_thread::sleep_for(std::chrono::microseconds(100));
  }
  if (ObjectManager::isShutdownRequested()) {  // a fault, an emergency stop or Ctrl-C ended the motion
    std::cerr << "sim_vs_real: stopped by a system shutdown: " << ObjectManager::getShutdownReason() << std::endl;
    return RoboticPlatform::kExitAfterShutdown;
  }
  std::cout << "sim_vs_real: largest joint-position difference between the arms: " << largest << " rad" << std::endl;
  return puma.getErrorCode() == 0 && pumaSimulated.getErrorCode() == 0 ? 0 : 1;
}
