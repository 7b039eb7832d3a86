// Ros2Bridge's <object>/joint_trajectory: trajectories written by plain Cyclone DDS writers
// generated from the same IDL (one in another process, ros2_trajectory_writer) are executed by a
// simulated Puma 560 until it reaches the last point; bad ones are refused with a message naming
// the field on <object>/state while the arm keeps holding (or keeps its motion); commands are off
// by default; the reader announces ROS 2's type name and QoS.
#include <dds/dds.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "Ros2Fixture.hpp"
#include "TrajectoryMessage.hpp"
#include "rp/RoboticPlatform.hpp"
#include "std_msgs.h"

namespace rp {
namespace {

using test::contains;
using test::TrajectoryMessage;

class Ros2TrajectoryTest : public test::Ros2Fixture {
 protected:
  void SetUp() override {
    test::Ros2Fixture::SetUp();
    options_.commands = true;
  }

  // A writer of `puma/joint_trajectory`, once the bridge's reader is matched.
  dds_entity_t writer() { return test::Ros2Fixture::writer(trajectory_msgs_msg_dds__JointTrajectory__desc, "puma/joint_trajectory"); }

  // A good trajectory for the Puma from `q0`: three points with positions only over 1.5 s,
  // the joint names in reverse order.
  static TrajectoryMessage goodTrajectory(const JointVector& q0, const JointVector& delta, double duration = 1.5) {
    TrajectoryMessage m;
    for (int k = 5; k >= 0; --k) m.names.push_back("puma_joint" + std::to_string(k + 1));
    for (int p = 1; p <= 3; ++p) {
      TrajectoryMessage::Point point;
      point.time = duration * p / 3;
      for (int k = 5; k >= 0; --k) point.positions.push_back(q0(k) + delta(k) * p / 3);
      m.points.push_back(point);
    }
    return m;
  }

  // Waits until the bridge has refused `refused` trajectories in all and the state topic says so;
  // returns the state's `trajectory` message.
  std::string refusal(Ros2Bridge& bridge, dds_entity_t state, std::uint64_t refused) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (bridge.getStatistics().trajectoriesRefused < refused && std::chrono::steady_clock::now() < end)
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    EXPECT_EQ(bridge.getStatistics().trajectoriesRefused, refused);
    std::string text;
    EXPECT_TRUE(takeUntil<std_msgs_msg_dds__String_>(state, [&](const std_msgs_msg_dds__String_& s) {
      const nlohmann::json j = nlohmann::json::parse(s.data);
      if (j["trajectoriesRefused"] != refused) return false;
      text = j["trajectory"];
      return true;
    })) << "no state with " << refused << " refusals";
    EXPECT_EQ(text, "refused: " + bridge.getLastCommandMessage("puma").substr(std::string("refused: ").size()));
    return text;
  }

  static bool waitFor(const std::function<bool()>& done, double seconds) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (!done()) {
      if (std::chrono::steady_clock::now() > end) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return true;
  }
};

JointVector pumaDelta() {
  JointVector d(6);
  d << 0.2, -0.15, 0.1, 0.2, -0.2, 0.3;
  return d;
}

// The set-up: the trajectory from another process over loopback UDP, the arm in this one.
TEST_F(Ros2TrajectoryTest, ATrajectoryFromAnotherProcessIsExecutedAndTheArmReachesItsLastPoint) {
  Puma560 puma("puma");
  Ros2Bridge bridge("ros", options_);
  ASSERT_TRUE(puma.isArmPowerOn());
  const JointVector q0 = puma.getJointPosition();
  const JointVector target = q0 + pumaDelta();
  for (int k = 0; k < 6; ++k) ASSERT_TRUE(target(k) > puma.getModel().getPositionMin()(k) && target(k) < puma.getModel().getPositionMax()(k));
  // The joint names in reverse order: the bridge reorders them.
  std::string command = std::string(RP_ROS2_TRAJECTORY_WRITER_PATH) + " " + std::to_string(options_.domain) + " " +
                        options_.nameSpace + " puma puma_joint6,puma_joint5,puma_joint4,puma_joint3,puma_joint2,puma_joint1";
  for (int p = 1; p <= 3; ++p) {
    command += " " + std::to_string(0.5 * p) + ":";
    for (int k = 5; k >= 0; --k) {
      char value[40];
      std::snprintf(value, sizeof value, "%.17g", q0(k) + pumaDelta()(k) * p / 3);
      command += value + std::string(k > 0 ? "," : "");
    }
  }
  command += " 2>&1";
  FILE* child = popen(command.c_str(), "r");
  ASSERT_NE(child, nullptr);
  std::string out;
  char buffer[512];
  while (std::fgets(buffer, sizeof buffer, child)) out += buffer;
  ASSERT_EQ(pclose(child), 0) << out;
  EXPECT_TRUE(contains(out, "written 3 points")) << out;
  ASSERT_TRUE(waitFor([&] { return bridge.getStatistics().trajectories == 1; }, 20))
      << bridge.getLastCommandMessage("puma");
  EXPECT_TRUE(contains(bridge.getLastCommandMessage("puma"), "accepted: 3 points over 1.5 s")) << bridge.getLastCommandMessage("puma");
  EXPECT_EQ(puma.getTrajectoryGenerator()->getName(), "ros_puma_joint_trajectory");
  auto* generator = dynamic_cast<TimedTrajectoryGenerator*>(puma.getTrajectoryGenerator());
  ASSERT_NE(generator, nullptr);
  ASSERT_TRUE(waitFor([&] { return generator->isDone(); }, 20));
  const JointVector setpoint = puma.getDesiredJointPosition();
  ASSERT_EQ(setpoint.size(), 6);
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(setpoint(k), target(k), 1e-9) << "joint " << k + 1;
  // The setpoint is the last point exactly; the arm within the PID's friction dead band of it.
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const JointVector q = puma.getJointPosition();
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(q(k), target(k), 0.01) << "joint " << k + 1;
  EXPECT_GT((q - q0).norm(), 0.3) << "the arm moved";
  EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
  EXPECT_EQ(bridge.getStatistics().trajectoriesRefused, 0u);
}

TEST_F(Ros2TrajectoryTest, TheReaderAnnouncesRos2TypeAndQos) {
  Puma560 puma("puma");
  Ros2Bridge bridge("ros", options_);
  participant_ = dds_create_participant(static_cast<dds_domainid_t>(options_.domain), nullptr, nullptr);
  ASSERT_GT(participant_, 0);
  const dds_entity_t subs = dds_create_reader(participant_, DDS_BUILTIN_TOPIC_DCPSSUBSCRIPTION, nullptr, nullptr);
  const std::string wanted = "rt/" + options_.nameSpace + "/puma/joint_trajectory";
  bool found = false;
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (!found && std::chrono::steady_clock::now() < end) {
    void* samples[16] = {};
    dds_sample_info_t info[16];
    const dds_return_t n = dds_take(subs, samples, info, 16, 16);
    for (dds_return_t i = 0; i < n; ++i) {
      const auto* ep = static_cast<const dds_builtintopic_endpoint_t*>(samples[i]);
      if (!info[i].valid_data || std::string(ep->topic_name) != wanted) continue;
      found = true;
      EXPECT_EQ(std::string(ep->type_name), "trajectory_msgs::msg::dds_::JointTrajectory_");
      dds_reliability_kind_t rel;
      dds_duration_t block;
      ASSERT_TRUE(dds_qget_reliability(ep->qos, &rel, &block));
      EXPECT_EQ(rel, DDS_RELIABILITY_RELIABLE);
      dds_durability_kind_t dur;
      ASSERT_TRUE(dds_qget_durability(ep->qos, &dur));
      EXPECT_EQ(dur, DDS_DURABILITY_VOLATILE);
      uint32_t reps = 0;
      dds_data_representation_id_t* values = nullptr;
      ASSERT_TRUE(dds_qget_data_representation(ep->qos, &reps, &values));
      ASSERT_EQ(reps, 1u);
      EXPECT_EQ(values[0], DDS_DATA_REPRESENTATION_XCDR1);
      dds_free(values);
    }
    if (n > 0) dds_return_loan(subs, samples, n);
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_TRUE(found) << "no reader of " << wanted;
}

TEST_F(Ros2TrajectoryTest, BadTrajectoriesAreRefusedWithTheFieldOnTheStateTopicAndTheArmHolds) {
  options_.commands = false;
  Puma560 puma("puma");
  Ros2Bridge bridge("ros", options_);
  EXPECT_FALSE(bridge.areCommandsEnabled());
  const dds_entity_t state = reader(std_msgs_msg_dds__String__desc, "puma/state");
  const dds_entity_t w = writer();
  const JointVector q0 = puma.getJointPosition();
  const ManipulatorModel& model = puma.getModel();
  std::uint64_t refused = 0;
  auto send = [&](TrajectoryMessage m) {
    EXPECT_GE(dds_write(w, &m.message()), 0);
    return refusal(bridge, state, ++refused);
  };
  // Off by default: a good trajectory is refused.
  EXPECT_TRUE(contains(send(goodTrajectory(q0, pumaDelta())), "commands are off")) << "commands off";
  bridge.setCommandsEnabled(true);

  struct Case {
    const char* what;
    std::function<void(TrajectoryMessage&)> breakIt;
    std::vector<std::string> expected;  // parts of the message
  };
  const std::vector<Case> cases = {
      {"unknown joint name", [](TrajectoryMessage& m) { m.names[2] = "puma_joint9"; }, {"joint_names[2]", "puma_joint9"}},
      {"duplicated joint name", [](TrajectoryMessage& m) { m.names[1] = m.names[0]; }, {"joint_names[1]", "twice"}},
      {"missing joint name", [](TrajectoryMessage& m) {
         m.names.pop_back();
         for (auto& p : m.points) p.positions.pop_back();
       }, {"joint_names: 5 names"}},
      {"NaN", [](TrajectoryMessage& m) { m.points[1].positions[3] = NAN; }, {"points[1].positions[3] (puma_joint3)", "not a finite"}},
      {"infinite velocity", [](TrajectoryMessage& m) {
         for (auto& p : m.points) p.velocities.assign(6, 0.0);
         m.points[0].velocities[0] = INFINITY;
       }, {"points[0].velocities[0]", "not a finite"}},
      {"times going backwards", [](TrajectoryMessage& m) { m.points[2].time = 0.2; }, {"points[2].time_from_start", "not after points[1]"}},
      {"equal times", [](TrajectoryMessage& m) { m.points[1].time = m.points[0].time; }, {"points[1].time_from_start"}},
      {"negative time", [](TrajectoryMessage& m) { m.points[0].time = -0.5; }, {"points[0].time_from_start", "negative"}},
      {"outside the joint limits", [&](TrajectoryMessage& m) { m.points[1].positions[5] = model.getPositionMax()(0) + 0.1; },
       {"points[1].positions[5] (puma_joint1)", "outside the joint limits"}},
      {"too fast", [&](TrajectoryMessage& m) {
         m.points[0].time = 0.01;
         m.points[0].positions[5] = q0(0) + 0.5;
       }, {"points[0]: puma_joint1 velocity", "exceeds the velocity limit"}},
      {"too few positions", [](TrajectoryMessage& m) { m.points[1].positions.pop_back(); }, {"points[1].positions: 5 values"}},
      {"velocities on some points only", [](TrajectoryMessage& m) { m.points[0].velocities.assign(6, 0.0); },
       {"points[1].velocities: 0 values"}},
      {"velocities of the wrong size", [](TrajectoryMessage& m) {
         for (auto& p : m.points) p.velocities.assign(6, 0.0);
         m.points[2].velocities.resize(7);
       }, {"points[2].velocities: 7 values"}},
      {"moving at the last point", [](TrajectoryMessage& m) {
         for (auto& p : m.points) p.velocities.assign(6, 0.0);
         m.points[2].velocities[1] = 0.1;
       }, {"points[2].velocities", "must be 0"}},
      {"no points", [](TrajectoryMessage& m) { m.points.clear(); }, {"points: none"}},
      {"oversized", [](TrajectoryMessage& m) {
         const TrajectoryMessage::Point last = m.points.back();
         m.points.assign(10001, last);
         for (std::size_t k = 0; k < m.points.size(); ++k) m.points[k].time = 1.5 + 0.001 * static_cast<double>(k);
       }, {"points: 10001, more than 10000"}},
      {"a start an hour ahead", [](TrajectoryMessage& m) {
         m.stamp = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count() + 3600;
       }, {"header.stamp", "in the future"}},
  };
  for (const Case& c : cases) {
    TrajectoryMessage m = goodTrajectory(q0, pumaDelta());
    c.breakIt(m);
    const std::string text = send(m);
    for (const std::string& part : c.expected) EXPECT_TRUE(contains(text, part)) << c.what << ": " << text;
  }
  // Nothing was taken: the arm held where it was, with no generator connected.
  EXPECT_EQ(bridge.getStatistics().trajectories, 0u);
  EXPECT_EQ(puma.getTrajectoryGenerator(), nullptr);
  EXPECT_NEAR((puma.getJointPosition() - q0).norm(), 0, 1e-3);
  EXPECT_NEAR((puma.getDesiredJointPosition() - q0).norm(), 0, 1e-3);
  EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
}

// A refused trajectory leaves the motion under way alone; a good one replaces it.
TEST_F(Ros2TrajectoryTest, ARefusalKeepsTheMotionAndANewTrajectoryReplacesIt) {
  Puma560 puma("puma");
  Ros2Bridge bridge("ros", options_);
  const dds_entity_t state = reader(std_msgs_msg_dds__String__desc, "puma/state");
  const dds_entity_t w = writer();
  const JointVector q0 = puma.getJointPosition();
  // A: slow (30 s), so that B surely replaces it in mid-motion; the test would wait for it else.
  TrajectoryMessage a = goodTrajectory(q0, pumaDelta(), 30.0);
  ASSERT_GE(dds_write(w, &a.message()), 0);
  ASSERT_TRUE(waitFor([&] { return bridge.getStatistics().trajectories == 1; }, 20));
  auto* generator = dynamic_cast<TimedTrajectoryGenerator*>(puma.getTrajectoryGenerator());
  ASSERT_NE(generator, nullptr);
  ASSERT_TRUE(waitFor([&] { return generator->getStartedCount() == 1; }, 20));
  TrajectoryMessage bad = goodTrajectory(q0, pumaDelta());
  bad.points[1].positions[0] = NAN;
  ASSERT_GE(dds_write(w, &bad.message()), 0);
  EXPECT_TRUE(contains(refusal(bridge, state, 1), "points[1].positions[0]"));
  EXPECT_FALSE(generator->isDone()) << "A goes on";
  EXPECT_EQ(generator->getStartedCount(), 1u);
  // B: back to q0 - delta / 2, replacing A in mid-motion.
  const JointVector target = q0 - 0.5 * pumaDelta();
  TrajectoryMessage b = goodTrajectory(q0, -0.5 * pumaDelta(), 1.5);
  b.points.erase(b.points.begin(), b.points.begin() + 2);  // one point: the target
  ASSERT_GE(dds_write(w, &b.message()), 0);
  ASSERT_TRUE(waitFor([&] { return generator->getStartedCount() == 2; }, 20)) << "B did not replace A";
  ASSERT_TRUE(waitFor([&] { return generator->isDone(); }, 20)) << "B did not end before A would have";
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const JointVector q = puma.getJointPosition();
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(q(k), target(k), 0.01) << "joint " << k + 1;
  EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
  EXPECT_EQ(bridge.getStatistics().trajectories, 2u);
}

}  // namespace
}  // namespace rp
