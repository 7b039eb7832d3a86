// A Puma560 with simulation mode off drives the hardware path: a hardware server
// (`rp-hwserver -board puma560`, a Puma 560 wired to an I/O board) started as a child process.
// Encoder counts in, DAC volts out, amplifier enable; on the real clock.
#include <gtest/gtest.h>

#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <thread>

#include "ChildProcess.hpp"
#include "SimulatedArmTest.hpp"
#include "rp/RoboticPlatform.hpp"
#include "rp/io/HwServerIoBoard.hpp"

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

// Starts `rp-hwserver -board puma560` named NAME-PID and configures [leader] as a Puma behind
// it, on the real clock. -watchdog 5000: a servo loop stalled by a loaded test machine is not cut
// off by the server.
test::ChildProcess startServer(const std::string& prefix) {
  const std::string name = prefix + "-" + std::to_string(::getpid());
  RoboticPlatform::setConfiguration(Configuration::parse(
      "[leader]\nclass Puma560\nsimulationMode off\nhwserver " + name + "\n", "rp.cfg"));
  RoboticPlatform::setSimulationModeOff();
  RoboticPlatform::useRealClock();
  ObjectManager::resetShutdown();
  return test::ChildProcess({RP_HWSERVER_PATH, "-name", name, "-rate", "1000", "-board", "puma560", "-watchdog", "5000"});
}

// Each test ends as the suite began, however it ends (a failed ASSERT too): no configuration,
// simulation mode on, the simulated clock, no shutdown pending.
class HardwareManipulator : public ::testing::Test {
 protected:
  void TearDown() override {
    RoboticPlatform::setConfiguration(Configuration());
    RoboticPlatform::setSimulationModeOn();
    RoboticPlatform::useSimulatedClock();
    ObjectManager::resetShutdown();
  }
};

TEST_F(HardwareManipulator, PumaBehindAHardwareServerHoldsMovesAndShutsDownWhenTheServerDies) {
  test::ChildProcess server = startServer("test-arm");
  ASSERT_TRUE(server.readLine(30000).has_value()) << "the server did not start";
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

    // The server dies: the next reads fail and the servo loop requests a safe shutdown. (Killed,
    // it leaves its shared memory behind: removed here, as its operator would.)
    server.signal(SIGKILL);
    EXPECT_EQ(::shm_unlink(("/rp-hwserver-test-arm-" + std::to_string(::getpid())).c_str()), 0)
        << "the killed server's shared memory (HwServerShm.hpp's name)";
    ASSERT_TRUE(ObjectManager::waitForShutdown(5));
    EXPECT_NE(puma.getErrorStatus().message.find("hardware failure"), std::string::npos)
        << puma.getErrorStatus().message;
  }
}

TEST_F(HardwareManipulator, AStalledCycleIsNoVelocitySpike) {
  // 100 ms without a cycle while joint 1 moves at 0.5 rad/s: the encoders moved 0.05 rad, which
  // divided by one period (1 ms) read as 50 rad/s and tripped the 2 rad/s velocity limit. The
  // velocity is taken over the time that really passed.
  test::ChildProcess server = startServer("test-stall");
  ASSERT_TRUE(server.readLine(30000).has_value()) << "the server did not start";
  {
    Puma560 puma("leader");
    test::StallingControl stall(puma.getDefaultPositionControl(), 300, 0, std::chrono::milliseconds(100));  // cycle 300: 100 ms
    test::JointRamp ramp(0, 0.5, 1.0);  // joint 1 at 0.5 rad/s for 1 s
    puma.setServoControl(stall);
    puma.setTrajectoryGenerator(ramp);
    for (int i = 0; i < 3000 && stall.calls.load() < 1000; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    EXPECT_GE(stall.calls.load(), 1000);
    EXPECT_GE(puma.getStatistics().missedCycles, 90u) << "the stall happened";
    EXPECT_FALSE(ObjectManager::isShutdownRequested()) << ObjectManager::getShutdownReason();
    EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
    puma.clearTrajectoryGenerator();
  }
}

// A Puma held still behind the server dithers by an encoder count now and then (5e-5 rad), which
// the velocity filter shows as pulses of up to 0.0072 rad/s a count. Still is at rest all the same:
// leaving the hardware is accepted, and a shutdown's hold powers the arm off once it has been still
// for 50 ms, not at the hold's 3 s timeout. (Both asked for less than the pulse of one count.)
TEST_F(HardwareManipulator, AnArmHeldStillIsAtRestWhateverItsEncodersDither) {
  test::ChildProcess server = startServer("test-rest");
  ASSERT_TRUE(server.readLine(30000).has_value()) << "the server did not start";
  double holdSeconds = 0;
  {
    auto puma = std::make_unique<Puma560>("leader");
    JointVector target = puma->getModel().getHomePosition();
    target(0) += 0.05;
    target(2) -= 0.05;
    {
      StepTo step(target);
      puma->setTrajectoryGenerator(step);
      std::this_thread::sleep_for(std::chrono::milliseconds(1000));
      puma->clearTrajectoryGenerator();
    }
    double dither = 0;  // the largest velocity read while the arm holds still
    for (int i = 0; i < 500; ++i) {
      dither = std::max(dither, puma->getJointVelocity().cwiseAbs().maxCoeff());
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    EXPECT_LT((puma->getJointPosition() - target).cwiseAbs().maxCoeff(), 0.01) << "holding at the target";
    std::printf("largest velocity read while held still: %.5f rad/s\n", dither);
    EXPECT_NO_THROW(puma->setSimulationModeOn()) << "a still arm is at rest";
    EXPECT_FALSE(puma->usesHardware());
    EXPECT_NO_THROW(puma->setSimulationModeOff()) << "and back to the hardware";
    ASSERT_TRUE(puma->usesHardware());
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    const auto start = std::chrono::steady_clock::now();
    puma.reset();  // the shutdown's hold: powered off once still
    holdSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  EXPECT_LT(holdSeconds, 1.0) << "the hold waited for a rest that encoder dither never gave";
}

// StateSnapshot::readTime (the ROS 2 bridge's stamps) of an arm behind a hardware server: the
// server's sample (its CLOCK_MONOTONIC stamp, on the arm's clock), as another client of the
// server reads it; a simulated arm's is its cycle's time (DefaultManipulator_test). While the
// server is stopped, the cycles go on reading its last sample: they keep that sample's time. (With
// the time of each read instead, old joints went out under new stamps: to a reader differentiating
// over them, as a program driving the arm over ROS 2 does, a velocity dip and then a spike.)
TEST_F(HardwareManipulator, TheStateSnapshotHoldsForTheServersSample) {
  test::ChildProcess server = startServer("test-read");
  ASSERT_TRUE(server.readLine(30000).has_value()) << "the server did not start";
  {
    Puma560 puma("leader");
    ASSERT_TRUE(puma.usesHardware());
    const auto* clock = dynamic_cast<const RealClock*>(&puma.getControlProgram()->getClock());
    ASSERT_NE(clock, nullptr);
    HwServerIoBoard probe("test-read-" + std::to_string(::getpid()), 500, HwServerIoBoard::Heartbeat::kBackgroundThread);
    auto onArmsClock = [&](std::int64_t ns) { return 1e-9 * static_cast<double>(ns - clock->epochNanoseconds()); };
    // The server's latest sample time, read again while the server is storing one (-1); -1 if it
    // still is after 100 ms (stopped in the middle of a store).
    auto serversLatest = [&]() -> std::int64_t {
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(100);
      std::int64_t t = probe.inputSampleTime();
      while (t < 0 && std::chrono::steady_clock::now() < deadline) t = probe.inputSampleTime();
      return t;
    };
    auto nextCycle = [&](double after) {
      StateSnapshot s;
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
      while (puma.getStateSnapshot(s) && s.time <= after && std::chrono::steady_clock::now() < deadline)
        std::this_thread::sleep_for(std::chrono::microseconds(200));
      return s;
    };
    // Running: each snapshot's joints are a sample the server took before the snapshot was read.
    StateSnapshot s = nextCycle(0);
    for (int i = 0; i < 20; ++i) {
      s = nextCycle(s.time);
      const std::int64_t ns = serversLatest();
      ASSERT_GT(ns, 0);
      const double latest = onArmsClock(ns);
      EXPECT_GT(s.readTime, 0);
      EXPECT_LE(s.readTime, latest + 1e-8) << "a sample newer than the server's latest";
      EXPECT_LT(latest - s.readTime, 0.5) << "a sample half a second old";
    }
    // Stopped: 30 ms of cycles read the last sample, and keep its time. A stop that lands in the
    // middle of a sample store (the sequence odd) is undone, and the server runs two whole cycles
    // before the next try. (Stopped again at once, it stayed stuck in that store: the tries added
    // up past the arm's 500 ms server timeout, and under ASan the arm shut down once.)
    std::int64_t lastNs = -1;
    for (int attempt = 0; attempt < 100 && lastNs < 0; ++attempt) {
      server.signal(SIGSTOP);
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
      lastNs = probe.inputSampleTime();  // stopped: -1 stays -1, no use waiting
      if (lastNs >= 0) break;
      server.signal(SIGCONT);
      ASSERT_EQ(probe.waitForCycle(2000), IoStatus::kOk) << "the server did not go on after SIGCONT";
    }
    ASSERT_GT(lastNs, 0) << "the server stopped in the middle of storing a sample, 100 times";
    const double last = onArmsClock(lastNs);
    const StateSnapshot first = nextCycle(clock->getTime());  // a cycle after the stop
    const StateSnapshot later = nextCycle(first.time + 0.03);
    server.signal(SIGCONT);
    EXPECT_GE(later.cycle - first.cycle, 10u) << "the servo loop did not run while the server was stopped";
    EXPECT_NEAR(first.readTime, last, 1e-8);
    EXPECT_NEAR(later.readTime, last, 1e-8) << "a cycle reading the stopped server's sample again stamped it anew";
    for (int k = 0; k < 6; ++k) EXPECT_EQ(later.values[k], first.values[k]) << "joint " << k + 1;
    // Going again: new samples, new times.
    StateSnapshot resumed = later;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
    while (resumed.readTime <= last && std::chrono::steady_clock::now() < deadline) resumed = nextCycle(resumed.time);
    EXPECT_GT(resumed.readTime, last) << "no new sample after the server went on";
    EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
  }
}

TEST_F(HardwareManipulator, AnAbsentServerIsAClearError) {
  RoboticPlatform::setConfiguration(Configuration::parse(
      "[leader]\nclass Puma560\nsimulationMode off\nhwserver no-such-server\n", "rp.cfg"));
  RoboticPlatform::setSimulationModeOff();
  EXPECT_THROW(Puma560("leader"), IoException);
}

}  // namespace
}  // namespace rp
