// rp-dds: lists and echoes the topics of a Ros2Bridge running in this process, from a process of
// its own over loopback, and refuses bad usage with status 2.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <string>

#include "RunProgram.hpp"
#include "rp/RoboticPlatform.hpp"

namespace rp {
namespace {

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// Runs rp-dds with `args`; its output (stdout and stderr) and exit status.
std::pair<std::string, int> rpDds(const std::string& args) { return test::runMerged(std::string(RP_DDS_PATH) + " " + args); }

class RpDdsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    RoboticPlatform::setSimulationModeOn();
    options_.domain = 1 + static_cast<int>(getpid() % 200);
    options_.nameSpace = std::string("t") + std::to_string(getpid());
  }
  void TearDown() override { ObjectManager().deleteAllObjects(); }
  Ros2BridgeOptions options_;
};

TEST_F(RpDdsTest, ListsTheBridgesTopicsWithTheirRosTypes) {
  Puma560 puma("puma");
  Ros2Bridge bridge("ros", options_);
  const auto [out, status] = rpDds(std::string("list -domain ") + std::to_string(options_.domain) + " -time 1.5");
  ASSERT_EQ(status, 0) << out;
  const std::string ns = std::string("/") + options_.nameSpace;
  EXPECT_TRUE(contains(out, ns + "/joint_states sensor_msgs/msg/JointState 1 writer\n")) << out;
  EXPECT_TRUE(contains(out, ns + "/tf tf2_msgs/msg/TFMessage 1 writer\n")) << out;
  EXPECT_TRUE(contains(out, ns + "/tf_static tf2_msgs/msg/TFMessage 1 writer transient-local\n")) << out;
  EXPECT_TRUE(contains(out, ns + "/robot_description std_msgs/msg/String 1 writer transient-local\n")) << out;
  EXPECT_TRUE(contains(out, ns + "/puma/state std_msgs/msg/String 1 writer\n")) << out;
}

TEST_F(RpDdsTest, EchoesJointStatesAndTheRobotDescription) {
  Puma560 puma("puma");
  Ros2Bridge bridge("ros", options_);
  const std::string domain = std::string(" -domain ") + std::to_string(options_.domain);
  const auto [js, s1] = rpDds(std::string("echo /") + options_.nameSpace + std::string("/joint_states -count 2 -time 10") + domain);
  ASSERT_EQ(s1, 0) << js;
  EXPECT_TRUE(contains(js, "name: [puma_joint1, puma_joint2, puma_joint3, puma_joint4, puma_joint5, puma_joint6]\n")) << js;
  EXPECT_TRUE(contains(js, "position: [")) << js;
  std::size_t samples = 0;
  for (std::size_t at = 0; (at = js.find("---\n", at)) != std::string::npos; at += 4) ++samples;
  EXPECT_EQ(samples, 2u) << js;
  // transient-local: a late joiner gets the description
  const auto [rd, s2] = rpDds(std::string("echo ") + options_.nameSpace + std::string("/puma/robot_description -count 1 -time 10") + domain);
  ASSERT_EQ(s2, 0) << rd.substr(0, 500);
  EXPECT_TRUE(contains(rd, "data: <?xml")) << rd.substr(0, 500);
  EXPECT_TRUE(contains(rd, "<joint name=\"puma_joint6\"")) << rd.substr(0, 500);
  const auto [tf, s3] = rpDds(std::string("echo /") + options_.nameSpace + std::string("/tf -count 1 -time 10") + domain);
  ASSERT_EQ(s3, 0) << tf;
  EXPECT_TRUE(contains(tf, "frame_id: world, child_frame_id: puma_tool")) << tf;
}

TEST_F(RpDdsTest, RefusesBadUsageAndSaysWhenNothingCame) {
  EXPECT_EQ(rpDds("").second, 2);
  EXPECT_EQ(rpDds("frobnicate").second, 2);
  EXPECT_EQ(rpDds("echo").second, 2);
  const auto [bad, s] = rpDds("list -domain 300");
  EXPECT_EQ(s, 2);
  EXPECT_TRUE(contains(bad, "-domain")) << bad;
  EXPECT_EQ(rpDds("list -interfaces no$such").second, 2);
  EXPECT_EQ(rpDds("--help").second, 0);
  // no bridge on this domain: nothing to echo
  const auto [none, s2] = rpDds(std::string("echo /") + options_.nameSpace + std::string("/joint_states -time 0.5 -domain ") + std::to_string(options_.domain));
  EXPECT_EQ(s2, 1) << none;
  EXPECT_TRUE(contains(none, std::string("no writer of /") + options_.nameSpace + "/joint_states")) << none;
}

}  // namespace
}  // namespace rp
