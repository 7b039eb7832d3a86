// Ros2Bridge's <object>/effort_commands (std_msgs/Float64MultiArray, as ros2_control's effort
// forward command controller sends): written by a plain Cyclone DDS writer generated from the same
// IDL, the torques drive a simulated Puma 560 exactly (its acceleration against the model's
// M(q)^-1, a second algorithm than the simulation's); when they stop the arm holds where it is;
// bad ones are refused with a message on <object>/state while the arm keeps holding; the servo
// cycle driven by them does not allocate.
#include <dds/dds.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include "AllocationCounter.hpp"
#include "Ros2Fixture.hpp"
#include "TrajectoryMessage.hpp"
#include "rp/RoboticPlatform.hpp"
#include "rp/model/Dynamics.hpp"
#include "rp/model/ManipulatorData.hpp"
#include "std_msgs.h"
#include "trajectory_msgs.h"

namespace rp {
namespace {

using test::contains;

// Counts, in the executor's thread, the allocations between two of its read phases: everything
// the other programs of its executor (the arm's servo loop) do in a cycle.
class AllocationProbe : public ControlProgram {
 public:
  AllocationProbe() : ControlProgram("probe") {}
  ~AllocationProbe() override { stop(); }
  std::atomic<std::size_t> allocations{0};
  std::atomic<long> cycles{0};

 protected:
  void readInputs() override {
    const std::size_t now = test::allocationCount();
    if (cycles_ > 2) allocations_ += now - last_;
    ++cycles_;
    last_ = test::allocationCount();
    allocations.store(allocations_);
    cycles.store(cycles_);
  }
  void control() override {}

 private:
  std::size_t allocations_ = 0, last_ = 0;
  long cycles_ = 0;
};

class Ros2EffortTest : public test::Ros2Fixture {
 protected:
  void SetUp() override {
    test::Ros2Fixture::SetUp();
    options_.commands = true;
    // The plant without friction: its torque balance is M(q) qdd + c + g = tau, M with the motors'
    // reflected inertia. The shoulder and elbow bent: gravity loads them.
    configure("[puma]\nclass Puma560\nsimFriction off\nsimInitialPosition 0 -30 -60 0 30 0\n");
  }

  // A writer of `puma/effort_commands`, once the bridge's reader is matched.
  dds_entity_t writer() { return test::Ros2Fixture::writer(std_msgs_msg_dds__Float64MultiArray__desc, "puma/effort_commands"); }
  static void send(dds_entity_t w, std::vector<double> efforts) {
    std_msgs_msg_dds__Float64MultiArray_ m{};
    m.data._buffer = efforts.data();
    m.data._length = m.data._maximum = static_cast<uint32_t>(efforts.size());
    ASSERT_GE(dds_write(w, &m), 0);
  }
  // The bridge's state JSON for the arm once `accept` holds for it ("" if it never did).
  std::string stateWhere(dds_entity_t state, const std::function<bool(const nlohmann::json&)>& accept, double seconds = 10) {
    std::string text;
    takeUntil<std_msgs_msg_dds__String_>(
        state,
        [&](const std_msgs_msg_dds__String_& s) {
          const nlohmann::json j = nlohmann::json::parse(s.data);
          if (!accept(j)) return false;
          text = s.data;
          return true;
        },
        seconds);
    return text;
  }
  // Streams the arm's gravity torque from writer `w` at about 1 kHz in a thread of its own until
  // destroyed (then it stops sending).
  struct GravityStream {
    GravityStream(Puma560& puma, dds_entity_t w)
        : thread([this, &puma, w] {
            ManipulatorData data(puma.getModel());
            while (!stop.load()) {
              JointVector g(6);
              gravityTorque(puma.getModel(), data, puma.getJointPosition(), g);
              send(w, std::vector<double>(g.data(), g.data() + 6));
              std::this_thread::sleep_for(std::chrono::milliseconds(1));
            }
          }) {}
    ~GravityStream() {
      stop = true;
      thread.join();
    }
    std::atomic<bool> stop{false};
    std::thread thread;
  };
  // Streams the arm's gravity torque (the arm holds still by it) until the state says effort
  // commands drive the arm, then for 50 ms more; then stops.
  void driveByGravity(Puma560& puma, dds_entity_t w, dds_entity_t state) {
    const ManipulatorModel& model = puma.getModel();
    ManipulatorData data(model);
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    int after = -1;
    while (after < 50 && std::chrono::steady_clock::now() < end) {
      JointVector g(6);
      gravityTorque(model, data, puma.getJointPosition(), g);
      send(w, std::vector<double>(g.data(), g.data() + 6));
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      if (after >= 0)
        ++after;
      else if (!stateWhere(state, [](const nlohmann::json& j) { return j.value("effortDriving", false); }, 0.002).empty())
        after = 0;
    }
    ASSERT_GE(after, 50) << "effort commands never drove the arm";
  }
  // Waits until the arm is powered and at rest.
  static void settle(Puma560& puma) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while ((!puma.isArmPowerOn() || puma.getJointVelocity().cwiseAbs().maxCoeff() > 1e-4) && std::chrono::steady_clock::now() < end)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    ASSERT_TRUE(puma.isArmPowerOn());
  }
};

// Gravity plus 20 N m on the shoulder: the shoulder accelerates as M(q)^-1 says, the other joints
// hardly move (the command is exactly the arm's torque: the manipulator's own gravity compensation
// is taken off). Then the commands stop and the arm holds where it is then.
TEST_F(Ros2EffortTest, EffortCommandsDriveTheArmByTorqueAndItHoldsWhenTheyStop) {
  Puma560 puma("puma");
  // Commands go on for 0.25 s after the last: the test's thread (normal scheduling) may stall
  // while it streams, and a hold in mid-push would spoil the measured acceleration.
  options_.effortTimeout = 0.25;
  Ros2Bridge bridge("ros", options_);
  settle(puma);
  ASSERT_TRUE(puma.isGravityCompensationOn());
  const ManipulatorModel& model = puma.getModel();
  ManipulatorData data(model);
  const JointVector q0 = puma.getJointPosition();
  JointVector g(6);
  gravityTorque(model, data, q0, g);
  ASSERT_GT(std::abs(g(1)), 20) << "a pose where gravity loads the shoulder: " << g.transpose();
  const JointMatrix M = massMatrix(model, data, q0, true);
  constexpr double kPush = 20;  // [N m] on joint 2
  JointVector push = JointVector::Zero(6);
  push(1) = kPush;
  const JointVector expected = M.inverse() * push;  // the acceleration at rest [rad/s^2]

  const dds_entity_t w = writer();
  const dds_entity_t state = reader(std_msgs_msg_dds__String__desc, "puma/state");
  // Stream g(q0) + push at 1 kHz until the shoulder has moved 0.02 rad (or 2 s).
  JointVector q = q0, qd = JointVector::Zero(6);
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(2);
  while (std::abs(q(1) - q0(1)) < 0.02 && std::chrono::steady_clock::now() < end) {
    std::vector<double> tau(6);
    for (int i = 0; i < 6; ++i) tau[static_cast<std::size_t>(i)] = g(i) + push(i);
    send(w, tau);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    q = puma.getJointPosition();
    qd = puma.getJointVelocity();
  }
  ASSERT_GE(std::abs(q(1) - q0(1)), 0.02) << "the shoulder did not move";
  EXPECT_GT(bridge.getStatistics().efforts, 10u);
  // Constant acceleration from rest: v^2 = 2 a d, whatever the moment the first command acted.
  const double measured = qd(1) * qd(1) / (2 * (q(1) - q0(1)));
  EXPECT_NEAR(measured, std::abs(expected(1)), 0.15 * std::abs(expected(1))) << "expected " << expected.transpose();
  EXPECT_GT((q(1) - q0(1)) * expected(1), 0) << "the direction";
  // Every joint as M(q)^-1 couples the push to it: from rest at constant acceleration, each moved
  // in the same ratio to the shoulder as its acceleration (to the change of g over the motion).
  for (int i = 0; i < 6; ++i)
    EXPECT_NEAR(q(i) - q0(i), expected(i) / expected(1) * (q(1) - q0(1)), 2e-3) << "joint " << i + 1 << ", expected "
                                                                                << expected.transpose();
  EXPECT_FALSE(stateWhere(state, [](const nlohmann::json& j) { return j.value("effortDriving", false); }).empty());

  // The writer lets go (an empty command): the arm holds at once, and stays where it stopped.
  // (Commands that just stop hold it after effortTimeout: Ros2IoBoardTest.KillingTheProgram...)
  send(w, {});
  std::this_thread::sleep_for(std::chrono::milliseconds(400));
  const JointVector held = puma.getJointPosition();
  EXPECT_LT(puma.getJointVelocity().cwiseAbs().maxCoeff(), 1e-2);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  EXPECT_LT((puma.getJointPosition() - held).cwiseAbs().maxCoeff(), 1e-3) << "held, not falling";
  EXPECT_LT((held - q).cwiseAbs().maxCoeff(), 0.05) << "held near where the commands stopped";
  EXPECT_FALSE(stateWhere(state, [](const nlohmann::json& j) { return !j.value("effortDriving", true); }).empty());
  EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
  EXPECT_EQ(bridge.getStatistics().effortsRefused, 0u);
}

// Wrong sizes, NaN, commands off: refused, named on the state topic; the arm keeps holding.
TEST_F(Ros2EffortTest, BadCommandsAreRefusedAndTheArmKeepsHolding) {
  Puma560 puma("puma");
  Ros2Bridge bridge("ros", options_);
  settle(puma);
  const dds_entity_t w = writer();
  const dds_entity_t state = reader(std_msgs_msg_dds__String__desc, "puma/state");
  driveByGravity(puma, w, state);  // the arm driven by effort commands, then holding
  const JointVector q0 = puma.getJointPosition();
  const std::uint64_t accepted = bridge.getStatistics().efforts;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  struct Case {
    std::vector<double> efforts;
    bool commandsOn;
    const char* message;
  };
  const Case cases[] = {
      {{1, 2, 3}, true, "data: 3 efforts, the arm has 6 joints"},
      {{1, 2, 3, 4, 5, 6, 7}, true, "data: 7 efforts, the arm has 6 joints"},
      {{0, 0, nan, 0, 0, 0}, true, "data[2] is not a finite number"},
      {{0, 0, 0, 0, 0, std::numeric_limits<double>::infinity()}, true, "data[5] is not a finite number"},
      {{0, 0, 0, 0, 0, 0}, false, "commands are off"},
  };
  std::uint64_t refused = 0;
  for (const Case& c : cases) {
    bridge.setCommandsEnabled(c.commandsOn);
    send(w, c.efforts);
    ++refused;
    const std::string text = stateWhere(state, [&](const nlohmann::json& j) {
      return j.value("effortsRefused", std::uint64_t{0}) == refused && contains(j.value("effort", std::string()), c.message);
    });
    EXPECT_FALSE(text.empty()) << c.message;
  }
  EXPECT_EQ(bridge.getStatistics().effortsRefused, refused);
  EXPECT_EQ(bridge.getStatistics().efforts, accepted);
  EXPECT_LT((puma.getJointPosition() - q0).cwiseAbs().maxCoeff(), 1e-3);
  EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
}

// A program's own trajectory generator keeps the arm: effort commands are refused, saying why.
TEST_F(Ros2EffortTest, AnArmDrivenByItsProgramRefusesEffortCommands) {
  Puma560 puma("puma");
  Ros2Bridge bridge("ros", options_);
  settle(puma);
  DefaultTrajectoryGenerator<6> tragen("program_motion");
  puma.setTrajectoryGenerator(tragen);
  const dds_entity_t w = writer();
  const dds_entity_t state = reader(std_msgs_msg_dds__String__desc, "puma/state");
  send(w, {0, 0, 0, 0, 0, 0});
  const std::string text = stateWhere(state, [](const nlohmann::json& j) { return j.value("effortsRefused", 0) == 1; });
  EXPECT_TRUE(contains(text, "program_motion")) << text;
  puma.clearTrajectoryGenerator();
}

// The arm's program takes it back (a servo control of its own) while effort commands drive it: the
// commands are refused from then on, naming why, so that their sender's board faults.
TEST_F(Ros2EffortTest, AProgramTakingTheArmBackRefusesTheCommands) {
  Puma560 puma("puma");
  Ros2Bridge bridge("ros", options_);
  settle(puma);
  const dds_entity_t w = writer();
  const dds_entity_t state = reader(std_msgs_msg_dds__String__desc, "puma/state");
  GravityStream stream(puma, w);
  ASSERT_FALSE(stateWhere(state, [](const nlohmann::json& j) { return j.value("effortDriving", false); }).empty());
  DefaultPositionControl own("own_control");
  puma.setServoControl(own);
  const std::string text = stateWhere(state, [](const nlohmann::json& j) { return j.value("effortsRefused", 0) >= 1; });
  EXPECT_TRUE(contains(text, "own_control")) << text;
  EXPECT_FALSE(contains(text, "\"effortDriving\":true")) << text;
  EXPECT_EQ(&puma.getServoControl(), &own);
}

// One command stream at a time: a trajectory while effort commands drive the arm is refused, and
// so are a second writer's commands; the driver's empty command lets go at once (the arm holds
// without waiting for effortTimeout), and then the other writer may drive it.
TEST_F(Ros2EffortTest, OneStreamDrivesTheArmAtATime) {
  Puma560 puma("puma");
  options_.effortTimeout = 1;  // a hold that came by time-out would come late
  Ros2Bridge bridge("ros", options_);
  settle(puma);
  const dds_entity_t first = writer(), second = writer();
  const dds_entity_t trajectoryWriter = Ros2Fixture::writer(trajectory_msgs_msg_dds__JointTrajectory__desc, "puma/joint_trajectory");
  const dds_entity_t state = reader(std_msgs_msg_dds__String__desc, "puma/state");
  {
    GravityStream stream(puma, first);
    ASSERT_FALSE(stateWhere(state, [](const nlohmann::json& j) { return j.value("effortDriving", false); }).empty());
    // A trajectory: refused while the commands drive the arm.
    test::TrajectoryMessage m;
    const JointVector q = puma.getJointPosition();
    for (int k = 0; k < 6; ++k) m.names.push_back("puma_joint" + std::to_string(k + 1));
    test::TrajectoryMessage::Point point;
    point.time = 1;
    for (int k = 0; k < 6; ++k) point.positions.push_back(q(k) + (k == 0 ? 0.05 : 0));
    m.points.push_back(point);
    ASSERT_GE(dds_write(trajectoryWriter, &m.message()), 0);
    const std::string t = stateWhere(state, [](const nlohmann::json& j) { return j.value("trajectoriesRefused", 0) == 1; });
    EXPECT_TRUE(contains(t, "driven by effort commands")) << t;
    // The second writer: refused.
    send(second, {0, 0, 0, 0, 0, 0});
    const std::string e = stateWhere(state, [](const nlohmann::json& j) { return j.value("effortsRefused", 0) == 1; });
    EXPECT_TRUE(contains(e, "another writer drives the arm")) << e;
  }
  // The first writer lets go: held at once, far sooner than effortTimeout (1 s).
  send(first, {});
  const auto let = std::chrono::steady_clock::now();
  EXPECT_FALSE(stateWhere(state, [](const nlohmann::json& j) { return !j.value("effortDriving", true); }, 0.5).empty());
  EXPECT_LT(std::chrono::steady_clock::now() - let, std::chrono::milliseconds(500));
  // Now the second writer may drive it.
  GravityStream stream(puma, second);
  EXPECT_FALSE(stateWhere(state, [](const nlohmann::json& j) { return j.value("effortDriving", false); }).empty());
  EXPECT_EQ(bridge.getStatistics().effortsRefused, 1u);
  EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
}

// The servo cycle driven by effort commands (the bridge's control reading them) does not allocate.
TEST_F(Ros2EffortTest, TheServoCycleDrivenByEffortCommandsDoesNotAllocate) {
  Puma560 puma("puma");
  Ros2Bridge bridge("ros", options_);
  settle(puma);
  AllocationProbe probe;  // the arm's rate and priority: the same executor, the same thread
  probe.setRate(1.0 / puma.getServoPeriod());
  probe.start();
  const ManipulatorModel& model = puma.getModel();
  ManipulatorData data(model);
  const dds_entity_t w = writer();
  const dds_entity_t state = reader(std_msgs_msg_dds__String__desc, "puma/state");
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  bool driving = false;
  long from = -1;
  std::size_t base = 0;
  while (std::chrono::steady_clock::now() < end && (from < 0 || probe.cycles.load() < from + 500)) {
    JointVector g(6);
    gravityTorque(model, data, puma.getJointPosition(), g);  // hold the arm by its gravity torque
    send(w, std::vector<double>(g.data(), g.data() + 6));
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    if (!driving && !stateWhere(state, [](const nlohmann::json& j) { return j.value("effortDriving", false); }, 0.002).empty()) {
      driving = true;
      from = probe.cycles.load();
      base = probe.allocations.load();
    }
  }
  ASSERT_TRUE(driving);
  ASSERT_GE(probe.cycles.load(), from + 500);
  // The probe counts the arm's cycles only in the arm's executor: in the same thread, not its own.
  ASSERT_FALSE(probe.getStatistics().ownThread);
  ASSERT_GE(probe.getStatistics().executorPrograms, 2u);
  EXPECT_EQ(probe.allocations.load() - base, 0u) << "over " << probe.cycles.load() - from << " cycles driven by effort commands";
  EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
}

}  // namespace
}  // namespace rp
