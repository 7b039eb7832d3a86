// A class of the user's own program (tests/core/user/UserGripper.cpp), registered in the type
// database by the one line next to its definition and by nothing else, is accepted in rp.cfg and
// created by ObjectManager::createDerivedObject() through the generic interface.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "rp/RoboticPlatform.hpp"
#include "user/UserGripper.hpp"

namespace rp {
namespace {

class UserClassTest : public ::testing::Test {
 protected:
  void SetUp() override {
    RoboticPlatform::setSimulationModeOn();
    file_ = (std::filesystem::temp_directory_path() / ("rp_user_class_" + std::to_string(::getpid()) + ".cfg")).string();
  }
  void TearDown() override {
    ObjectManager().deleteAllObjects();
    RoboticPlatform::setConfiguration(Configuration());
    std::remove(file_.c_str());
  }
  void writeAndRead(const std::string& text) {
    std::ofstream(file_) << text;
    RoboticPlatform::setConfiguration(Configuration::read(file_));
  }
  std::string file_;
};

TEST_F(UserClassTest, TheClassRegistersItselfByItsDefinition) {
  EXPECT_TRUE(TypeDatabase::instance().contains("UserGripper"));
  EXPECT_TRUE(TypeDatabase::instance().isDerivedFrom<Gripper>("UserGripper"));
  ASSERT_NE(TypeDatabase::instance().find("UserGripper")->schema.find("port"), nullptr) << "its declareSettings";
}

TEST_F(UserClassTest, CreateDerivedObjectFindsItByTheClassNameInRpCfg) {
  writeAndRead("[hand]\nclass UserGripper\nport /dev/ser1\nposition 0 0 100\n");
  ObjectManager om;
  Gripper* gripper = om.createDerivedObject<Gripper>("hand");  // generic code: any gripper
  ASSERT_NE(gripper, nullptr);
  auto* mine = dynamic_cast<user::UserGripper*>(gripper);
  ASSERT_NE(mine, nullptr) << "created as " << gripper->getClassName();
  EXPECT_EQ(gripper->getClassName(), "UserGripper");
  EXPECT_EQ(mine->port(), "/dev/ser1");
  EXPECT_NEAR(getPosition(gripper->getTransform())(2), 0.1, 1e-12);
  gripper->executeCommand("Open Gripper");
  EXPECT_EQ(gripper->getState(), Gripper::State::Open);
  EXPECT_EQ(mine->hardwareCalls(), 0) << "simulated: the hardware is not driven";
}

TEST_F(UserClassTest, ItsSettingsAreCheckedWhenRpCfgIsRead) {
  try {
    writeAndRead("[hand]\nclass UserGripper\nprot /dev/ser1\n");
    FAIL() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(":3: setting 'prot' is not known for class UserGripper"), std::string::npos)
        << e.what();
  }
}

TEST_F(UserClassTest, AnUnnamedOneIsConfiguredFromItsClassSection) {
  writeAndRead("[UserGripper]\nclass UserGripper\nport /dev/ser2\n");
  user::UserGripper gripper;
  EXPECT_EQ(gripper.port(), "/dev/ser2");
}

}  // namespace
}  // namespace rp
