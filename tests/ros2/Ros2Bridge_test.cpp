// Ros2Bridge: a simulated Puma 560 published on DDS, read back with plain Cyclone DDS readers
// generated from the same IDL: topic and type names as ROS 2 has them, joint names, sizes and
// values against the arm, tf against its kinematics, robot_description for a late joiner, the
// writers' QoS as discovery announces them, and bad rp.cfg settings.
#include "rp/ros2/Ros2Bridge.hpp"

#include <dds/dds.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <functional>
#include <string>
#include <thread>

#include "ChildProcess.hpp"
#include "Ros2Fixture.hpp"
#include "rp/RoboticPlatform.hpp"
#include "sensor_msgs.h"
#include "std_msgs.h"
#include "tf2_msgs.h"

namespace rp {
namespace {

using test::Child;
using test::contains;
using Ros2BridgeTest = test::Ros2Fixture;

TEST_F(Ros2BridgeTest, DdsNamesFollowRos2Conventions) {
  EXPECT_EQ(Ros2Bridge::ddsTopicName("", "joint_states"), "rt/joint_states");
  EXPECT_EQ(Ros2Bridge::ddsTopicName("/lab/cell1/", "tf"), "rt/lab/cell1/tf");
  const std::string lo = Ros2Bridge::cycloneConfig({"lo"});
  EXPECT_TRUE(contains(lo, "<Interfaces><NetworkInterface name=\"lo\"/></Interfaces>")) << lo;
  EXPECT_TRUE(contains(lo, "<Peer Address=\"127.0.0.1\"/>")) << lo;
  EXPECT_TRUE(contains(Ros2Bridge::cycloneConfig({"10.0.0.2"}), "<NetworkInterface address=\"10.0.0.2\"/>"));
  EXPECT_FALSE(contains(Ros2Bridge::cycloneConfig({"any"}), "Interfaces"));
  const std::string urdf = "<robot name=\"r\">\n  <link name=\"world\"/>\n  <link name=\"link1\"/>\n"
                           "  <joint name=\"joint1\" type=\"revolute\">\n    <parent link=\"world\"/>\n"
                           "    <child link=\"link1\"/>\n  </joint>\n</robot>\n";
  EXPECT_EQ(Ros2Bridge::prefixUrdf("arm", urdf),
            "<robot name=\"r\">\n  <link name=\"world\"/>\n  <link name=\"arm_link1\"/>\n"
            "  <joint name=\"arm_joint1\" type=\"revolute\">\n    <parent link=\"world\"/>\n"
            "    <child link=\"arm_link1\"/>\n  </joint>\n</robot>\n");
  EXPECT_EQ(Ros2Bridge::checkOptions(Ros2BridgeOptions{}), "");
  Ros2BridgeOptions bad;
  bad.domain = 231;
  EXPECT_TRUE(contains(Ros2Bridge::checkOptions(bad), "domain"));
  bad = {};
  bad.nameSpace = "9lives";
  EXPECT_TRUE(contains(Ros2Bridge::checkOptions(bad), "namespace"));
  for (const double rate : {-1.0, 0.5, 1001.0}) {
    bad = {};
    bad.rate = rate;
    EXPECT_TRUE(contains(Ros2Bridge::checkOptions(bad), "rate")) << rate;
    EXPECT_THROW(Ros2Bridge("b", bad), std::invalid_argument) << rate;
  }
  Ros2BridgeOptions servo;
  servo.rate = Ros2BridgeOptions::kServoRate;
  EXPECT_EQ(Ros2Bridge::checkOptions(servo), "");
}

TEST_F(Ros2BridgeTest, PublishesTheArmsJointStatesWithRos2NamesAndTypes) {
  Puma560 puma("puma");
  Ros2Bridge bridge("ros", options_);
  const dds_entity_t r = reader(sensor_msgs_msg_dds__JointState__desc, "joint_states");
  char name[200];
  ASSERT_GE(dds_get_name(dds_get_topic(r), name, sizeof name), 0);
  EXPECT_EQ(std::string(name), "rt/" + options_.nameSpace + "/joint_states");
  ASSERT_GE(dds_get_type_name(dds_get_topic(r), name, sizeof name), 0);
  EXPECT_EQ(std::string(name), "sensor_msgs::msg::dds_::JointState_");

  const JointVector q = puma.getJointPosition();  // the simulated arm holds where it starts
  ASSERT_EQ(q.size(), 6);
  int checked = 0;
  const bool got = takeUntil<sensor_msgs_msg_dds__JointState_>(r, [&](const sensor_msgs_msg_dds__JointState_& js) {
    EXPECT_EQ(js.name._length, 6u);
    EXPECT_EQ(js.position._length, 6u);
    EXPECT_EQ(js.velocity._length, 6u);
    EXPECT_EQ(js.effort._length, 6u);
    if (js.name._length != 6 || js.position._length != 6 || js.velocity._length != 6 || js.effort._length != 6) return true;
    for (int k = 0; k < 6; ++k) {
      EXPECT_EQ(std::string(js.name._buffer[k]), "puma_joint" + std::to_string(k + 1));
      EXPECT_NEAR(js.position._buffer[k], q(k), 1e-3) << k;
      EXPECT_TRUE(std::isfinite(js.velocity._buffer[k]));
      EXPECT_TRUE(std::isfinite(js.effort._buffer[k]));
    }
    // The stamp is the wall clock, as ROS 2's time is.
    const double stamp = js.header.stamp.sec + 1e-9 * js.header.stamp.nanosec;
    const double wall = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
    EXPECT_NEAR(stamp, wall, 5.0);
    return ++checked >= 3;  // several cycles
  });
  EXPECT_TRUE(got) << "no joint_states from the bridge";
  const Ros2BridgeStatistics s = bridge.getStatistics();
  EXPECT_EQ(s.manipulators, 1u);
  EXPECT_GE(s.jointStates, 3u);
  EXPECT_EQ(s.writeFailures, 0u);
}

TEST_F(Ros2BridgeTest, WritersAnnounceRos2QosAndXcdr1) {
  Puma560 puma("puma");
  Ros2Bridge bridge("ros", options_);
  if (participant_ <= 0) participant_ = dds_create_participant(static_cast<dds_domainid_t>(options_.domain), nullptr, nullptr);
  ASSERT_GT(participant_, 0);
  const dds_entity_t pubs = dds_create_reader(participant_, DDS_BUILTIN_TOPIC_DCPSPUBLICATION, nullptr, nullptr);
  ASSERT_GT(pubs, 0);
  const std::string prefix = "rt/" + options_.nameSpace + "/";
  std::map<std::string, std::string> types;
  std::map<std::string, bool> transientLocal;
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (types.size() < 6 && std::chrono::steady_clock::now() < end) {
    void* samples[16] = {};
    dds_sample_info_t info[16];
    const dds_return_t n = dds_take(pubs, samples, info, 16, 16);
    for (dds_return_t i = 0; i < n; ++i) {
      if (!info[i].valid_data) continue;
      const auto* ep = static_cast<const dds_builtintopic_endpoint_t*>(samples[i]);
      const std::string topic = ep->topic_name;
      if (topic.rfind(prefix, 0) != 0) continue;
      types[topic.substr(prefix.size())] = ep->type_name;
      dds_reliability_kind_t rel;
      dds_duration_t block;
      ASSERT_TRUE(dds_qget_reliability(ep->qos, &rel, &block));
      EXPECT_EQ(rel, DDS_RELIABILITY_RELIABLE) << topic;
      dds_durability_kind_t dur;
      ASSERT_TRUE(dds_qget_durability(ep->qos, &dur));
      transientLocal[topic.substr(prefix.size())] = dur == DDS_DURABILITY_TRANSIENT_LOCAL;
      uint32_t reps = 0;
      dds_data_representation_id_t* values = nullptr;
      ASSERT_TRUE(dds_qget_data_representation(ep->qos, &reps, &values));
      ASSERT_EQ(reps, 1u) << topic;
      EXPECT_EQ(values[0], DDS_DATA_REPRESENTATION_XCDR1) << topic;
      dds_free(values);
    }
    if (n > 0) dds_return_loan(pubs, samples, n);
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_EQ(types["joint_states"], "sensor_msgs::msg::dds_::JointState_");
  EXPECT_EQ(types["tf"], "tf2_msgs::msg::dds_::TFMessage_");
  EXPECT_EQ(types["tf_static"], "tf2_msgs::msg::dds_::TFMessage_");
  EXPECT_EQ(types["robot_description"], "std_msgs::msg::dds_::String_");
  EXPECT_EQ(types["puma/robot_description"], "std_msgs::msg::dds_::String_");
  EXPECT_EQ(types["puma/state"], "std_msgs::msg::dds_::String_");
  EXPECT_FALSE(transientLocal["joint_states"]);
  EXPECT_FALSE(transientLocal["tf"]);
  EXPECT_FALSE(transientLocal["puma/state"]);
  EXPECT_TRUE(transientLocal["tf_static"]);
  EXPECT_TRUE(transientLocal["robot_description"]);
  EXPECT_TRUE(transientLocal["puma/robot_description"]);
}

TEST_F(Ros2BridgeTest, ALateJoinerGetsTheRobotDescription) {
  Puma560 puma("puma");
  Ros2Bridge bridge("ros", options_);
  // Late: after the bridge has published the descriptions.
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (bridge.getStatistics().descriptions < 2 && std::chrono::steady_clock::now() < end)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_GE(bridge.getStatistics().descriptions, 2u);
  std::this_thread::sleep_for(std::chrono::milliseconds(100));

  const std::string expected = Ros2Bridge::prefixUrdf("puma", toUrdf(puma.getModel()));
  EXPECT_TRUE(contains(expected, "<joint name=\"puma_joint6\""));
  const dds_entity_t arm = reader(std_msgs_msg_dds__String__desc, "puma/robot_description", true);
  EXPECT_TRUE(takeUntil<std_msgs_msg_dds__String_>(arm, [&](const std_msgs_msg_dds__String_& s) {
    EXPECT_EQ(std::string(s.data), expected);
    return true;
  })) << "no puma/robot_description for a late joiner";
  const dds_entity_t all = reader(std_msgs_msg_dds__String__desc, "robot_description", true);
  EXPECT_TRUE(takeUntil<std_msgs_msg_dds__String_>(all, [&](const std_msgs_msg_dds__String_& s) {
    const std::string text = s.data;
    EXPECT_TRUE(contains(text, "<joint name=\"puma_joint1\" type=\"revolute\">")) << text;
    EXPECT_TRUE(contains(text, "<link name=\"puma_tool\"/>")) << text;
    const std::size_t world = text.find("<link name=\"world\"/>");
    EXPECT_NE(world, std::string::npos);
    EXPECT_EQ(text.find("<link name=\"world\"/>", world + 1), std::string::npos) << "one world link";
    return true;
  })) << "no robot_description for a late joiner";
  // tf_static: the base for a late joiner too.
  const dds_entity_t st = reader(tf2_msgs_msg_dds__TFMessage__desc, "tf_static", true);
  EXPECT_TRUE(takeUntil<tf2_msgs_msg_dds__TFMessage_>(st, [&](const tf2_msgs_msg_dds__TFMessage_& m) {
    EXPECT_EQ(m.transforms._length, 1u);
    if (m.transforms._length != 1) return true;
    EXPECT_EQ(std::string(m.transforms._buffer[0].header.frame_id), "world");
    EXPECT_EQ(std::string(m.transforms._buffer[0].child_frame_id), "puma_base_link");
    const Transform b = puma.getModel().getBaseTransform();
    EXPECT_NEAR(m.transforms._buffer[0].transform.translation.z, b(2, 3), 1e-12);
    return true;
  })) << "no tf_static for a late joiner";
}

TEST_F(Ros2BridgeTest, TfGivesEveryLinkFrameAndTheEndEffectorInTheWorld) {
  Puma560 puma("puma");
  Ros2Bridge bridge("ros", options_);
  const dds_entity_t r = reader(tf2_msgs_msg_dds__TFMessage__desc, "tf");
  const Transform ee = puma.getEndEffectorTransform();
  const ManipulatorModel& model = puma.getModel();
  ManipulatorData data(model);
  forwardKinematics(model, data, puma.getJointPosition());
  EXPECT_TRUE(takeUntil<tf2_msgs_msg_dds__TFMessage_>(r, [&](const tf2_msgs_msg_dds__TFMessage_& m) {
    EXPECT_EQ(m.transforms._length, 7u);  // link1..6 and the tool
    if (m.transforms._length != 7) return true;
    for (uint32_t f = 0; f < 7; ++f) {
      const auto& ts = m.transforms._buffer[f];
      EXPECT_EQ(std::string(ts.header.frame_id), "world");
      const std::string child = ts.child_frame_id;
      const Eigen::Quaterniond qr(ts.transform.rotation.w, ts.transform.rotation.x, ts.transform.rotation.y,
                                  ts.transform.rotation.z);
      EXPECT_NEAR(qr.norm(), 1.0, 1e-9);
      Transform t = Transform::unit();
      t.topLeftCorner<3, 3>() = qr.toRotationMatrix();
      t(0, 3) = ts.transform.translation.x;
      t(1, 3) = ts.transform.translation.y;
      t(2, 3) = ts.transform.translation.z;
      if (f == 6) {
        EXPECT_EQ(child, "puma_tool");
        EXPECT_NEAR((t - ee).norm(), 0.0, 1e-4);
      } else {
        EXPECT_EQ(child, "puma_link" + std::to_string(f + 1));
        // URDF link k is the model's DH frame k without its x offset and twist (toUrdf()).
        const LinkParameters& l = model.getLink(static_cast<int>(f));
        const Transform dh = t * translation(l.a, 0, 0) * xRotation(l.alpha);
        EXPECT_NEAR((dh - data.linkTransforms[f]).norm(), 0.0, 1e-4) << child;
      }
    }
    return true;
  })) << "no tf from the bridge";
}

TEST_F(Ros2BridgeTest, StateTellsPowerErrorsAndShutdown) {
  Puma560 puma("puma");
  Ros2Bridge bridge("ros", options_);
  const dds_entity_t r = reader(std_msgs_msg_dds__String__desc, "puma/state");
  EXPECT_TRUE(takeUntil<std_msgs_msg_dds__String_>(r, [&](const std_msgs_msg_dds__String_& s) {
    const nlohmann::json j = nlohmann::json::parse(s.data);
    EXPECT_EQ(j["object"], "puma");
    EXPECT_EQ(j["class"], "Puma560");
    EXPECT_EQ(j["errorCode"], 0);
    EXPECT_EQ(j["shutdown"], false);
    // The arm powers on in its loop's first cycle: a state written before says off (it did once in
    // a full run), the ones after on.
    return j["power"] == true;
  })) << "no state with the arm's power on";
  EXPECT_TRUE(puma.isArmPowerOn());
  ObjectManager::requestSystemShutdown("test: stop everything");
  EXPECT_TRUE(takeUntil<std_msgs_msg_dds__String_>(r, [&](const std_msgs_msg_dds__String_& s) {
    const nlohmann::json j = nlohmann::json::parse(s.data);
    return j["shutdown"] == true && contains(j["shutdownReason"].get<std::string>(), "test: stop everything");
  })) << "no state with the shutdown";
  ObjectManager::resetShutdown();
}

// The set-up: the reader in another process, discovery and samples over loopback UDP
// (unicast: lo has no multicast), robot_description taken as a late joiner.
TEST_F(Ros2BridgeTest, AReaderInAnotherProcessGetsJointStatesAndTheDescription) {
  Puma560 puma("puma");
  Ros2Bridge bridge("ros", options_);
  const JointVector q = puma.getJointPosition();
  const std::string command = std::string(RP_ROS2_READER_PATH) + " " + std::to_string(options_.domain) + " " +
                              options_.nameSpace + " 2>&1";
  FILE* child = popen(command.c_str(), "r");
  ASSERT_NE(child, nullptr);
  std::string out;
  char buffer[4096];
  while (std::fgets(buffer, sizeof buffer, child)) out += buffer;
  const int status = pclose(child);
  ASSERT_EQ(status, 0) << out;
  std::istringstream lines(out);
  std::string line;
  bool jointStates = false, description = false;
  while (std::getline(lines, line)) {
    std::istringstream words(line);
    std::string kind;
    words >> kind;
    if (kind == "joint_states") {
      jointStates = true;
      for (int k = 0; k < 6; ++k) {
        std::string name;
        double position = NAN;
        ASSERT_TRUE(words >> name >> position) << line;
        EXPECT_EQ(name, "puma_joint" + std::to_string(k + 1));
        EXPECT_NEAR(position, q(k), 1e-3) << name;
      }
      std::string more;
      EXPECT_FALSE(words >> more) << "more than 6 joints: " << line;
    } else if (kind == "robot_description") {
      description = true;
      std::size_t bytes = 0;
      words >> bytes;
      EXPECT_GT(bytes, 1000u);
      EXPECT_TRUE(contains(line, "<joint name=\"puma_joint6\" type=\"revolute\">")) << line.substr(0, 300);
    }
  }
  EXPECT_TRUE(jointStates) << out;
  EXPECT_TRUE(description) << out;
}

// The scheduling policy and priority of this process's thread named "ros2bridge", once it has
// one of `policy` (the thread sets its own when it starts), within 5 s.
std::optional<std::pair<int, int>> bridgeThreadScheduling(int policy) {
  std::optional<std::pair<int, int>> seen;
  for (int k = 0; k < 500; ++k) {
    for (const auto& task : std::filesystem::directory_iterator("/proc/self/task")) {
      std::ifstream comm(task.path() / "comm");
      std::string name;
      std::getline(comm, name);
      if (name != "ros2bridge") continue;
      const pid_t tid = static_cast<pid_t>(std::stol(task.path().filename().string()));
      sched_param sp{};
      if (sched_getparam(tid, &sp) == 0) seen = std::make_pair(sched_getscheduler(tid), sp.sched_priority);
    }
    if (seen && seen->first == policy) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return seen;
}

// The publishing thread runs at its SCHED_FIFO priority (default 26, one below the control loops'
// 27), in both modes, or with normal scheduling at priority 0.
TEST_F(Ros2BridgeTest, ThePublishingThreadRunsAtItsPriority) {
  int probe = 0;
  std::thread([&probe] {
    sched_param sp{};
    sp.sched_priority = 1;
    probe = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp);
  }).join();
  if (probe != 0) GTEST_SKIP() << "this process may not use SCHED_FIFO (" << std::strerror(probe) << ")";
  EXPECT_EQ(Ros2BridgeOptions{}.priority, 26);
  const struct {
    double rate;
    int priority;
    int policy;
  } cases[] = {{Ros2BridgeOptions::kServoRate, 26, SCHED_FIFO}, {20, 12, SCHED_FIFO}, {Ros2BridgeOptions::kServoRate, 0, SCHED_OTHER}};
  for (const auto& c : cases) {
    Ros2BridgeOptions o = options_;
    o.rate = c.rate;
    o.priority = c.priority;
    {
      Ros2Bridge bridge("ros", o);
      const auto seen = bridgeThreadScheduling(c.policy);
      ASSERT_TRUE(seen.has_value()) << "no thread named ros2bridge";
      EXPECT_EQ(seen->first, c.policy) << "rate " << c.rate << ", priority " << c.priority;
      EXPECT_EQ(seen->second, c.priority) << "rate " << c.rate;
    }
  }
  Ros2BridgeOptions bad = options_;
  bad.priority = 99;
  EXPECT_THROW(Ros2Bridge("ros", bad), std::invalid_argument);
}

TEST_F(Ros2BridgeTest, BadRpCfgSettingsNameFileAndLine) {
  const std::pair<const char*, const char*> cases[] = {
      {"domain 231", "domain"},
      {"domain 2.5", "domain"},
      {"namespace 9lives", "namespace"},
      {"namespace a//b", "namespace"},
      {"rate 0", "rate"},
      {"rate 5000", "rate"},
      {"rate fast", "rate"},
      {"rate 50Hz", "rate"},
      {"interfaces no$such", "interfaces"},
      {"interfaces rpnosuchif0", "interfaces"},
      {"commands maybe", "commands"},
      {"priority 99", "priority"},
      {"priority -1", "priority"},
      {"priority 2.5", "priority"},
      {"effortTimeout 0.001", "effortTimeout"},
      {"effortTimeout 2", "effortTimeout"},
  };
  for (const auto& [line, setting] : cases) {
    try {
      configure(std::string("[ros]\nclass Ros2Bridge\n") + line + "\n");  // the schema's checks
      ObjectManager().createDerivedObject<Ros2Bridge>("ros");
      ADD_FAILURE() << line << " accepted";
    } catch (const ConfigError& e) {
      EXPECT_TRUE(contains(e.what(), "test.cfg:3")) << line << ": " << e.what();
      EXPECT_TRUE(contains(e.what(), setting)) << line << ": " << e.what();
    }
    ObjectManager().deleteAllObjects();
  }
  // Good settings from rp.cfg are taken.
  configure("[ros]\nclass Ros2Bridge\ndomain " + std::to_string(options_.domain) + "\nnamespace /" + options_.nameSpace +
            "/\nrate 20\ninterfaces lo\ncommands on\npriority 12\neffortTimeout 0.05\n");
  auto* bridge = ObjectManager().createDerivedObject<Ros2Bridge>("ros");
  ASSERT_NE(bridge, nullptr);
  EXPECT_EQ(bridge->getOptions().domain, options_.domain);
  EXPECT_EQ(bridge->getOptions().rate, 20);
  EXPECT_EQ(bridge->getOptions().interfaces, std::vector<std::string>{"lo"});
  EXPECT_EQ(bridge->getClassName(), "Ros2Bridge");
  EXPECT_TRUE(bridge->getOptions().commands);
  EXPECT_EQ(bridge->getOptions().priority, 12);
  EXPECT_EQ(bridge->getOptions().effortTimeout, 0.05);
  EXPECT_TRUE(bridge->areCommandsEnabled());
  bridge->setCommandsEnabled(false);
  EXPECT_FALSE(bridge->areCommandsEnabled());
  EXPECT_FALSE(Ros2BridgeOptions{}.commands) << "commands are off by default";
  ObjectManager().deleteAllObjects();
  configure("[ros]\nclass Ros2Bridge\ndomain " + std::to_string(options_.domain) + "\nrate servo\n");
  auto* servo = ObjectManager().createDerivedObject<Ros2Bridge>("ros");
  ASSERT_NE(servo, nullptr);
  EXPECT_EQ(servo->getOptions().rate, Ros2BridgeOptions::kServoRate);
}

// Records, in the arm's servo thread, the time each servo cycle read the joints (the arm's state
// snapshot, StateSnapshot::readTime) with the cycle's number: a program of the arm's rate, priority,
// CPU and clock, so stepped by the same thread in the same cycles (ThreadMode::Shared).
class CycleRecorder : public ControlProgram {
 public:
  explicit CycleRecorder(RoboticObject& arm) : ControlProgram("recorder"), arm_(arm) {
    const ControlProgram& servo = *arm.getControlProgram();
    setClock(servo.getClock());
    setRate(servo.getRate());
    setPriority(servo.getPriority());
    setCpuAffinity(servo.getCpuAffinity());
    readTimes_.reserve(100000);
  }
  ~CycleRecorder() override { stop(); }
  /// (read time [ns], cycle number) of each cycle seen, in order; call after stop().
  const std::vector<std::pair<std::int64_t, std::uint64_t>>& readTimes() const { return readTimes_; }

 private:
  void control() override {
    StateSnapshot s;
    if (!arm_.getStateSnapshot(s) || s.readTime <= 0 || readTimes_.size() == readTimes_.capacity()) return;
    if (readTimes_.empty() || readTimes_.back().second != s.cycle)
      readTimes_.emplace_back(std::llround(s.readTime * 1e9), s.cycle);
  }
  RoboticObject& arm_;
  std::vector<std::pair<std::int64_t, std::uint64_t>> readTimes_;
};

// At the servo rate (`rate servo`) the bridge publishes every servo cycle as it ends: each sample
// is a cycle not published before, stamped with the time that cycle read the joints, and most
// samples are the cycle after the one before (at a set rate of 100 Hz they are ten apart).
// (The arm is simulated: its read times are its cycles' times, StateSnapshot::readTime.)
// The stamps are compared with the read times the servo cycles themselves recorded: a stamp is a
// cycle's read time plus the offset from the arm's clock to the wall clock, to the nanosecond, and
// that offset stays the same between the bridge's measurements of it (one a second). So the test
// does not depend on how late the servo thread wakes (hundreds of microseconds under ASan with
// other tests running).
// Takes joint_states samples from `r` until `stamps` holds `count` stamps [ns] (at most 20 s; at
// least one take).
void takeStamps(dds_entity_t r, std::vector<std::int64_t>& stamps, std::size_t count) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  do {
    void* samples[10] = {nullptr};
    dds_sample_info_t info[10];
    const dds_return_t n = dds_take(r, samples, info, 10, 10);
    for (dds_return_t i = 0; i < n; ++i) {
      if (!info[i].valid_data) continue;
      const auto& m = *static_cast<const sensor_msgs_msg_dds__JointState_*>(samples[i]);
      stamps.push_back(static_cast<std::int64_t>(m.header.stamp.sec) * 1000000000LL + m.header.stamp.nanosec);
    }
    if (n > 0) dds_return_loan(r, samples, n);
    std::this_thread::sleep_for(std::chrono::microseconds(500));
  } while (stamps.size() < count && std::chrono::steady_clock::now() < end);
}

// An arm behind a hardware server (rp-hwserver's emulated Puma), published at the servo rate:
// each of the server's samples goes out once, stamped with when the server took it. While the
// server is stopped, the servo cycles read its last sample again: nothing goes out, and the next
// sample's stamp is the whole stop later. (Before, the old joints went out every cycle under the
// cycles' new stamps: to a reader differentiating over them, standing still, then a jump.)
TEST_F(Ros2BridgeTest, AtTheServoRateEachHardwareSampleGoesOutOnceStampedWhenTaken) {
  const std::string name = "test-bridge-hw-" + std::to_string(::getpid());
  struct Unlink {  // the segment of the server, which its SIGKILL at the end leaves behind
    const std::string& name;
    ~Unlink() { ::shm_unlink(("/rp-hwserver-" + name).c_str()); }
  } unlink{name};
  Child server({RP_HWSERVER_PATH, "-name", name, "-rate", "1000", "-board", "puma560", "-watchdog", "5000"});
  ASSERT_TRUE(contains(server.line(), "serving")) << "the hardware server did not start";
  RoboticPlatform::setConfiguration(Configuration::parse("[puma]\nclass Puma560\nsimulationMode off\nhwserver " + name + "\n", "rp.cfg"));
  RoboticPlatform::setSimulationModeOff();  // (the real clock, this suite's)
  struct Restore {
    ~Restore() {
      RoboticPlatform::setSimulationModeOn();
      RoboticPlatform::setConfiguration(Configuration());
      ObjectManager::resetShutdown();
    }
  } restore;
  std::vector<std::int64_t> stamps;  // [ns]
  {
    Puma560 puma("puma");
    ASSERT_TRUE(puma.usesHardware());
    options_.rate = Ros2BridgeOptions::kServoRate;
    Ros2Bridge bridge("ros", options_);
    const dds_entity_t r = reader(sensor_msgs_msg_dds__JointState__desc, "joint_states");
    takeStamps(r, stamps, 100);
    // 40 ms stopped, taking what comes meanwhile (the reader keeps only the last ten samples).
    ::kill(server.pid, SIGSTOP);
    const auto resume = std::chrono::steady_clock::now() + std::chrono::milliseconds(40);
    while (std::chrono::steady_clock::now() < resume) takeStamps(r, stamps, 0);
    ::kill(server.pid, SIGCONT);
    takeStamps(r, stamps, stamps.size() + 100);
    EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
  }
  ASSERT_GE(stamps.size(), 200u);
  std::int64_t longest = 0;
  for (std::size_t i = 1; i < stamps.size(); ++i) {
    EXPECT_GT(stamps[i], stamps[i - 1]) << "sample " << i << " went out again (or out of order)";
    longest = std::max(longest, stamps[i] - stamps[i - 1]);
  }
  EXPECT_GE(longest, 35000000) << "no sample waited for the stopped server";
}

TEST_F(Ros2BridgeTest, AtTheServoRateEachSampleIsTheNextServoCycleStampedWithItsTime) {
  Puma560 puma("puma");
  CycleRecorder recorder(puma);
  recorder.start();
  // The recorder sees a cycle's state in the next cycle: let it run before the bridge's first
  // sample, and after its last, so that it has recorded every cycle the bridge published (ci-3,
  // release: 399 cycles recorded for 400 samples, without these waits).
  ASSERT_TRUE(puma.waitForCycles(3));
  options_.rate = Ros2BridgeOptions::kServoRate;
  Ros2Bridge bridge("ros", options_);
  const dds_entity_t r = reader(sensor_msgs_msg_dds__JointState__desc, "joint_states");
  std::vector<std::int64_t> stamps;  // [ns]
  takeStamps(r, stamps, 400);
  ASSERT_GE(stamps.size(), 400u);
  ASSERT_TRUE(puma.waitForCycles(3));
  recorder.stop();
  // The offset from the arm's clock to the wall clock, as the bridge measures it (to microseconds):
  // a simulated arm's read times are its cycles' times, exactly a period apart, so offsets a whole
  // number of periods apart match the samples equally well; the true one is the nearest to this.
  const Clock& armClock = puma.getControlProgram()->getClock();
  const double before = armClock.getTime();
  const std::int64_t wall = std::chrono::duration_cast<std::chrono::nanoseconds>(
                                std::chrono::system_clock::now().time_since_epoch()).count();
  const std::int64_t approximateOffset = wall - std::llround(0.5 * (before + armClock.getTime()) * 1e9);
  const auto& cycles = recorder.readTimes();
  ASSERT_GE(cycles.size(), 400u);
  for (std::size_t i = 1; i < cycles.size(); ++i)
    ASSERT_EQ(cycles[i].second, cycles[i - 1].second + 1) << "the recorder missed a servo cycle";

  // The cycle that read the joints at `t` [ns], or none.
  const auto cycleAt = [&](std::int64_t t) -> std::optional<std::uint64_t> {
    const auto it = std::lower_bound(cycles.begin(), cycles.end(), std::make_pair(t, std::uint64_t{0}));
    if (it == cycles.end() || it->first != t) return std::nullopt;
    return it->second;
  };
  // The offset with which samples k.. are cycles' read times: the one that makes sample k a
  // cycle's read time and the most of the next ten too (at least eight; none by chance).
  const auto offsetAt = [&](std::size_t k) -> std::optional<std::int64_t> {
    std::optional<std::int64_t> best;
    std::size_t bestCount = 0;
    const std::size_t next = std::min<std::size_t>(10, stamps.size() - k - 1);
    if (next < 5) return std::nullopt;
    for (const auto& [t, cycle] : cycles) {
      const std::int64_t offset = stamps[k] - t;
      std::size_t count = 0;
      for (std::size_t j = k + 1; j <= k + next; ++j) count += cycleAt(stamps[j] - offset).has_value();
      if (count > bestCount || !best ||
          (count == bestCount && std::llabs(offset - approximateOffset) < std::llabs(*best - approximateOffset))) {
        best = offset;
        bestCount = count;
      }
    }
    if (bestCount < next - 2) return std::nullopt;
    return best;
  };

  std::optional<std::int64_t> offset;
  std::optional<std::uint64_t> previous;
  std::vector<std::uint64_t> steps;
  int measurements = 0, unmatched = 0;
  // From the second sample on: the first may be the arm's state from before its first cycle,
  // stamped when it was published.
  for (std::size_t k = 1; k < stamps.size(); ++k) {
    std::optional<std::uint64_t> cycle = offset ? cycleAt(stamps[k] - *offset) : std::nullopt;
    if (!cycle) {
      // The first sample, or the bridge measured the offset again.
      if (const std::optional<std::int64_t> o = offsetAt(k)) {
        offset = o;
        ++measurements;
        cycle = cycleAt(stamps[k] - *offset);
      }
    }
    if (!cycle) {
      // Only the samples of the arm's cycles before the recorder's first, or after its last (it
      // may record a cycle one cycle late), may be of no cycle recorded.
      EXPECT_TRUE(!previous || k + 3 >= stamps.size()) << "sample " << k << ": not the read time of a servo cycle";
      ++unmatched;
      continue;
    }
    if (previous) {
      EXPECT_GT(*cycle, *previous) << "sample " << k << ": not a later cycle";
      if (*cycle > *previous) steps.push_back(*cycle - *previous);
    }
    previous = cycle;
  }
  EXPECT_LE(unmatched, 6);
  const double seconds = 1e-9 * static_cast<double>(stamps.back() - stamps.front());
  EXPECT_LE(measurements, 2 + seconds) << "the offset to the wall clock changed more often than it was measured";
  ASSERT_GE(steps.size(), 300u);
  std::nth_element(steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2), steps.end());
  EXPECT_EQ(steps[steps.size() / 2], 1u) << "the median sample is not the next servo cycle";
}

}  // namespace
}  // namespace rp
