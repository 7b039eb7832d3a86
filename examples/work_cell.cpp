// A work cell to watch in the Scene Viewer: a Puma 560 with a gripper mounted on its end-effector
// moves between two places over a work piece, opening and closing the gripper, until Ctrl-C
// (or for `--seconds S`). The program prints the URL to open (RoboticPlatform::init starts the
// viewer); right-click an object in the view or the Object List for its pop-up menu.
//
// Run: build/bin/work_cell [-simclock] [--seconds S] [--arm-only]
// (--arm-only leaves the gripper to the user: its pop-up menu's Open/Close/Relax.)
#include "RoboticPlatform.hpp"

#include <chrono>
#include <cstdlib>
#include <iostream>
#include <string>

int main(int argc, char* argv[]) {
  RoboticPlatform::init(argc, argv,
                        "work_cell [--seconds S] [--arm-only]: a Puma 560 with a gripper at work until Ctrl-C");
  double seconds = 0;
  bool armOnly = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--seconds" && i + 1 < argc) {
      seconds = std::atof(argv[++i]);
    } else if (a == "--arm-only") {
      armOnly = true;
    } else {
      std::cerr << "work_cell: unknown argument '" << a << "' (usage: work_cell [--seconds S] [--arm-only])\n";
      return 2;
    }
  }

  Puma560 puma("puma");
  DefaultGripper gripper("gripper");
  gripper.setConnection(puma, "endEffector");
  PhysicalObject workpiece("workpiece");
  workpiece.setTransform(translation(0, 0.5, 0.05));
  DefaultTrajectoryGenerator<6> tragen("tragen");
  puma.setTrajectoryGenerator(tragen);
  // Puma560, DefaultGripper and DefaultTrajectoryGenerator publish themselves to the Scene Viewer
  // when constructed; a plain PhysicalObject is published by the program (its destructor
  // withdraws it).
  workpiece.publishObject();

  std::cout << "work_cell: objects:";
  for (const ObjectInfo& o : ObjectManager().getObjectList()) std::cout << " " << o.name << " (" << o.className << ")";
  std::cout << std::endl;

  const Transform down = xRotation(M_PI);
  const auto start = std::chrono::steady_clock::now();
  auto timeUp = [&] {
    return seconds > 0 && std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >= seconds;
  };
  auto wait = [&] {
    while (!tragen.waitUntilDone(0.1))
      if (ObjectManager::isShutdownRequested() || timeUp()) return false;
    return !ObjectManager::isShutdownRequested();
  };
  std::cout << "work_cell: running" << (seconds > 0 ? " for " + std::to_string(seconds) + " s" : " until Ctrl-C")
            << std::endl;
  int cycles = 0;
  while (!ObjectManager::isShutdownRequested() && !timeUp()) {
    if (!armOnly) gripper.open();
    tragen.moveTo(translation(0, 0.5, 0.2) * down);
    tragen.stop(0.5);
    if (!wait()) break;
    if (!armOnly) gripper.close();
    tragen.moveTo(translation(0.5, 0.5, 0.3) * down);
    tragen.moveTo(translation(0.6, 0.2, 0.2) * down);
    tragen.stop(0.5);
    if (!wait()) break;
    if (!armOnly) gripper.open();
    tragen.moveTo(translation(0.5, 0.5, 0.3) * down);
    tragen.stop(0.2);
    if (!wait()) break;
    ++cycles;
  }
  puma.clearTrajectoryGenerator();
  const ControlStatistics st = puma.getStatistics();
  std::cout << "work_cell: " << cycles << " cycles done; servo loop: " << st.cycles << " cycles, " << st.overruns
            << " overruns, computation p99 " << st.computationTime.p99 << " us, wake-up latency p99 "
            << st.wakeupLatency.p99 << " us, max " << st.wakeupLatency.max << " us" << std::endl;
  if (ObjectManager::isShutdownRequested()) {  // a fault, an emergency stop or Ctrl-C ended the motion
    std::cerr << "work_cell: stopped by a system shutdown: " << ObjectManager::getShutdownReason() << std::endl;
    return RoboticPlatform::kExitAfterShutdown;
  }
  return 0;
}
