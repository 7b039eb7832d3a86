// Ros2IoBoard: the paper's Figure 21 (examples/pick_and_place, which declares `Puma560 puma;`) runs
// unchanged against a Puma in another process (ros2_arm: its Ros2Bridge at the servo rate with
// commands on), driven by torque over DDS, by changing only rp.cfg. Every exit path is checked
// against the remote arm, not against this side's flags: the program killed (the arm holds), the
// remote arm gone, its bridge refusing, a bridge too slow for a torque loop; the servo cycle's
// allocations; the settings' errors. Every program run here has its exit status checked.
#include <signal.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <fstream>
#include <thread>

#include "../support/RunProgram.hpp"
#include "../support/ScratchDirectory.hpp"
#include "ChildProcess.hpp"
#include "CountingHold.hpp"
#include "Ros2Fixture.hpp"
#include "rp/model/Kinematics.hpp"
#include "rp/model/ManipulatorData.hpp"
#include "rp/model/Puma560Model.hpp"
#include "rp/ros2/Ros2IoBoard.hpp"
#include "sensor_msgs.h"
#include "std_msgs.h"

namespace rp::test {
namespace {

class Ros2IoBoardTest : public Ros2Fixture {
 protected:
  void SetUp() override {
    Ros2Fixture::SetUp();
    ns_ = options_.nameSpace + "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name();
    options_.nameSpace = ns_;  // the fixture's readers: the remote arm's topics
  }
  void TearDown() override {
    Ros2Fixture::TearDown();  // the participant first
    if (domain_ > 0) dds_delete(domain_);
  }
  // The remote arm: ros2_arm with its bridge's commands `on` or off, at `rate` (servo or Hz).
  std::unique_ptr<Child> startArm(bool commands = true, const std::string& rate = "servo") {
    auto arm = std::make_unique<Child>(std::vector<std::string>{RP_ROS2_ARM_PATH, std::to_string(options_.domain), ns_, "lo", "120",
                                                                commands ? "commands" : "nocommands", stopFile(), rate});
    EXPECT_EQ(arm->line(), "ready");
    return arm;
  }
  std::string stopFile() const { return (dir_ / "stop").string(); }
  // Stops the arm (the stop file) and returns its output; checks its exit status.
  std::string stopArm(Child& arm) {
    std::ofstream(stopFile()) << "stop\n";
    std::string out;
    EXPECT_EQ(arm.finish(out), 0) << out;
    return out;
  }
  std::string writeConfig(const std::string& name, const std::string& text) {
    const std::string path = (dir_ / name).string();
    std::ofstream(path) << text;
    return path;
  }
  // Figure 21's unnamed Puma560 (its class section) wired to the remote arm.
  std::string remoteConfig(const std::string& extra = "") {
    return writeConfig("remote.cfg", "[Puma560]\nclass Puma560\nsimulationMode off\nremote " + ns_ + "/puma\ndomain " +
                                         std::to_string(options_.domain) + "\nconnectTimeout 30\n" + extra);
  }
  Outcome run(const std::string& config) {
    // `timeout`: a hang ends as status 124 (a failure) rather than blocking the suite.
    return runProgram("timeout -s KILL 120 " + std::string(PICK_AND_PLACE_PATH) + " -config " + config + " -nogui",
                      (dir_ / "run").string());
  }
  // A reader of the remote arm's `topic`, in this process's domain on loopback as ros2_arm's bridge
  // has it (Cyclone's default interface may not be lo).
  dds_entity_t reader(const dds_topic_descriptor_t& desc, const std::string& topic) {
    if (domain_ == 0) {
      domain_ = dds_create_domain(static_cast<dds_domainid_t>(options_.domain), Ros2Bridge::cycloneConfig({"lo"}).c_str());
      EXPECT_GT(domain_, 0);
    }
    return Ros2Fixture::reader(desc, topic);
  }
  // Waits (at most `seconds`) for a joint_states sample of the remote arm for which `accept` holds.
  bool waitForJoints(const std::function<bool(const JointVector& q, const JointVector& qd)>& accept, double seconds) {
    if (jointStates_ == 0) jointStates_ = reader(sensor_msgs_msg_dds__JointState__desc, "joint_states");
    return takeUntil<sensor_msgs_msg_dds__JointState_>(
        jointStates_,
        [&](const sensor_msgs_msg_dds__JointState_& js) {
          if (js.position._length != 6 || js.velocity._length != 6) return false;
          JointVector q(6), qd(6);
          for (int i = 0; i < 6; ++i) {
            q(i) = js.position._buffer[i];
            qd(i) = js.velocity._buffer[i];
          }
          return accept(q, qd);
        },
        seconds);
  }

  // The remote run's outcome is the local run's: the program's exit status, and the task's outcome
  // as the simulated arm's.
  void expectTheLocalOutcome(const Outcome& local, const Outcome& remote, const std::string& armOut) {
    EXPECT_FALSE(contains(armOut, "error")) << armOut;
    EXPECT_EQ(remote.status, 0) << remote.out << remote.err;
    const std::vector<double> q = numbersAfter(armOut, "final");
    ASSERT_EQ(q.size(), 6u) << "the remote arm did not come to rest:\n" << armOut;

    // The end-effector and the work piece where the program left them, to the settling of two servo
    // loops (the remote one has up to two cycles of delay) and the piece's fall (it bounces on the
    // table).
    const std::vector<double> le = numbersAfter(local.out, "end-effector at"), re = numbersAfter(remote.out, "end-effector at");
    const std::vector<double> lp = numbersAfter(local.out, "work piece at"), rpiece = numbersAfter(remote.out, "work piece at");
    ASSERT_EQ(le.size(), 3u) << local.out;
    ASSERT_EQ(re.size(), 3u) << remote.out;
    ASSERT_EQ(rpiece.size(), 3u) << remote.out;
    for (std::size_t i = 0; i < 3; ++i) {
      EXPECT_NEAR(re[i], le[i], 2e-3) << "end-effector " << i << "\n" << remote.out;
      EXPECT_NEAR(rpiece[i], lp[i], 5e-3) << "work piece " << i << "\n" << remote.out;
    }
    // The remote arm is really there: its own final joints, through the Puma's model, put the
    // end-effector where the program read it over DDS.
    Puma560Model puma;
    ManipulatorData data(puma);
    JointVector rq(6);
    for (int i = 0; i < 6; ++i) rq(i) = q[static_cast<std::size_t>(i)];
    const Transform t = forwardKinematics(puma, data, rq);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(t(i, 3), re[static_cast<std::size_t>(i)], 1e-3) << i << "\n" << armOut;
    EXPECT_NEAR(t(2, 2), -1, 1e-3) << "the gripper points down";
  }

  // A writer of `topic` in the remote arm's namespace, as its bridge's.
  dds_entity_t writer(const dds_topic_descriptor_t& desc, const std::string& topic) {
    const std::string name = "rt/" + ns_ + "/" + topic;
    const dds_entity_t t = dds_create_topic(participant_, &desc, name.c_str(), nullptr, nullptr);
    dds_qos_t* qos = dds_create_qos();
    dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    const dds_entity_t w = dds_create_writer(participant_, t, qos, nullptr);
    dds_delete_qos(qos);
    EXPECT_GT(w, 0) << name;
    return w;
  }
  // A joint_states sample of the remote arm `arm` with its one joint `joint1` at q [rad], stamped
  // `stamp` [ns since the epoch].
  static void writeJoint(dds_entity_t joints, std::int64_t stamp, double q) {
    sensor_msgs_msg_dds__JointState_ js{};
    js.header.stamp.sec = static_cast<int32_t>(stamp / 1000000000);
    js.header.stamp.nanosec = static_cast<uint32_t>(stamp % 1000000000);
    js.header.frame_id = const_cast<char*>("");
    char name[] = "arm_joint1";
    char* names[] = {name};
    double position[] = {q}, zero[] = {0.0};
    js.name = {1, 1, names, false};
    js.position = {1, 1, position, false};
    js.velocity = {1, 1, zero, false};
    js.effort = {1, 1, zero, false};
    dds_write(joints, &js);
  }
  // The remote arm's state: powered, no fault.
  static void writePowerOn(dds_entity_t state) {
    std_msgs_msg_dds__String_ s{};
    s.data = const_cast<char*>(R"({"power":true,"errorCode":0,"shutdown":false,"effortsRefused":0})");
    dds_write(state, &s);
  }

  ScratchDirectory dir_{"rp_ros2_board_test_", "scratch"};
  std::string ns_;
  dds_entity_t domain_ = 0, jointStates_ = 0;
};

// Figure 21 unchanged: the remote arm does the task, driven by the program's own servo loop.
TEST_F(Ros2IoBoardTest, PickAndPlaceRunsUnchangedAgainstAnArmInAnotherProcess) {
  const Outcome local = run(writeConfig("local.cfg", "[Puma560]\nclass Puma560\n"));
  ASSERT_EQ(local.status, 0) << local.err;
  auto arm = startArm();
  const Outcome remote = run(remoteConfig());
  const std::string armOut = stopArm(*arm);
  expectTheLocalOutcome(local, remote, armOut);
}

// The same while the arm's process stalls for 3 ms every 100 ms, as a busy machine stalls it: the
// late cycles of its servo loop and the cycles after them catch up, and the joint states they
// publish are stamped with the times their joints hold for. (Stamped with when the late cycles
// ran, they made the program read joint 2 at 2.0-2.3 rad/s while it moved at 1.6, and stop at the
// 2 rad/s limit, in 6 of 7 runs.)
TEST_F(Ros2IoBoardTest, PickAndPlaceRunsUnchangedWhileTheArmsProcessStalls) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  // Not in a sanitizer build: there both processes' servo loops already miss about one cycle in
  // ten without the stalls (the project's CI saw 335 missed cycles of the arm's 2,622 and 195 of
  // the program's 1,690, and the arm stopping at joint 2's velocity limit: an overloaded torque
  // loop's safe stop, not a stamping error). The release build runs this test in CI.
  GTEST_SKIP() << "a sanitizer build is itself a larger stall than this test's; the release build runs it";
#endif
  const Outcome local = run(writeConfig("local.cfg", "[Puma560]\nclass Puma560\n"));
  ASSERT_EQ(local.status, 0) << local.err;
  auto arm = startArm();
  std::atomic<bool> done{false};
  std::atomic<int> stalls{0};
  std::thread stall([&] {
    while (!done.load()) {
      const auto start = std::chrono::steady_clock::now();
      if (kill(arm->pid, SIGSTOP) != 0) break;
      while (std::chrono::steady_clock::now() - start < std::chrono::milliseconds(3)) {
      }
      kill(arm->pid, SIGCONT);
      ++stalls;
      std::this_thread::sleep_for(std::chrono::milliseconds(97));
    }
  });
  const Outcome remote = run(remoteConfig());
  done.store(true);
  stall.join();
  const std::string armOut = stopArm(*arm);
  EXPECT_GT(stalls.load(), 50) << "the arm's process was stalled";
  expectTheLocalOutcome(local, remote, armOut);
}

// SIGKILL mid-motion: no more effort commands, and the remote bridge holds the arm where it is.
TEST_F(Ros2IoBoardTest, KillingTheProgramLeavesTheRemoteArmHolding) {
  auto arm = startArm();
  Child program({PICK_AND_PLACE_PATH, "-config", remoteConfig(), "-nogui"});
  // The remote arm moving fast, under the program's torques.
  ASSERT_TRUE(waitForJoints([](const JointVector&, const JointVector& qd) { return qd.cwiseAbs().maxCoeff() > 0.2; }, 60))
      << "the remote arm never moved";
  kill(program.pid, SIGKILL);
  std::string out;
  EXPECT_EQ(program.finish(out), -1) << out;
  // Held within a fraction of a second (effortTimeout 0.02 s, then the hold's braking); then
  // still, 0.5 s later at the same place: held, not falling.
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  JointVector held;
  ASSERT_TRUE(waitForJoints(
      [&](const JointVector& q, const JointVector& qd) {
        held = q;
        return qd.cwiseAbs().maxCoeff() < 1e-3;
      },
      5))
      << "the remote arm did not stop";
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  ASSERT_TRUE(waitForJoints([&](const JointVector& q, const JointVector&) { return (q - held).cwiseAbs().maxCoeff() < 1e-3; }, 1))
      << "the remote arm moved on";
  const std::string armOut = stopArm(*arm);
  EXPECT_FALSE(contains(armOut, "error")) << armOut;
  EXPECT_TRUE(contains(armOut, "final")) << armOut;
}

// The remote arm's process killed mid-motion: the program shuts down, naming it.
TEST_F(Ros2IoBoardTest, AVanishedRemoteArmShutsTheProgramDown) {
  auto arm = startArm();
  Child program({PICK_AND_PLACE_PATH, "-config", remoteConfig(), "-nogui"});
  ASSERT_TRUE(waitForJoints([](const JointVector&, const JointVector& qd) { return qd.cwiseAbs().maxCoeff() > 0.2; }, 60));
  kill(arm->pid, SIGKILL);
  std::string out;
  EXPECT_EQ(program.finish(out), RoboticPlatform::kExitAfterShutdown) << out;
  EXPECT_TRUE(contains(out, "no joint_states from " + ns_ + "/puma")) << out;
  EXPECT_TRUE(contains(out, "stopped by a system shutdown")) << out;
}

// The remote bridge refuses the effort commands (its commands are off): a shutdown naming why.
TEST_F(Ros2IoBoardTest, TheRemoteBridgesRefusalShutsTheProgramDown) {
  auto arm = startArm(false);
  const Outcome r = run(remoteConfig());
  EXPECT_EQ(r.status, RoboticPlatform::kExitAfterShutdown) << r.out << r.err;
  EXPECT_TRUE(contains(r.err, "the remote arm " + ns_ + "/puma refused the effort commands: commands are off")) << r.err;
  const std::string armOut = stopArm(*arm);
  EXPECT_FALSE(contains(armOut, "error")) << armOut;
  EXPECT_TRUE(contains(armOut, "final")) << "the remote arm held still:\n" << armOut;
}

// A remote bridge publishing at 100 Hz cannot carry a torque loop: refused at construction,
// naming the setting's line and the remedy.
TEST_F(Ros2IoBoardTest, ABridgeSlowerThanTheServoRateIsRefused) {
  auto arm = startArm(true, "100");
  const Outcome r = run(remoteConfig());
  EXPECT_EQ(r.status, 1) << r.out << r.err;
  EXPECT_TRUE(contains(r.err, "remote.cfg:4: setting 'remote " + ns_ + "/puma'")) << r.err;
  EXPECT_TRUE(contains(r.err, "rate servo")) << r.err;
  stopArm(*arm);
}

// In this process: the servo cycle of an arm on the board makes no DDS call and does not allocate,
// while joint states come in and an effort command goes out each cycle.
TEST_F(Ros2IoBoardTest, TheServoCycleDoesNotAllocate) {
  auto arm = startArm();
  // The readers first: their domain (on loopback) is then this test's, not the arm's board's,
  // which would delete it when the arm goes.
  const dds_entity_t state = reader(std_msgs_msg_dds__String__desc, "puma/state");
  jointStates_ = reader(sensor_msgs_msg_dds__JointState__desc, "joint_states");
  RoboticPlatform::setSimulationModeOff();
  configure("[leader]\nclass Puma560\nsimulationMode off\nremote " + ns_ + "/puma\ndomain " + std::to_string(options_.domain) +
            "\nconnectTimeout 30\n");
  {
    Puma560 puma("leader");
    ASSERT_TRUE(puma.usesHardware());
    puma.enableArmPower();
    CountingHold hold(puma.getJointPosition());
    puma.setTrajectoryGenerator(hold);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (hold.calls.load() < 500 && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    ASSERT_GE(hold.calls.load(), 500);
    EXPECT_EQ(hold.allocations.load(), 0u) << "over " << hold.calls.load() << " cycles";
    // Meanwhile the cycles' torques drove the remote arm (its bridge says so).
    EXPECT_TRUE(takeUntil<std_msgs_msg_dds__String_>(
        state, [](const std_msgs_msg_dds__String_& s) { return contains(s.data, "\"effortDriving\":true"); }, 5));
    EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
    puma.clearTrajectoryGenerator();
  }
  ASSERT_TRUE(waitForJoints([](const JointVector&, const JointVector& qd) { return qd.cwiseAbs().maxCoeff() < 1e-3; }, 5));
  const std::string armOut = stopArm(*arm);
  EXPECT_FALSE(contains(armOut, "error")) << armOut;
}

// The board alone against this test as the remote arm (a one-joint arm "arm" published by plain
// DDS writers): the encoder is the published position; the torque of one volt goes out on
// arm/effort_commands each cycle; when the samples stop, the torques stop at once (one empty
// command: the remote bridge holds the arm) and come back with the samples; after `timeout` the
// reads fail naming the arm; the amplifiers switched off send one empty command.
TEST_F(Ros2IoBoardTest, TheBoardSendsTorquesOnlyWhileItsSamplesAreFresh) {
  const dds_entity_t efforts = reader(std_msgs_msg_dds__Float64MultiArray__desc, "arm/effort_commands");
  const dds_entity_t joints = writer(sensor_msgs_msg_dds__JointState__desc, "joint_states");
  const dds_entity_t state = writer(std_msgs_msg_dds__String__desc, "arm/state");
  std::atomic<bool> publishing{true}, stop{false};
  std::thread remote([&] {  // the remote arm at 1 kHz: joint1 at 0.5 rad; its state each 50 ms
    int k = 0;
    while (!stop.load()) {
      if (publishing.load())
        writeJoint(joints, std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count(), 0.5);
      if (k++ % 50 == 0) writePowerOn(state);
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  });
  StopAndJoin join{stop, remote};
  // The lengths of the effort commands received since the last call, in order.
  auto received = [&] {
    std::vector<uint32_t> lengths;
    for (;;) {
      void* samples[1] = {nullptr};
      dds_sample_info_t info[1];
      if (dds_take(efforts, samples, info, 1, 1) <= 0) break;
      const auto& m = *static_cast<const std_msgs_msg_dds__Float64MultiArray_*>(samples[0]);
      if (info[0].valid_data) {
        lengths.push_back(m.data._length);
        if (m.data._length == 1) {
          EXPECT_DOUBLE_EQ(m.data._buffer[0], 3.0);
        }
      }
      dds_return_loan(efforts, samples, 1);
    }
    return lengths;
  };
  auto cycles = [](Ros2IoBoard& board, int count, bool on) {  // a servo loop's outputs, 1 ms apart
    for (int k = 0; k < count; ++k) {
      board.writeAnalogOutput(0, 1.5);  // 2 N m per volt: 3 N m
      board.writeDigitalOutput(0, on);
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  };

  Ros2IoBoardOptions o;
  o.remote = ns_ + "/arm";
  o.domain = options_.domain;
  o.connectTimeout = 30;
  Ros2IoBoard board(o, {"joint1"}, {2.0});
  std::int64_t counts = 0;
  ASSERT_EQ(board.readEncoder(0, counts), IoStatus::kOk) << board.lastError();
  EXPECT_EQ(counts, 500000000);  // 0.5 rad at 1e9 counts a radian
  EXPECT_GT(board.inputSampleTime(), 0);

  cycles(board, 100, true);
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  std::vector<uint32_t> got = received();
  // (Without a servo loop's cycle-end signal the writer wakes each 10 ms, and writes the latest.)
  EXPECT_GE(std::count(got.begin(), got.end(), 1u), 5) << "torques while on";
  EXPECT_EQ(std::count(got.begin(), got.end(), 0u), 0);

  publishing = false;  // the samples stop: within 10 ms one empty command, then nothing
  std::this_thread::sleep_for(std::chrono::milliseconds(30));
  cycles(board, 40, true);
  bool on = false;
  EXPECT_EQ(board.readDigitalOutput(0, on), IoStatus::kOk);
  EXPECT_TRUE(on) << "the amplifiers stay on as written";
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  got = received();
  ASSERT_FALSE(got.empty());
  EXPECT_EQ(got.back(), 0u) << "the last command lets go";
  EXPECT_EQ(std::count(got.begin(), got.end(), 0u), 1);
  EXPECT_EQ(board.readEncoder(0, counts), IoStatus::kTimeout) << "no sample for over 0.1 s";
  EXPECT_TRUE(contains(board.lastError(), "no joint_states from " + ns_ + "/arm")) << board.lastError();

  publishing = true;  // the samples again: torques again
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  cycles(board, 50, true);
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  got = received();
  EXPECT_GE(std::count(got.begin(), got.end(), 1u), 3);
  EXPECT_EQ(board.readEncoder(0, counts), IoStatus::kOk) << board.lastError();

  cycles(board, 20, false);  // the amplifiers off: one empty command, then nothing
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  got = received();
  ASSERT_FALSE(got.empty());
  EXPECT_EQ(got.back(), 0u);
  EXPECT_EQ(std::count(got.begin(), got.end(), 0u), 1);
  const Ros2IoBoardStatistics st = board.getStatistics();
  EXPECT_GT(st.samples, 100u);
  EXPECT_EQ(st.writeFailures, 0u);
}

// A sample that comes again under the same stamp (a bridge publishing an arm's hardware sample
// that its server has not renewed yet) is the same sample: no new sample for the servo loop
// (DefaultManipulator keeps position and velocity), and the next new sample's time step is the
// whole time since the last. (Before, a repeated stamp counted as one cycle later: the joints
// read as standing still for a cycle, then moving twice as fast.) Sample times are on this
// machine's CLOCK_MONOTONIC, as IoBoard::inputSampleTime() says (they were the remote's stamps).
TEST_F(Ros2IoBoardTest, ASampleRepeatedUnderItsStampIsOneSample) {
  (void)reader(std_msgs_msg_dds__Float64MultiArray__desc, "arm/effort_commands");  // the domain on loopback, as the board's
  const dds_entity_t joints = writer(sensor_msgs_msg_dds__JointState__desc, "joint_states");
  const dds_entity_t state = writer(std_msgs_msg_dds__String__desc, "arm/state");
  const std::int64_t t0 = std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
  std::atomic<bool> stop{false};
  std::atomic<std::int64_t> last{t0};
  std::thread remote([&] {  // until the board is connected: samples 1 ms apart, and the state
    for (int k = 1; !stop.load(); ++k) {
      writeJoint(joints, t0 + k * 1000000, 0.5);
      last = t0 + k * 1000000;
      if (k % 50 == 1) writePowerOn(state);
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  });
  Ros2IoBoardOptions o;
  o.remote = ns_ + "/arm";
  o.domain = options_.domain;
  o.connectTimeout = 30;
  o.timeout = 5;  // (a loaded machine's pauses between the samples below are no fault)
  std::unique_ptr<Ros2IoBoard> board;
  {
    StopAndJoin join{stop, remote};  // (a throwing constructor too)
    board = std::make_unique<Ros2IoBoard>(o, std::vector<std::string>{"joint1"}, std::vector<double>{2.0});
  }
  std::uint64_t samplesBefore = board->getStatistics().samples;  // once the last of those is in
  for (int i = 0; i < 100; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    const std::uint64_t now = board->getStatistics().samples;
    if (now == samplesBefore) break;
    samplesBefore = now;
  }
  // One sample at a time, each waited for.
  auto send = [&](std::int64_t stamp, double q) {
    const std::uint64_t before = board->getStatistics().samples;
    writeJoint(joints, stamp, q);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
    while (board->getStatistics().samples == before && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    EXPECT_GT(board->getStatistics().samples, before) << "the sample stamped " << stamp << " did not come";
    std::int64_t counts = 0;
    EXPECT_EQ(board->readEncoder(0, counts), IoStatus::kOk) << board->lastError();
    return std::make_pair(board->inputSampleTime(), counts);
  };
  const std::int64_t s = last.load();
  const auto a = send(s + 1000000, 0.501);
  // On this machine's CLOCK_MONOTONIC (the IoBoard contract), near when it came.
  const std::int64_t now = std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
  EXPECT_LE(a.first, now);
  EXPECT_GT(a.first, now - 10000000000) << "not a time on this machine's monotonic clock";
  writeJoint(joints, s + 1000000, 0.501);   // the same sample again: not counted, no time of its own
  const auto c = send(s + 3000000, 0.503);  // two cycles on (it follows the repeat: one writer, in order)
  EXPECT_EQ(a.second, 501000000);
  // (The offset to this clock moves by at most 1 us a sample.)
  EXPECT_NEAR(c.first - a.first, 2000000, 1000) << "the step to the next new sample is not the time between their stamps";
  EXPECT_EQ(c.second, 503000000);
  EXPECT_EQ(board->getStatistics().samples - samplesBefore, 2u) << "the repeated sample counted as a new one";
}

// The sample times are this machine's CLOCK_MONOTONIC at the least delayed samples' receipt, not
// at the first sample's: a first sample that came 200 ms late (a resend after discovery, an old
// sample) does not put every later sample 200 ms in the future; nor does its gap to the next
// sample count as the remote's rate at the connection (the board refused such a remote: "its
// joint_states come every 10.2 ms").
TEST_F(Ros2IoBoardTest, ALateFirstSampleDoesNotShiftTheSampleTimes) {
  (void)reader(std_msgs_msg_dds__Float64MultiArray__desc, "arm/effort_commands");  // the domain on loopback, as the board's
  const dds_entity_t joints = writer(sensor_msgs_msg_dds__JointState__desc, "joint_states");
  const dds_entity_t state = writer(std_msgs_msg_dds__String__desc, "arm/state");
  auto wallNow = [] {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
  };
  std::atomic<bool> stop{false};
  std::thread remote([&] {  // once the board reads: samples stamped when written, the first 200 ms before
    dds_publication_matched_status_t matched{};
    while (!stop.load() && (dds_get_publication_matched_status(joints, &matched) != 0 || matched.current_count == 0)) {
      writePowerOn(state);
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    for (int k = 0; !stop.load(); ++k) {
      writeJoint(joints, wallNow() - (k == 0 ? 200000000 : 0), 0.5);
      if (k % 50 == 0) writePowerOn(state);
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  });
  StopAndJoin join{stop, remote};
  Ros2IoBoardOptions o;
  o.remote = ns_ + "/arm";
  o.domain = options_.domain;
  o.connectTimeout = 30;
  Ros2IoBoard board(o, {"joint1"}, {2.0});
  std::int64_t t = board.inputSampleTime();
  for (int i = 0; i < 1000 && t < 0; ++i) t = board.inputSampleTime();
  const std::int64_t now = std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
  EXPECT_LE(t, now + 1000000) << "the latest sample " << 1e-6 * static_cast<double>(t - now) << " ms in the future";
  EXPECT_GT(t, now - 100000000) << "the latest sample " << 1e-6 * static_cast<double>(now - t) << " ms old";
}

TEST_F(Ros2IoBoardTest, SettingsErrorsNameTheFileAndLine) {
  RoboticPlatform::setSimulationModeOff();
  auto expectError = [&](const std::string& cfg, const std::string& where, const std::string& what) {
    configure(cfg);
    try {
      Puma560 puma("leader");
      ADD_FAILURE() << "no error for\n" << cfg;
    } catch (const std::exception& e) {
      EXPECT_TRUE(contains(e.what(), where)) << e.what();
      EXPECT_TRUE(contains(e.what(), what)) << e.what();
    }
  };
  expectError("[leader]\nclass Puma560\nsimulationMode off\nremote a//b\n", "test.cfg:4", "is not NS/OBJECT");
  expectError("[leader]\nclass Puma560\nsimulationMode off\nremote cell/puma\nhwserver hw0\n", "test.cfg:5", "not both");
  // Nobody there: waited for a bounded time; the error names the topic.
  expectError("[leader]\nclass Puma560\nsimulationMode off\nremote " + ns_ + "/nobody\ndomain " + std::to_string(options_.domain) +
                  "\nconnectTimeout 0.3\n",
              "test.cfg:4", "rt/" + ns_ + "/joint_states");
  // Out of range: refused by the settings' schema at the setting's line.
  for (const char* line : {"timeout 0.001", "connectTimeout 0", "domain 231", "interfaces no$such"}) {
    try {
      configure(std::string("[leader]\nclass Puma560\nsimulationMode off\nremote cell/puma\n") + line + "\n");
      ObjectManager().createDerivedObject<Puma560>("leader");
      ADD_FAILURE() << line << " accepted";
    } catch (const ConfigError& e) {
      EXPECT_TRUE(contains(e.what(), "test.cfg:5")) << line << ": " << e.what();
    }
    ObjectManager().deleteAllObjects();
  }
  EXPECT_THROW(Ros2IoBoard(Ros2IoBoardOptions{}, {"joint1"}, {1.0}), std::invalid_argument);
}

}  // namespace
}  // namespace rp::test
