// rp-plan as a user runs it: the exit status, the JSON it prints (parsed and checked against the
// library's plan: duration, samples within the limits, the end exactly on the target), and bad
// arguments (exit 2, one line on stderr naming the argument).
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <unistd.h>

#include "rp/trajectory/SynchronizedJointMotion.hpp"

namespace rp {
namespace {

struct Outcome {
  int status = -1;
  std::string out, err;
};

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

Outcome runPlan(const std::string& args) {
  const std::string base = ::testing::TempDir() + "rp_plan_" + std::to_string(::getpid());
  const std::string command = std::string("'") + RP_PLAN_PROGRAM + "' " + args + " >" + base + ".out 2>" + base + ".err";
  const int raw = std::system(command.c_str());
  Outcome r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  r.out = slurp(base + ".out");
  r.err = slurp(base + ".err");
  std::remove((base + ".out").c_str());
  std::remove((base + ".err").c_str());
  return r;
}

const char* kStart = "0.1,-0.5,1.2,0,0.3,-1,2";
const char* kTarget = "1.4,0.7,-0.4,0.9,-0.8,0.2,0.5";
const char* kVmax = "0.6,3,3,3,3,3,3";
const char* kAmax = "20,20,20,20,20,1.5,20";
const char* kJmax = "200,200,200,200,200,200,20";

JointVector vec(const std::string& text) {
  std::stringstream ss(text);
  std::string item;
  JointVector v(0);
  std::vector<double> values;
  while (std::getline(ss, item, ',')) values.push_back(std::stod(item));
  v = JointVector(static_cast<Eigen::Index>(values.size()));
  for (std::size_t i = 0; i < values.size(); ++i) v(static_cast<Eigen::Index>(i)) = values[i];
  return v;
}

std::string problem() {
  return std::string("--start ") + kStart + " --target " + kTarget + " --vmax " + kVmax + " --amax " + kAmax +
         " --jmax " + kJmax;
}

TEST(RpPlan, PrintsTheDurationAndTheSamplesAsJson) {
  const Outcome r = runPlan(problem() + " --rate 500");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  const nlohmann::json out = nlohmann::json::parse(r.out);
  const JointVector start = vec(kStart), target = vec(kTarget), v = vec(kVmax), a = vec(kAmax), j = vec(kJmax);
  const SynchronizedJointMotion expected(start, target, v, a, j, Synchronization::Time);
  EXPECT_EQ(out.at("sync"), "time") << "the default";
  EXPECT_EQ(out.at("joints"), 7);
  const double T = out.at("duration").get<double>();
  EXPECT_NEAR(T, expected.getDuration(), 1e-12);
  for (int i = 0; i < 7; ++i) EXPECT_NEAR(out.at("durations").at(i).get<double>(), T, 1e-12) << "ends together";
  const auto& time = out.at("time");
  const auto& q = out.at("q");
  const auto& qd = out.at("qd");
  const auto& qdd = out.at("qdd");
  const std::size_t n = time.size();
  ASSERT_EQ(n, static_cast<std::size_t>(std::ceil(T * 500)) + 1);
  ASSERT_EQ(q.size(), n);
  ASSERT_EQ(qd.size(), n);
  ASSERT_EQ(qdd.size(), n);
  EXPECT_EQ(time.at(0).get<double>(), 0.0);
  EXPECT_EQ(time.at(n - 1).get<double>(), T);
  for (std::size_t k = 0; k < n; ++k) {
    ASSERT_EQ(q.at(k).size(), 7u);
    for (int i = 0; i < 7; ++i) {
      ASSERT_LE(std::abs(qd.at(k).at(i).get<double>()), v(i) * (1 + 1e-9));
      ASSERT_LE(std::abs(qdd.at(k).at(i).get<double>()), a(i) * (1 + 1e-9));
    }
  }
  for (int i = 0; i < 7; ++i) {
    EXPECT_EQ(q.at(0).at(i).get<double>(), start(i));
    EXPECT_EQ(q.at(n - 1).at(i).get<double>(), target(i));
    EXPECT_EQ(qd.at(n - 1).at(i).get<double>(), 0.0);
    EXPECT_EQ(qdd.at(n - 1).at(i).get<double>(), 0.0);
  }
}

TEST(RpPlan, SyncModesAndNoSamplesWithoutARate) {
  const Outcome timed = runPlan(problem() + " --sync time");
  const Outcome phase = runPlan(problem() + " --sync phase");
  const Outcome none = runPlan(problem() + " --sync none");
  ASSERT_EQ(timed.status, 0) << timed.err;
  ASSERT_EQ(phase.status, 0) << phase.err;
  ASSERT_EQ(none.status, 0) << none.err;
  const nlohmann::json t = nlohmann::json::parse(timed.out), p = nlohmann::json::parse(phase.out),
                       o = nlohmann::json::parse(none.out);
  EXPECT_FALSE(t.contains("q"));
  EXPECT_EQ(p.at("sync"), "phase");
  EXPECT_EQ(o.at("sync"), "none");
  // Joint 1 limited by its velocity, joint 6 by its acceleration, joint 7 by its jerk: no
  // straight line lets each reach its own limits (2.630 s against 2.276 s).
  EXPECT_GT(p.at("duration").get<double>(), 1.1 * t.at("duration").get<double>());
  EXPECT_EQ(o.at("duration").get<double>(), t.at("duration").get<double>());
  int shorter = 0;
  for (int i = 0; i < 7; ++i) shorter += o.at("durations").at(i).get<double>() < t.at("duration").get<double>() ? 1 : 0;
  EXPECT_GT(shorter, 0) << "without synchronisation most joints arrive early";
}

TEST(RpPlan, BadArgumentsExitTwoNamingTheArgument) {
  const std::string limits = std::string(" --vmax 1 --amax 1 --jmax 1");
  const struct {
    std::string args, named;
  } cases[] = {
      {"--start 0,0 --target 1,1 --amax 1 --jmax 1", "--vmax"},
      {"--target 1,1" + limits, "--start"},
      {"--start 0,x --target 1,1" + limits, "--start"},
      {"--start 0,0 --target 1,1,1" + limits, "--target"},
      {"--start 0,0 --target 1,nan" + limits, "--target"},
      {"--start 0,0 --target 1,1 --vmax 1 --amax 0 --jmax 1", "--amax"},
      {"--start 0,0 --target 1,1 --vmax 1 --amax 1 --jmax 1,2,3", "--jmax"},
      {"--start 0,0 --target 1,1" + limits + " --sync fast", "--sync"},
      {"--start 0,0 --target 1,1" + limits + " --rate -5", "--rate"},
      {"--start 0,0 --target 1,1" + limits + " --rate 1e9", "--rate"},
      {"--start 0,0 --target 1,1" + limits + " --bogus 3", "--bogus"},
      {"--start 0,0 --target 1,1" + limits + " --rate", "--rate"},
  };
  for (const auto& c : cases) {
    const Outcome r = runPlan(c.args);
    EXPECT_EQ(r.status, 2) << c.args;
    EXPECT_EQ(r.out, "") << c.args;
    EXPECT_NE(r.err.find(c.named), std::string::npos) << c.args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << c.args << ": " << r.err;
  }
}

}  // namespace
}  // namespace rp
