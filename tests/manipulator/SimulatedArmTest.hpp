// Shared by the manipulator tests: the platform's simulated clock and a fixture that runs each
// test in simulation mode on it with a fresh configuration and no pending shutdown.
#pragma once

#include <gtest/gtest.h>

#include "rp/RoboticPlatform.hpp"

namespace rp::test {

inline SimulatedClock& simClock() {
  RoboticPlatform::useSimulatedClock();
  return dynamic_cast<SimulatedClock&>(RoboticPlatform::getDefaultClock());
}

class SimulatedArmTest : public ::testing::Test {
 protected:
  void SetUp() override {
    RoboticPlatform::setConfiguration(Configuration());
    RoboticPlatform::setSimulationModeOn();
    ObjectManager::resetShutdown();
    simClock().resume();
  }
  void TearDown() override { simClock().resume(); }
};

}  // namespace rp::test
