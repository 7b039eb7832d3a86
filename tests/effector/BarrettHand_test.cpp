// BarrettHand (the effector class) against the BarrettHand emulator on a pseudo-terminal.
#include "rp/effector/BarrettHand.hpp"

#include <gtest/gtest.h>

#include "BarrettHandEmulator.hpp"
#include "EffectorTestSupport.hpp"

namespace rp {
namespace {

using emulator::BarrettHandEmulator;
using test::contains;

class BarrettHandTest : public test::EffectorTest {
 protected:
  void SetUp() override {
    hand_.start();
    configure("[hand]\nclass BarrettHand\nsimulationMode off\nport " + hand_.devicePath() +
              "\ntimeout 300\nmotionTimeout 500\n");
  }
  BarrettHandEmulator hand_;
};

TEST_F(BarrettHandTest, InitialisesThenClosesOpensAndRelaxes) {
  auto* g = om_.createDerivedObject<Gripper>("hand");
  g->executeCommand("Close");
  ASSERT_EQ(g->getErrorCode(), 0) << g->getErrorStatus().message;
  EXPECT_EQ(g->getState(), Gripper::State::Closed);
  g->executeCommand("Open");
  g->executeCommand("Relax");
  EXPECT_EQ(g->getErrorCode(), 0) << g->getErrorStatus().message;
  EXPECT_EQ(hand_.commands(), (std::vector<std::string>{"HI", "GC", "GO", "T"}));
  std::string reply;
  ASSERT_TRUE(g->handleMessage("read", "", reply));
  EXPECT_EQ(reply, "{\"state\": \"relaxed\", \"positions\": [0, 0, 0, 0]}");
}

TEST_F(BarrettHandTest, ReadingDoesNotInitialiseTheHandOnlyInitializeDoes) {
  auto* g = om_.createDerivedObject<BarrettHand>("hand");
  std::string reply;
  ASSERT_TRUE(g->handleMessage("read", "", reply));
  EXPECT_EQ(reply, "{\"state\": \"unknown\", \"positions\": [0, 0, 0, 0]}") << reply;
  ASSERT_TRUE(g->handleMessage("read", "", reply));
  EXPECT_EQ(hand_.commands(), (std::vector<std::string>{"FGET P", "FGET P"})) << "no HI: it moves every finger";
  g->executeCommand("Initialize");
  EXPECT_EQ(g->getErrorCode(), 0) << g->getErrorStatus().message;
  EXPECT_EQ(hand_.commands().back(), "HI");
}

TEST(BarrettHand, SectionWithoutPortIsAConfigurationError) {
  RoboticPlatform::setConfiguration(
      Configuration::parse("# a hand\n[hand]\nclass BarrettHand\nsimulationMode off\nbaud 9600\n", "t.cfg"));
  ObjectManager om;
  try {
    om.createDerivedObject<Gripper>("hand");
    FAIL() << "created without a port";
  } catch (const ConfigError& e) {
    EXPECT_TRUE(contains(e.what(), "t.cfg:2")) << e.what();
    EXPECT_TRUE(contains(e.what(), "[hand] has no 'port' setting")) << e.what();
  }
}

TEST_F(BarrettHandTest, ErrReplyBecomesTheErrorStatus) {
  auto* g = om_.createDerivedObject<BarrettHand>("hand");
  ASSERT_TRUE(g->initialize()) << g->getErrorStatus().message;
  hand_.setFault(BarrettHandEmulator::Fault::kError, 16);
  EXPECT_FALSE(g->close());
  EXPECT_EQ(g->getErrorCode(), 1);
  EXPECT_TRUE(contains(g->getErrorStatus().message, "hand: BarrettHand " + hand_.devicePath() +
                                                        ": 'GC' failed: ERR 16 (couldn't reach position)"))
      << g->getErrorStatus().message;
  hand_.setFault(BarrettHandEmulator::Fault::kNone);
  EXPECT_TRUE(g->close()) << g->getErrorStatus().message;
  EXPECT_EQ(g->getErrorCode(), 0) << "a successful command clears the error";
}

TEST_F(BarrettHandTest, SilentHandTimesOutAndUnpluggedHandIsReported) {
  auto* g = om_.createDerivedObject<Gripper>("hand");
  hand_.setFault(BarrettHandEmulator::Fault::kSilent);
  EXPECT_FALSE(g->close());
  EXPECT_TRUE(contains(g->getErrorStatus().message, "'HI' failed: no reply within 500 ms")) << g->getErrorStatus().message;
  hand_.stop();
  EXPECT_FALSE(g->open());
  EXPECT_EQ(g->getErrorCode(), 1);
}

TEST(BarrettHand, NoSuchSerialPort) {
  RoboticPlatform::setConfiguration(
      Configuration::parse("[hand]\nclass BarrettHand\nsimulationMode off\nport /dev/rp-no-such-port\n", "t.cfg"));
  ObjectManager om;
  auto* g = om.createDerivedObject<Gripper>("hand");
  EXPECT_FALSE(g->close());
  EXPECT_TRUE(contains(g->getErrorStatus().message, "cannot open serial port: No such file or directory"))
      << g->getErrorStatus().message;
  om.deleteAllObjects();
  RoboticPlatform::setConfiguration(Configuration());
}

TEST(BarrettHand, SimulationNeedsNoPort) {
  BarrettHand hand;
  EXPECT_TRUE(hand.isSimulationModeOn());
  EXPECT_TRUE(hand.close());
  EXPECT_EQ(hand.getState(), Gripper::State::Closed);
}

}  // namespace
}  // namespace rp
