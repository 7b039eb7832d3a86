// Two hosts on one machine: the test makes two network namespaces joined by a veth pair (as two
// computers on one cable) with `ip`, runs a simulated Puma with a Ros2Bridge restricted to its
// end of the pair in one namespace (ros2_arm), and rp-dds, or a program driving the arm as a
// RemoteManipulator (trajectories over the link) or the paper's Figure 21 with its Puma560 wired to
// the arm by rp.cfg (Ros2IoBoard: torques over the link), in the other; DDS finds the bridge across the
// pair only. Without the privilege to make namespaces (CAP_NET_ADMIN, e.g. not root) every case is
// skipped with a message saying so.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "RunProgram.hpp"
#include "ScratchDirectory.hpp"
#include "rp/model/Kinematics.hpp"
#include "rp/model/ManipulatorData.hpp"
#include "rp/model/Puma560Model.hpp"

namespace {

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

using rp::test::numbersAfter;
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
  // ros2_arm in namespace a_, its bridge on its end of the pair, for 120 s with `args` after that;
  // null (a failure recorded) if it did not say "ready".
  FILE* startArmInA(const std::string& args) {
    FILE* arm = popen(("ip netns exec " + a_ + " " + RP_ROS2_ARM_PATH + " " + domain_ + " " + ns_ + " " + ifA_ + " 120 " + args +
                       " 2>&1").c_str(), "r");
    if (arm == nullptr) return nullptr;
    char line[4096] = "";
    const bool ready = std::fgets(line, sizeof line, arm) != nullptr && std::string(line) == "ready\n";
    EXPECT_TRUE(ready) << line;
    if (!ready) pclose(arm);
    return ready ? arm : nullptr;
  }
  // The arm's output until it ends; its exit status checked.
  static std::string finishArm(FILE* arm) {
    char line[4096];
    std::string rest;
    while (std::fgets(line, sizeof line, arm)) rest += line;
    const int armStatus = pclose(arm);
    EXPECT_TRUE(WIFEXITED(armStatus) && WEXITSTATUS(armStatus) == 0) << rest;
    return rest;
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

// The other host drives the arm: Figure 21's motions as a program whose [leader] is a
// RemoteManipulator on its end of the pair (joint states in, trajectories out, over the link).
// With the RemoteManipulator on the other host's loopback instead, the test fails (no robot
// description within 30 s).
TEST_F(TwoHosts, ARemoteManipulatorOnTheOtherHostDrivesTheArmOverTheLink) {
  if (!skip_.empty()) GTEST_SKIP() << skip_;
  rp::test::ScratchDirectory dir("rp_two_hosts_", "remote");
  const std::string stop = (dir.path() / "stop").string(), config = (dir.path() / "remote.cfg").string();
  std::ofstream(config) << "[leader]\nclass RemoteManipulator\nremote " << ns_ << "/puma\ndomain " << domain_
                        << "\ninterfaces " << ifB_ << "\nconnectTimeout 30\n";
  FILE* arm = startArmInA("commands " + stop);
  ASSERT_NE(arm, nullptr);
  // `timeout`: a hang ends as a failure (status 137) rather than blocking the suite.
  const auto [out, status] = runMerged("cd " + dir.path().string() + " && ip netns exec " + b_ +
                                       " timeout -s KILL 120 " + REMOTE_MOTION_PATH + " -config " + config + " -nogui");
  EXPECT_EQ(status, 0) << out;
  std::ofstream(stop) << "stop\n";
  const std::string rest = finishArm(arm);
  const std::vector<double> seen = numbersAfter(out, "final"), actual = numbersAfter(rest, "final");
  ASSERT_EQ(seen.size(), 6u) << out;
  ASSERT_EQ(actual.size(), 6u) << rest;
  // The program on the other host read the arm's final position over the link, and the arm ended
  // where the same program ends a local Puma (joints 1 to 3: the wrist may differ by a flip, see
  // RemoteManipulator_test.cpp), so it followed the trajectories sent over the link.
  for (std::size_t i = 0; i < 6; ++i) EXPECT_NEAR(seen[i], actual[i], 1e-3) << "joint " << i + 1 << "\n" << out;
  const std::string localConfig = (dir.path() / "local.cfg").string();
  std::ofstream(localConfig) << "[leader]\nclass Puma560\n";
  const auto [localOut, localStatus] =
      runMerged("cd " + dir.path().string() + " && timeout -s KILL 120 " + REMOTE_MOTION_PATH + " -config " + localConfig + " -nogui");
  ASSERT_EQ(localStatus, 0) << localOut;
  const std::vector<double> local = numbersAfter(localOut, "final");
  ASSERT_EQ(local.size(), 6u) << localOut;
  for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(actual[i], local[i], 5e-3) << "joint " << i + 1;
}

// The paper's Figure 21 unchanged on the other host, its Puma560 wired by rp.cfg to the arm over
// the link (Ros2IoBoard): the program's servo loop drives the arm by torque across the pair.
TEST_F(TwoHosts, FigureTwentyOneOnTheOtherHostDrivesTheArmByTorqueOverTheLink) {
  if (!skip_.empty()) GTEST_SKIP() << skip_;
  rp::test::ScratchDirectory dir("rp_two_hosts_", "torque");
  const std::string stop = (dir.path() / "stop").string(), config = (dir.path() / "remote.cfg").string();
  std::ofstream(config) << "[Puma560]\nclass Puma560\nsimulationMode off\nremote " << ns_ << "/puma\ndomain " << domain_
                        << "\ninterfaces " << ifB_ << "\nconnectTimeout 30\n";
  FILE* arm = startArmInA("commands " + stop + " servo");
  ASSERT_NE(arm, nullptr);
  const auto [out, status] = runMerged("cd " + dir.path().string() + " && ip netns exec " + b_ +
                                       " timeout -s KILL 120 " + PICK_AND_PLACE_PATH + " -config " + config + " -nogui");
  std::ofstream(stop) << "stop\n";
  const std::string rest = finishArm(arm);
  EXPECT_FALSE(contains(rest, "error")) << rest;
  EXPECT_EQ(status, 0) << out;
  const std::vector<double> q = numbersAfter(rest, "final"), seen = numbersAfter(out, "end-effector at");
  ASSERT_EQ(q.size(), 6u) << "the arm did not come to rest:\n" << rest;
  ASSERT_EQ(seen.size(), 3u) << out;
  // Where the task put the end-effector (Figure 21's drop point, 0.6 0.2 0.3 m), read over the
  // link, is where the arm's own joints put it.
  rp::Puma560Model puma;
  rp::ManipulatorData data(puma);
  rp::JointVector rq(6);
  for (int i = 0; i < 6; ++i) rq(i) = q[static_cast<std::size_t>(i)];
  const rp::Transform t = rp::forwardKinematics(puma, data, rq);
  const double drop[3] = {0.6, 0.2, 0.3};
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(t(i, 3), seen[static_cast<std::size_t>(i)], 1e-3) << i << "\n" << out;
    EXPECT_NEAR(t(i, 3), drop[i], 3e-3) << i << "\n" << out;
  }
}

TEST_F(TwoHosts, ABridgeOnAnInterfaceItsHostLacksIsAnErrorNamingIt) {
  if (!skip_.empty()) GTEST_SKIP() << skip_;
  // ifB_ is in the other namespace: the arm's host has no such interface.
  const auto [out, status] = runMerged("ip netns exec " + a_ + " " + RP_ROS2_ARM_PATH + " " + domain_ + " " + ns_ + " " + ifB_ + " 1");
  EXPECT_EQ(status, 1) << out;
  EXPECT_TRUE(contains(out, ifB_)) << out;
}

}  // namespace
