// A Puma560 with simulation mode off drives the hardware path: a hardware server
// (`rp-hwserver -board puma560`, a Puma 560 wired to an I/O board) started as a child process.
// Encoder counts in, DAC volts out, amplifier enable; on the real clock.
#include <gtest/gtest.h>

#include <unistd.h>

#include <chrono>
#include <csignal>
#include <thread>

#include "ChildProcess.hpp"
#include "rp/RoboticPlatform.hpp"

namespace rp {
namespace {

class StepTo : public TrajectoryGenerator {
 public:
  explicit StepTo(const JointVector& target) : target_(target) {}
  ~StepTo() override { releaseFromManipulators(); }
  bool getCurrentSetpoint(double, Setpoint& sp) override {
    sp.position = target_;
    return true;
  }

 private:
  JointVector target_;
};

TEST(HardwareManipulator, PumaBehindAHardwareServerHoldsMovesAndShutsDownWhenTheServerDies) {
  const std::string name = "test-arm-" + std::to_string(::getpid());
  // -watchdog 5000: a servo loop stalled by a loaded test machine is not cut off by the server.
  test::ChildProcess server({RP_HWSERVER_PATH, "-name", name, "-rate", "1000", "-board", "puma560", "-watchdog", "5000"});
  ASSERT_TRUE(server.readLine(10000).has_value()) << "the server did not start";
  RoboticPlatform::setConfiguration(Configuration::parse(
      "[leader]\nclass Puma560\nsimulationMode off\nhwserver " + name + "\n", "rp.cfg"));
  RoboticPlatform::setSimulationModeOff();
  RoboticPlatform::useRealClock();
  ObjectManager::resetShutdown();
  {
    Puma560 puma("leader");
    ASSERT_TRUE(puma.usesHardware());
    const JointVector home = puma.getModel().getHomePosition();
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    // Holding under gravity compensation through encoders and DACs (quantised at 5e-5 rad).
    const JointVector held = puma.getJointPosition();
    for (int i = 0; i < 6; ++i) EXPECT_NEAR(held(i), home(i), 0.01) << "joint " << i + 1;
    EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;

    JointVector target = home;
    target(0) += 0.05;
    StepTo step(target);
    puma.setTrajectoryGenerator(step);
    std::this_thread::sleep_for(std::chrono::milliseconds(1500));
    EXPECT_NEAR(puma.getJointPosition()(0), target(0), 0.01) << "the arm behind the server follows";
    EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
    puma.clearTrajectoryGenerator();

    // The server dies: the next reads fail and the servo loop requests a safe shutdown.
    server.signal(SIGKILL);
    ASSERT_TRUE(ObjectManager::waitForShutdown(5));
    EXPECT_NE(puma.getErrorStatus().message.find("hardware failure"), std::string::npos)
        << puma.getErrorStatus().message;
  }
  RoboticPlatform::setSimulationModeOn();
  RoboticPlatform::useSimulatedClock();
  ObjectManager::resetShutdown();
}

TEST(HardwareManipulator, AnAbsentServerIsAClearError) {
  RoboticPlatform::setConfiguration(Configuration::parse(
      "[leader]\nclass Puma560\nsimulationMode off\nhwserver no-such-server\n", "rp.cfg"));
  RoboticPlatform::setSimulationModeOff();
  EXPECT_THROW(Puma560("leader"), IoException);
  RoboticPlatform::setSimulationModeOn();
}

}  // namespace
}  // namespace rp
