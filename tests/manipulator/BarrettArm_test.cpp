// BarrettArm, the paper's name for the WAM (section 3.6): created by name from rp.cfg with the
// 4- or 7-link model chosen there (`links`), and moved in simulation through the paper's
// generic interface (Manipulator, a DefaultTrajectoryGenerator's move() in degrees).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "SimulatedArmTest.hpp"
#include "rp/RoboticPlatform.hpp"

namespace rp::test {
namespace {

class BarrettArmTest : public SimulatedArmTest {
 protected:
  void TearDown() override {
    ObjectManager().deleteAllObjects();
    RoboticPlatform::setConfiguration(Configuration());
    SimulatedArmTest::TearDown();
  }
  // Creates [leader] as the generic code of section 3.6 does and moves every joint `degrees` from
  // its home position towards the middle of its range (the WAM 7's shoulder cannot hold its arm
  // out straight within its torque limit: small moves).
  void createAndMove(const std::string& cfg, int joints, const std::string& model, double degrees) {
    RoboticPlatform::setConfiguration(Configuration::parse(cfg, "cell.cfg"));
    ObjectManager om;
    Manipulator* manipulator = om.createDerivedObject<Manipulator>("leader");
    ASSERT_NE(manipulator, nullptr);
    EXPECT_EQ(manipulator->getClassName(), "BarrettArm");
    EXPECT_NE(dynamic_cast<WAM*>(manipulator), nullptr) << "a WAM";
    ASSERT_EQ(manipulator->getNumberOfJoints(), joints);
    EXPECT_EQ(manipulator->getModel().getName(), model);
    ASSERT_TRUE(dynamic_cast<PhysicalObject*>(manipulator)->isSimulationModeOn());

    const ManipulatorModel& m = manipulator->getModel();
    JointVector targetDegrees(joints);
    for (int i = 0; i < joints; ++i) {
      const double home = m.getHomePosition()(i), middle = (m.getPositionMin()(i) + m.getPositionMax()(i)) / 2;
      targetDegrees(i) = home * 180 / M_PI + (home < middle ? degrees : -degrees);
    }
    DefaultTrajectoryGenerator<> tragen;
    manipulator->setTrajectoryGenerator(tragen);
    manipulator->enableArmPower();
    tragen.move(targetDegrees);
    tragen.stop(0.2);
    ASSERT_TRUE(tragen.waitUntilDone(120.0)) << "the motion did not end";
    EXPECT_FALSE(ObjectManager::isShutdownRequested()) << ObjectManager::getShutdownReason();
    const JointVector q = manipulator->getJointPosition();
    const JointVector start = manipulator->getModel().getHomePosition();
    for (int i = 0; i < joints; ++i) {
      EXPECT_NEAR(q(i) * 180 / M_PI, targetDegrees(i), 2.0) << "joint " << i + 1 << " (PID with friction: a dead band)";
      EXPECT_GT(std::abs(q(i) - start(i)), (degrees / 2) * M_PI / 180) << "joint " << i + 1 << " moved";
    }
    om.deleteObject(manipulator);
  }
};

TEST_F(BarrettArmTest, FourLinkWamChosenInRpCfgMoves) {
  createAndMove("[leader]\nclass BarrettArm\nlinks 4\n", 4, "wam4", 15);
}

TEST_F(BarrettArmTest, SevenLinkWamChosenInRpCfgMoves) {
  createAndMove("[leader]\nclass BarrettArm\nlinks 7\n", 7, "wam7", 15);
}

TEST_F(BarrettArmTest, DeclaredLikeThePaperAndConfiguredByItsClassSection) {
  RoboticPlatform::setConfiguration(
      Configuration::parse("[BarrettArm]\nclass BarrettArm\nlinks 4\nposition 300 0 0\n", "cell.cfg"));
  BarrettArm arm;  // unnamed, as Puma560 puma; in the paper
  EXPECT_EQ(arm.getNumberOfJoints(), 4);
  EXPECT_NEAR(getPosition(arm.getTransform())(0), 0.3, 1e-12);
  BarrettArm seven("", 7);
  EXPECT_EQ(seven.getNumberOfJoints(), 4) << "rp.cfg's links win over the constructor's argument";
  RoboticPlatform::setConfiguration(Configuration());
  BarrettArm plain;
  EXPECT_EQ(plain.getNumberOfJoints(), 7) << "the default";
}

TEST_F(BarrettArmTest, OtherLinkCountsAreRefusedWithTheFileAndLine) {
  try {
    RoboticPlatform::setConfiguration(Configuration::parse("[leader]\nclass BarrettArm\nlinks 6\n", "cell.cfg"));
    FAIL() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), "cell.cfg:3: setting 'links': '6' is not one of 4, 7");
  }
}

}  // namespace
}  // namespace rp::test
