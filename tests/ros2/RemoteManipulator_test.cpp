// RemoteManipulator: the paper's generic program (section 3.6, examples/generic_manipulator) and the
// motions of Figure 21 (RemoteMotion.cpp) run against a simulated Puma in another process
// (ros2_arm, Ros2Arm.cpp) by changing only rp.cfg; a remote arm that vanishes mid-motion ends the
// program with a shutdown naming it; a refusal by the remote bridge becomes the local error; the
// settings' errors; latency and loss reported. Every program run here has its exit status checked.
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <fstream>
#include <sstream>
#include <thread>

#include "../support/RunProgram.hpp"
#include "ChildProcess.hpp"
#include "CountingHold.hpp"
#include "AllocationCounter.hpp"
#include "../support/ScratchDirectory.hpp"
#include "Ros2Fixture.hpp"
#include "rp/model/Kinematics.hpp"
#include "rp/model/ManipulatorData.hpp"
#include "rp/model/Puma560Model.hpp"
#include "rp/model/UrdfExport.hpp"
#include "sensor_msgs.h"
#include "std_msgs.h"

namespace rp::test {
namespace {

class RemoteManipulatorTest : public Ros2Fixture {
 protected:
  void SetUp() override {
    Ros2Fixture::SetUp();
    ns_ = options_.nameSpace + "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name();
  }
  // The remote arm: ros2_arm with commands (`commands`) and the stop file.
  std::unique_ptr<Child> startArm(bool commands = true) {
    std::vector<std::string> args{RP_ROS2_ARM_PATH, std::to_string(options_.domain), ns_, "lo", "120"};
    if (commands) {
      args.push_back("commands");
      args.push_back(stopFile());
    }
    auto arm = std::make_unique<Child>(args);
    EXPECT_EQ(arm->line(), "ready");
    return arm;
  }
  std::string stopFile() const { return (dir_ / "stop").string(); }
  // Stops the arm (the stop file), checks its exit status and returns its final joint positions.
  std::vector<double> stopArm(Child& arm) {
    std::ofstream(stopFile()) << "stop\n";
    std::string out;
    EXPECT_EQ(arm.finish(out), 0) << out;
    return numbersAfter(out, "final");
  }
  std::string writeConfig(const std::string& name, const std::string& text) {
    const std::string path = (dir_ / name).string();
    std::ofstream(path) << text;
    return path;
  }
  std::string remoteConfig(const std::string& extra = "") {
    return writeConfig("remote.cfg", "[leader]\nclass RemoteManipulator\nremote " + ns_ + "/puma\ndomain " +
                                         std::to_string(options_.domain) + "\nconnectTimeout 30\n" + extra);
  }
  Outcome run(const std::string& program, const std::string& config) {
    // `timeout`: a hang ends as status 124 (a failure) rather than blocking the suite.
    return runProgram("timeout -s KILL 120 " + program + " -config " + config + " -nogui", (dir_ / "run").string());
  }

  ScratchDirectory dir_{"rp_remote_test_", "scratch"};
  std::string ns_;
};

// Section 3.6 unchanged: the remote Puma's end-effector frame, as the local Puma's.
TEST_F(RemoteManipulatorTest, GenericManipulatorRunsAgainstAnArmInAnotherProcess) {
  const Outcome local = run(GENERIC_MANIPULATOR_PATH, writeConfig("local.cfg", "[leader]\nclass Puma560\n"));
  ASSERT_EQ(local.status, 0) << local.err;
  auto arm = startArm();
  const Outcome remote = run(GENERIC_MANIPULATOR_PATH, remoteConfig());
  EXPECT_EQ(remote.status, 0) << remote.out << remote.err;
  const std::vector<double> l = numbersAfter(local.out, "Frame:"), r = numbersAfter(remote.out, "Frame:");
  ASSERT_EQ(l.size(), 16u) << local.out;
  ASSERT_EQ(r.size(), 16u) << remote.out;
  // The same pose (the Puma's home, qr) by two models of the same arm (DH, and its URDF export
  // loaded back): to the 1e-4 the stream prints and the arm's sag under position control.
  for (std::size_t i = 0; i < 16; ++i) EXPECT_NEAR(r[i], l[i], 1e-3) << i << "\n" << remote.out;
  EXPECT_EQ(stopArm(*arm).size(), 6u);
}

// Figure 21's motions, generic, against the remote arm: it ends where the local arm ends.
TEST_F(RemoteManipulatorTest, FigureTwentyOneMotionsEndWhereTheLocalArmEnds) {
  const Outcome local = run(REMOTE_MOTION_PATH, writeConfig("local.cfg", "[leader]\nclass Puma560\n"));
  ASSERT_EQ(local.status, 0) << local.err;
  const std::vector<double> l = numbersAfter(local.out, "final");
  ASSERT_EQ(l.size(), 6u) << local.out;
  auto arm = startArm();
  const Outcome remote = run(REMOTE_MOTION_PATH, remoteConfig());
  EXPECT_EQ(remote.status, 0) << remote.out << remote.err;
  const std::vector<double> r = stopArm(*arm);
  ASSERT_EQ(r.size(), 6u);
  // Both arms follow the same planned motion to the same end-effector pose and come to rest there
  // under position control. Their joint positions may differ by a wrist flip (joints 4 and 6 by pi,
  // joint 5 in sign: the same pose), as the remote model (the URDF export loaded back) has a
  // numeric inverse kinematics where the local Puma560 has the closed-form branches; so the final
  // poses are compared, by the Puma's own model: 2 mm and 5e-3 (rotation matrix entries) allow the
  // settling error of each arm's servo after its last setpoint, and the numeric IK's tolerance.
  Puma560Model puma;
  ManipulatorData data(puma);
  JointVector lq(6), rq(6);
  for (int i = 0; i < 6; ++i) {
    lq(i) = l[static_cast<std::size_t>(i)];
    rq(i) = r[static_cast<std::size_t>(i)];
  }
  const Transform lt = forwardKinematics(puma, data, lq);
  const Transform rt = forwardKinematics(puma, data, rq);
  for (int row = 0; row < 3; ++row) {
    EXPECT_NEAR(rt(row, 3), lt(row, 3), 2e-3) << "position " << row << "\n" << remote.err;
    for (int col = 0; col < 3; ++col) EXPECT_NEAR(rt(row, col), lt(row, col), 5e-3) << row << "," << col;
  }
  for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(r[i], l[i], 5e-3) << "joint " << i + 1;  // the arm's joints: no flip there
  // What the program read back over DDS agrees with the arm's own final reading.
  const std::vector<double> seen = numbersAfter(remote.out, "final");
  ASSERT_EQ(seen.size(), 6u) << remote.out;
  for (std::size_t i = 0; i < 6; ++i) EXPECT_NEAR(seen[i], r[i], 1e-3) << i;
}

// The remote arm's process killed mid-motion: the program ends with the shutdown status, naming
// the remote arm, instead of waiting for ever.
TEST_F(RemoteManipulatorTest, AVanishedRemoteArmEndsTheProgramWithAnError) {
  auto arm = startArm();
  const pid_t pid = arm->pid;
  const std::string out = (dir_ / "run.out").string();  // runProgram's file, read while it runs
  std::thread killer([pid, out] {
    // Once the program moves the arm (connected, the first motion queued), 1 s into the motion
    // (it lasts several seconds); after 300 s regardless.
    for (int k = 0; k < 30000 && slurp(out).find("moving") == std::string::npos; ++k)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    std::this_thread::sleep_for(std::chrono::seconds(1));
    kill(pid, SIGKILL);
  });
  const Outcome remote = run(REMOTE_MOTION_PATH, remoteConfig());
  killer.join();
  EXPECT_EQ(remote.status, RoboticPlatform::kExitAfterShutdown) << remote.out << remote.err;
  EXPECT_TRUE(contains(remote.err, "no joint_states from " + ns_ + "/puma")) << remote.err;
  EXPECT_TRUE(contains(remote.out, "moving")) << remote.out;
  EXPECT_FALSE(contains(remote.out, "final")) << remote.out;
}

// The loop makes no DDS call and does not allocate (the reader and writer threads do the DDS
// work), while joint states keep coming in and a trajectory goes out each cycle.
TEST_F(RemoteManipulatorTest, TheStreamingCycleDoesNotAllocate) {
  auto arm = startArm();
  RemoteManipulatorOptions o;
  o.remote = ns_ + "/puma";
  o.domain = options_.domain;
  o.connectTimeout = 30;
  RemoteManipulator m("leader", o);
  ASSERT_TRUE(m.isArmPowerOn());
  JointVector q = m.getJointPosition();
  q(1) += 0.01;  // a small step, held
  CountingHold hold(q);
  m.setTrajectoryGenerator(hold);
  const RemoteManipulatorStatistics before = m.getStatistics();
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (hold.calls.load() < 200 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  ASSERT_GE(hold.calls.load(), 200);
  EXPECT_EQ(hold.allocations.load(), 0u) << "over " << hold.calls.load() << " cycles";
  const RemoteManipulatorStatistics after = m.getStatistics();
  EXPECT_GT(after.samples, before.samples + 50) << "joint states came in meanwhile";
  EXPECT_GT(after.trajectoriesSent, before.trajectoriesSent + 150) << "a trajectory went out each cycle";
  EXPECT_EQ(m.getDesiredJointPosition(), q);
  EXPECT_EQ(m.getErrorCode(), 0) << m.getErrorStatus().message;
  m.clearTrajectoryGenerator();
  stopArm(*arm);
}

// In this process, from code: the figures of the link, and the remote bridge's refusal (commands
// off) as this object's error; waits end.
TEST_F(RemoteManipulatorTest, ReportsLatencyLossAndTheRemoteRefusal) {
  auto arm = startArm(false);
  RemoteManipulatorOptions o;
  o.remote = ns_ + "/puma";
  o.domain = options_.domain;
  o.connectTimeout = 30;
  RemoteManipulator m("leader", o);
  EXPECT_EQ(m.getNumberOfJoints(), 6);
  EXPECT_TRUE(m.isArmPowerOn());
  EXPECT_EQ(m.getModel().getJointName(0).rfind("puma_", 0), 0u) << m.getModel().getJointName(0);
  // Holding where the remote arm was when it connected (its simulation settles by far less).
  EXPECT_LT((m.getDesiredJointPosition() - m.getJointPosition()).norm(), 1e-3);
  EXPECT_GT(m.getDesiredJointPosition().norm(), 0.1) << "the arm's position, not zeros";
  DefaultTrajectoryGenerator<6> tragen;
  m.setTrajectoryGenerator(tragen);
  JointVector target = m.getJointPosition();
  target(0) += 0.2;
  tragen.moveRadians(target);
  EXPECT_FALSE(tragen.waitUntilDone(60));  // ended by the fault, not by a time-out
  EXPECT_TRUE(ObjectManager::isShutdownRequested());
  const std::string error = m.getErrorStatus().message;
  EXPECT_TRUE(contains(error, "refused the trajectory")) << error;
  EXPECT_TRUE(contains(error, "commands are off")) << error;
  const RemoteManipulatorStatistics s = m.getStatistics();
  EXPECT_GT(s.samples, 0u);
  EXPECT_GT(s.trajectoriesSent, 0u);
  EXPECT_GE(s.remoteRefusals, 1u);
  EXPECT_GT(s.period, 0);
  EXPECT_TRUE(std::isfinite(s.latencyMedian) && std::isfinite(s.latencyP99));
  EXPECT_LE(s.latencyMedian, s.latencyP99);
  std::printf("remote link: %llu samples, period %.4f s, %llu gaps (%llu lost), latency median %.3f ms, p99 %.3f ms\n",
              static_cast<unsigned long long>(s.samples), s.period, static_cast<unsigned long long>(s.gaps),
              static_cast<unsigned long long>(s.missing), 1e3 * s.latencyMedian, 1e3 * s.latencyP99);
  m.clearTrajectoryGenerator();
}

// A remote arm faked here (its description, state and joint_states written by this test) whose
// joint_states carry a position that is not a number. Such a sample is no state of an arm: it is
// never taken (it used to become the arm's position, the start of the next motion). While
// connecting, it is the constructor's error; once connected, a fault that shuts the system down;
// both name the joint. A velocity or effort that is not a number is one the publisher does not
// have (ros2_control's joint_state_broadcaster writes NaN for those): taken as absent, 0.
TEST_F(RemoteManipulatorTest, AJointStateThatIsNotANumberIsRefusedNamingTheJoint) {
  const std::string wire = "rt/" + ns_ + "/";
  const dds_entity_t description = topicWriter(std_msgs_msg_dds__String__desc, wire + "arm/robot_description", true);
  const dds_entity_t state = topicWriter(std_msgs_msg_dds__String__desc, wire + "arm/state");
  const dds_entity_t joints = topicWriter(sensor_msgs_msg_dds__JointState__desc, wire + "joint_states");
  const std::string urdf = toUrdf(Puma560Model());
  std_msgs_msg_dds__String_ d{};
  d.data = const_cast<char*>(urdf.c_str());
  ASSERT_EQ(dds_write(description, &d), 0);

  // The fake arm: at home, powered, every 2 ms; `bad` puts a NaN into joint 2's field `field`
  // (0 position, 1 velocity, 2 effort) or nowhere (-1).
  std::atomic<int> bad{-1};
  std::atomic<bool> stop{false};
  std::thread remote([&] {
    const Puma560Model puma;
    std::vector<std::string> names;
    for (int i = 0; i < 6; ++i) names.push_back("arm_joint" + std::to_string(i + 1));
    std::vector<char*> namePointers;
    for (std::string& n : names) namePointers.push_back(n.data());
    std_msgs_msg_dds__String_ s{};
    s.data = const_cast<char*>(R"({"power":true,"errorCode":0,"shutdown":false,"trajectoriesRefused":0})");
    while (!stop.load()) {
      double q[6], qd[6] = {0, 0, 0, 0, 0, 0}, tau[6] = {0, 0, 0, 0, 0, 0};
      for (int i = 0; i < 6; ++i) q[i] = puma.getHomePosition()(i);
      double* fields[3] = {q, qd, tau};
      if (const int f = bad.load(); f >= 0) fields[f][1] = std::nan("");
      const std::int64_t now =
          std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
      sensor_msgs_msg_dds__JointState_ js{};
      js.header.stamp.sec = static_cast<int32_t>(now / 1000000000);
      js.header.stamp.nanosec = static_cast<uint32_t>(now % 1000000000);
      js.header.frame_id = const_cast<char*>("");
      js.name = {6, 6, namePointers.data(), false};
      js.position = {6, 6, q, false};
      js.velocity = {6, 6, qd, false};
      js.effort = {6, 6, tau, false};
      dds_write(joints, &js);
      dds_write(state, &s);
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  });
  StopAndJoin join{stop, remote};
  configure("[leader]\nclass RemoteManipulator\nremote " + ns_ + "/arm\ndomain " + std::to_string(options_.domain) +
            "\nconnectTimeout 30\n");

  bad = 0;  // from the start: the constructor refuses the arm
  try {
    RemoteManipulator m("leader");
    ADD_FAILURE() << "connected to an arm whose position is not a number";
  } catch (const std::exception& e) {
    EXPECT_TRUE(contains(e.what(), "sent joint_states with position of joint 'arm_joint2' nan: not a finite number"))
        << e.what();
  }

  bad = 1;  // connected, velocity not a number (not given): taken as 0, no fault
  RemoteManipulator m("leader");
  ASSERT_EQ(m.getErrorCode(), 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_FALSE(ObjectManager::isShutdownRequested()) << ObjectManager::getShutdownReason();
  EXPECT_TRUE(m.getJointVelocity().allFinite());
  EXPECT_EQ(m.getJointVelocity()(1), 0.0);
  const JointVector before = m.getJointPosition();
  bad = 0;  // then a position that is not a number: a fault
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (!ObjectManager::isShutdownRequested() && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  EXPECT_TRUE(ObjectManager::isShutdownRequested());
  EXPECT_NE(m.getErrorCode(), 0);
  EXPECT_TRUE(contains(m.getErrorStatus().message, "sent joint_states with position of joint 'arm_joint2' nan"))
      << m.getErrorStatus().message;
  EXPECT_TRUE(m.getJointPosition().allFinite()) << "the refused sample was taken";
  EXPECT_LT((m.getJointPosition() - before).cwiseAbs().maxCoeff(), 1e-12);
}

TEST_F(RemoteManipulatorTest, SettingsErrorsNameTheFileAndLine) {
  configure("[leader]\nclass RemoteManipulator\ndomain 3\n");
  try {
    RemoteManipulator m("leader");
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_TRUE(contains(e.what(), "test.cfg")) << e.what();
    EXPECT_TRUE(contains(e.what(), "remote NS/OBJECT")) << e.what();
  }
  configure("[leader]\nclass RemoteManipulator\nremote a//b\n");
  try {
    RemoteManipulator m("leader");
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_TRUE(contains(e.what(), "test.cfg:3")) << e.what();
    EXPECT_TRUE(contains(e.what(), "is not NS/OBJECT")) << e.what();
  }
  // Nobody there: the description is waited for a bounded time, and the error names its topic.
  configure("[leader]\nclass RemoteManipulator\nremote " + ns_ + "/nobody\ndomain " + std::to_string(options_.domain) +
            "\nconnectTimeout 0.3\n");
  try {
    RemoteManipulator m("leader");
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_TRUE(contains(e.what(), "test.cfg:3")) << e.what();
    EXPECT_TRUE(contains(e.what(), "rt/" + ns_ + "/nobody/robot_description")) << e.what();
  }
}

}  // namespace
}  // namespace rp::test
