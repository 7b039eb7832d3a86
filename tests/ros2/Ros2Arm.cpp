// A simulated Puma 560 ("puma") with a Ros2Bridge in a process of its own, for the two-host test
// (TwoHosts_test.cpp) and the remote-arm tests (RemoteManipulator_test.cpp): joins DOMAIN with
// namespace NS on the network interface IF only, publishes at 100 Hz, prints "ready" once the
// bridge runs and ends after SECONDS seconds with status 0 (1 with a message on stderr if the arm
// or the bridge cannot start, 2 for bad usage).
// With `commands`, the bridge takes trajectories (`commands on`); with STOPFILE too, the arm also
// ends as soon as that file exists, once it has come to rest (at most 5 s later), and prints
// "final q1 ... qn" (its joint positions [rad]) before it ends, or "moving q1 ... qn" if it did
// not come to rest. RATE is the bridge's rate: Hz, or `servo` (every servo cycle, as a remote
// arm driven by torque needs); default 100.
// `nocommands` instead of `commands` leaves the bridge's commands off. Before "final" it prints
// "error MESSAGE" if the arm has an error.
// Usage: ros2_arm DOMAIN NS IF SECONDS [commands|nocommands [STOPFILE [RATE]]]
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <thread>

#include "rp/RoboticPlatform.hpp"

int main(int argc, char** argv) {
  if (argc < 5 || argc > 8 || (argc >= 6 && std::string(argv[5]) != "commands" && std::string(argv[5]) != "nocommands")) {
    std::fprintf(stderr, "usage: ros2_arm DOMAIN NS IF SECONDS [commands|nocommands [STOPFILE [RATE]]]\n");
    return 2;
  }
  rp::RoboticPlatform::setSimulationModeOn();
  try {
    rp::Puma560 puma("puma");
    rp::Ros2BridgeOptions options;
    options.domain = std::atoi(argv[1]);
    options.nameSpace = argv[2];
    options.interfaces = {argv[3]};
    options.rate = argc == 8 ? (std::string(argv[7]) == "servo" ? rp::Ros2BridgeOptions::kServoRate : std::atof(argv[7])) : 100;
    options.commands = argc >= 6 && std::string(argv[5]) == "commands";
    rp::Ros2Bridge bridge("ros", options);
    std::printf("ready\n");
    std::fflush(stdout);
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(std::atof(argv[4]));
    const char* stopFile = argc >= 7 ? argv[6] : nullptr;
    while (std::chrono::steady_clock::now() < end && (stopFile == nullptr || access(stopFile, F_OK) != 0))
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    if (stopFile != nullptr) {
      const auto restEnd = std::chrono::steady_clock::now() + std::chrono::seconds(5);
      int still = 0;  // cycles of 10 ms at rest in a row
      while (still < 30 && std::chrono::steady_clock::now() < restEnd) {
        still = puma.getJointVelocity().cwiseAbs().maxCoeff() < 1e-4 ? still + 1 : 0;
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
      if (puma.getErrorCode() != 0) std::printf("error %s\n", puma.getErrorStatus().message.c_str());
      const rp::JointVector q = puma.getJointPosition();
      std::printf(still >= 30 ? "final" : "moving");
      for (int i = 0; i < q.size(); ++i) std::printf(" %.9g", q(i));
      std::printf("\n");
      std::fflush(stdout);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ros2_arm: %s\n", e.what());
    return 1;
  }
  return 0;
}
