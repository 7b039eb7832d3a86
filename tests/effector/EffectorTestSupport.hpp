#pragma once
// Fixture for the end-effector tests: installs an rp.cfg text as the global configuration and
// destroys every object the ObjectManager created after each test.
#include <gtest/gtest.h>

#include <string>

#include "rp/core/ObjectManager.hpp"
#include "rp/core/RoboticPlatform.hpp"

namespace rp::test {

class EffectorTest : public ::testing::Test {
 protected:
  void configure(const std::string& text) { RoboticPlatform::setConfiguration(Configuration::parse(text, "test.cfg")); }
  void TearDown() override {
    om_.deleteAllObjects();
    RoboticPlatform::setConfiguration(Configuration());
  }
  ObjectManager om_;
};

inline bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace rp::test
