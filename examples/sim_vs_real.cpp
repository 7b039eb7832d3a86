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
//   joint-position difference between the arms, the second interpolated at the first's sample
//   times (the paper's program only queued them).
#include "RoboticPlatform.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <thread>
#include <vector>

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

  // Follow the motion, recording each arm's published joint positions with their servo-cycle
  // times; then compare the arms at the same instants: the second arm's positions interpolated
  // (linearly) at the first arm's sample times (the two servo loops run on their own clocks'
  // cycles, so their samples rarely share a time stamp).
  struct Sample {
    double time;
    double q[6];
  };
  std::vector<Sample> real, simulated;
  auto record = [](const Puma560& arm, std::vector<Sample>& samples) {
    StateSnapshot s;
    if (!arm.getStateSnapshot(s) || (!samples.empty() && s.time <= samples.back().time)) return;
    Sample sample{s.time, {}};
    std::copy(s.values, s.values + 6, sample.q);
    samples.push_back(sample);
  };
  while (!tragen.isDone() && !ObjectManager::isShutdownRequested()) {
    record(puma, real);
    record(pumaSimulated, simulated);
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  double largest = 0;
  std::size_t k = 0, compared = 0;
  for (const Sample& s : real) {
    while (k + 1 < simulated.size() && simulated[k + 1].time < s.time) ++k;
    if (k + 1 >= simulated.size() || simulated[k].time > s.time) continue;  // outside the other record
    const Sample& s0 = simulated[k];
    const Sample& s1 = simulated[k + 1];
    // Only between samples one servo cycle apart (or at a sample), where the linear interpolation
    // is accurate; on the simulated clock both arms' samples share their times.
    if (s.time != s0.time && s.time != s1.time && s1.time - s0.time > 1.5 * puma.getPeriod()) continue;
    const double w = (s.time - s0.time) / (s1.time - s0.time);
    for (int i = 0; i < 6; ++i) largest = std::max(largest, std::abs(s.q[i] - ((1 - w) * s0.q[i] + w * s1.q[i])));
    ++compared;
  }
  if (ObjectManager::isShutdownRequested()) {  // a fault, an emergency stop or Ctrl-C ended the motion
    std::cerr << "sim_vs_real: stopped by a system shutdown: " << ObjectManager::getShutdownReason() << std::endl;
    return RoboticPlatform::kExitAfterShutdown;
  }
  std::cout << "sim_vs_real: " << compared << " instants compared; largest joint-position difference between the arms: "
            << largest << " rad" << std::endl;
  return puma.getErrorCode() == 0 && pumaSimulated.getErrorCode() == 0 ? 0 : 1;
}
