// The operator's commands of a manipulator (the control panel's buttons and the pop-up menu,
// paper Figures 17 and 18) as the GUI runs them, by name: the servo-control switch among the
// controls the program offered, and what a command says when it is refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "SimulatedArmTest.hpp"
#include "rp/RoboticPlatform.hpp"

namespace rp {
namespace {

using test::ConstantTorque;
using test::simClock;
using OperatorCommands = test::SimulatedArmTest;

bool hasCommand(const RoboticObject& o, const std::string& name) {
  const std::vector<CommandInfo> commands = o.getCommands();
  return std::any_of(commands.begin(), commands.end(), [&](const CommandInfo& c) { return c.name == name; });
}

// Counts its cycles and outputs the default position control's torque (it holds the arm).
struct CountingControl : ServoControl {
  explicit CountingControl(const std::string& name) : ServoControl(name) {}
  ~CountingControl() override { releaseFromManipulator(); }
  void activate() override { dynamic_cast<DefaultManipulator&>(*d_manipulator).getDefaultPositionControl().activate(); }
  void calculate() override {
    ++calls;
    dynamic_cast<DefaultManipulator&>(*d_manipulator).getDefaultPositionControl().calculate();
  }
  std::atomic<int> calls{0};
};

TEST_F(OperatorCommands, TheServoControlSwitchOffersTheDefaultControlAndThoseTheProgramOffered) {
  Puma560 puma("arm");
  EXPECT_EQ(puma.getServoControlNames(), std::vector<std::string>{"arm.control"});
  EXPECT_EQ(puma.getServoControlName(), "arm.control");
  CountingControl stiff("stiff");
  puma.addServoControl(stiff);  // offered, not used
  EXPECT_EQ(puma.getServoControlNames(), (std::vector<std::string>{"arm.control", "stiff"}));
  EXPECT_EQ(puma.getServoControlName(), "arm.control");
  EXPECT_TRUE(hasCommand(puma, "Servo Control: stiff"));
  // A control set by the program is offered too, so the operator can switch back to it.
  CountingControl soft("soft");
  puma.setServoControl(soft);
  EXPECT_EQ(puma.getServoControlNames(), (std::vector<std::string>{"arm.control", "stiff", "soft"}));
  EXPECT_EQ(puma.getServoControlName(), "soft");

  simClock().pause();
  const JointVector before = puma.getJointPosition();
  const std::string said = puma.executeCommand("Servo Control: stiff");
  EXPECT_NE(said.find("servo control stiff in use"), std::string::npos) << said;
  EXPECT_EQ(&puma.getServoControl(), &stiff);
  // One cycle first: a cycle under way when the clock paused may still have run the one before
  // (it did once, under ASan in CI); from the next cycle on, only the chosen one runs.
  ASSERT_TRUE(puma.runCycles(1));
  const int softCalls = soft.calls.load();
  ASSERT_TRUE(puma.runCycles(500));
  EXPECT_GE(stiff.calls.load(), 499) << "the chosen control runs";
  EXPECT_EQ(soft.calls.load(), softCalls) << "the one before does not";
  EXPECT_LT((puma.getJointPosition() - before).cwiseAbs().maxCoeff(), 1e-3) << "a bumpless switch: the arm stays";
  EXPECT_EQ(puma.executeCommand("Servo Control: arm.control").find("servo control arm.control in use"), 0u);
  EXPECT_EQ(&puma.getServoControl(), &puma.getDefaultPositionControl());
  simClock().resume();
  EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
}

TEST_F(OperatorCommands, AReleasedOrDestroyedControlIsNoLongerOffered) {
  Puma560 puma("arm");
  auto gone = std::make_unique<CountingControl>("gone");
  puma.setServoControl(*gone);
  CountingControl kept("kept");
  puma.addServoControl(kept);
  puma.releaseServoControl(kept);
  EXPECT_FALSE(hasCommand(puma, "Servo Control: kept"));
  gone.reset();  // in use: the default control takes over
  EXPECT_FALSE(hasCommand(puma, "Servo Control: gone"));
  EXPECT_EQ(puma.getServoControlNames(), std::vector<std::string>{"arm.control"});
  EXPECT_EQ(puma.getServoControlName(), "arm.control");
  try {
    puma.executeCommand("Servo Control: gone");
    ADD_FAILURE() << "a destroyed control was switched to";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("no command 'Servo Control: gone'"), std::string::npos) << e.what();
  }
  // The same name may be offered again by a new control.
  CountingControl again("gone");
  puma.addServoControl(again);
  EXPECT_TRUE(hasCommand(puma, "Servo Control: gone"));
}

TEST_F(OperatorCommands, SwitchingTheServoControlIsRefusedDuringAShutdown) {
  Puma560 puma("arm");
  CountingControl other("other");
  puma.addServoControl(other);
  ObjectManager::requestSystemShutdown("test: shutdown");
  ASSERT_TRUE(ObjectManager::waitForShutdown(20));
  EXPECT_THROW(puma.executeCommand("Servo Control: other"), std::logic_error);
  EXPECT_NE(&puma.getServoControl(), &other);
}

}  // namespace
}  // namespace rp
