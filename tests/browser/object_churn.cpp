// Test program for the browser tests: creates a Puma 560 and a gripper, keeps them 0.6 s, destroys
// them, waits 0.3 s, and again, until SIGTERM: the Object List must follow, and the viewer must
// never touch an object being destroyed (run under AddressSanitizer in CI).
#include <chrono>
#include <iostream>
#include <memory>
#include <string>
#include <thread>

#include "RoboticPlatform.hpp"

int main(int argc, char* argv[]) {
  RoboticPlatform::init(argc, argv);
  for (int k = 1; !ObjectManager::isShutdownRequested(); ++k) {
    {
      Puma560 arm("arm_" + std::to_string(k));
      DefaultGripper tool("tool_" + std::to_string(k));
      tool.setConnection(arm, "endEffector");
      std::cout << "object_churn: created arm_" << k << std::endl;
      for (int i = 0; i < 12 && !ObjectManager::isShutdownRequested(); ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
  }
  return 0;
}
