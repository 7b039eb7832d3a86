// Two hosts on one machine: the test makes two network namespaces joined by a veth pair (as two
// computers on one cable) with `ip`, runs a simulated Puma with a Ros2Bridge restricted to its
// end of the pair in one namespace (ros2_arm), and rp-dds in the other; DDS finds the bridge across
// the pair only. Without the privilege to make namespaces (CAP_NET_ADMIN, e.g. not root) every
// case is skipped with a message saying so.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "RunProgram.hpp"

namespace {

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

using rp::test::runMerged;

class TwoHosts : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string id = std::to_string(getpid());
    a_ = "rpA" + id, b_ = "rpB" + id, ifA_ = "rpvA" + id, ifB_ = "rpvB" + id;
    const auto [out, status] = runMerged("ip netns add " + a_);
    if (status != 0) {
      skip_ = "cannot make a network namespace (`ip netns add` needs CAP_NET_ADMIN): " + out;
      return;
    }
    made_ = true;
    for (const std::string& c :
         {"ip netns add " + b_, "ip link add " + ifA_ + " netns " + a_ + " type veth peer name " + ifB_ + " netns " + b_,
          "ip -n " + a_ + " addr add 10.213.0.1/24 dev " + ifA_, "ip -n " + b_ + " addr add 10.213.0.2/24 dev " + ifB_,
          "ip -n " + a_ + " link set lo up", "ip -n " + b_ + " link set lo up", "ip -n " + a_ + " link set " + ifA_ + " up",
          "ip -n " + b_ + " link set " + ifB_ + " up"}) {
      const auto [o, s] = runMerged(c);
      ASSERT_EQ(s, 0) << c << ": " << o;
    }
    domain_ = std::to_string(1 + getpid() % 200);
    ns_ = "h" + id;
  }
  void TearDown() override {
    if (!made_) return;
    runMerged("ip netns del " + a_);  // takes its end of the pair, and so the pair, with it
    runMerged("ip netns del " + b_);
  }
  // rp-dds in namespace b_ with `args`.
  std::pair<std::string, int> rpDdsInB(const std::string& args) {
    return runMerged("ip netns exec " + b_ + " " + RP_DDS_PATH + " " + args + " -domain " + domain_);
  }
  std::string skip_;
  bool made_ = false;
  std::string a_, b_, ifA_, ifB_, domain_, ns_;
};

TEST_F(TwoHosts, AReaderOnTheOtherHostGetsTheArmOverTheLinkOnly) {
  if (!skip_.empty()) GTEST_SKIP() << skip_;
  // The arm's host: a bridge on its end of the pair only, for 12 s.
  FILE* arm = popen(("ip netns exec " + a_ + " " + RP_ROS2_ARM_PATH + " " + domain_ + " " + ns_ + " " + ifA_ + " 12 2>&1").c_str(), "r");
  ASSERT_NE(arm, nullptr);
  char line[4096] = "";
  ASSERT_NE(std::fgets(line, sizeof line, arm), nullptr);
  ASSERT_EQ(std::string(line), "ready\n");
  // The other host, over the link: joint states and, as a late joiner, the robot description.
  const auto [js, s1] = rpDdsInB("echo /" + ns_ + "/joint_states -count 3 -time 8 -interfaces " + ifB_);
  EXPECT_EQ(s1, 0) << js;
  EXPECT_TRUE(contains(js, "name: [puma_joint1, puma_joint2, puma_joint3, puma_joint4, puma_joint5, puma_joint6]\n")) << js;
  const auto [rd, s2] = rpDdsInB("echo /" + ns_ + "/puma/robot_description -count 1 -time 8 -interfaces " + ifB_);
  EXPECT_EQ(s2, 0) << rd.substr(0, 300);
  EXPECT_TRUE(contains(rd, "<joint name=\"puma_joint6\"")) << rd.substr(0, 300);
  // The other host's loopback is another network: nothing comes there.
  const auto [none, s3] = rpDdsInB("echo /" + ns_ + "/joint_states -count 1 -time 2 -interfaces lo");
  EXPECT_EQ(s3, 1) << none;
  std::string rest;
  while (std::fgets(line, sizeof line, arm)) rest += line;
  const int status = pclose(arm);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << rest;
}

TEST_F(TwoHosts, ABridgeOnAnInterfaceItsHostLacksIsAnErrorNamingIt) {
  if (!skip_.empty()) GTEST_SKIP() << skip_;
  // ifB_ is in the other namespace: the arm's host has no such interface.
  const auto [out, status] = runMerged("ip netns exec " + a_ + " " + RP_ROS2_ARM_PATH + " " + domain_ + " " + ns_ + " " + ifB_ + " 1");
  EXPECT_EQ(status, 1) << out;
  EXPECT_TRUE(contains(out, ifB_)) << out;
}

}  // namespace
