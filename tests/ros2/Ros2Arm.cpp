// A simulated Puma 560 ("puma") with a Ros2Bridge in a process of its own, for the two-host test
// (TwoHosts_test.cpp): joins DOMAIN with namespace NS on the network interface IF only, publishes
// at 100 Hz, prints "ready" once the bridge runs and ends after SECONDS seconds with status 0 (1
// with a message on stderr if the arm or the bridge cannot start, 2 for bad usage).
// Usage: ros2_arm DOMAIN NS IF SECONDS
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <thread>

#include "rp/RoboticPlatform.hpp"

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: ros2_arm DOMAIN NS IF SECONDS\n");
    return 2;
  }
  rp::RoboticPlatform::setSimulationModeOn();
  try {
    rp::Puma560 puma("puma");
    rp::Ros2BridgeOptions options;
    options.domain = std::atoi(argv[1]);
    options.nameSpace = argv[2];
    options.interfaces = {argv[3]};
    options.rate = 100;
    rp::Ros2Bridge bridge("ros", options);
    std::printf("ready\n");
    std::fflush(stdout);
    std::this_thread::sleep_for(std::chrono::duration<double>(std::atof(argv[4])));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ros2_arm: %s\n", e.what());
    return 1;
  }
  return 0;
}
