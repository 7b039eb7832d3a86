// The Puma 560's closed-form inverse kinematics against the Robotics Toolbox's ikine_a solutions
// (shared/refdata/04_puma560_ikine_a_solutions.txt: all eight configurations of three poses) and
// against forward kinematics on seeded random poses.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <set>
#include <string>

#include "rp/model/Kinematics.hpp"
#include "rp/model/Puma560Model.hpp"

namespace rp {
namespace {

constexpr double kPi = std::numbers::pi;

double angleDistance(double a, double b) { return std::abs(std::remainder(a - b, 2 * kPi)); }

JointVector joints(std::initializer_list<double> v) {
  JointVector q(static_cast<Eigen::Index>(v.size()));
  int i = 0;
  for (double x : v) q(i++) = x;
  return q;
}

void expectSameSet(const std::array<Puma560IkSolution, 8>& ours, const std::vector<JointVector>& toolbox) {
  for (const JointVector& t : toolbox) {
    bool found = false;
    for (const Puma560IkSolution& s : ours) {
      double worst = 0;
      for (int i = 0; i < 6; ++i) worst = std::max(worst, angleDistance(s.q(i), t(i)));
      if (worst < 1e-7) found = true;
    }
    EXPECT_TRUE(found) << "toolbox solution " << Vector<6>(t).transpose() << " not among ours";
  }
}

TEST(Puma560Ik, EightBranchesMatchTheToolbox) {
  Puma560Model model;
  ManipulatorData data(model);
  struct Case {
    JointVector q;
    std::vector<JointVector> toolbox;
  };
  const std::vector<Case> cases = {
      {joints({0, kPi / 4, kPi, 0, kPi / 4, 0}),
       {joints({2.64856121, 2.35619449, 0.09395583, -0.60903322, -0.97434958, -2.76819308}),
        joints({2.64856121, 2.35619449, 0.09395583, 2.53255944, 0.97434958, 0.37339958}),
        joints({2.64856121, -2.30805959, -3.14159265, -2.46732640, -0.86039026, -0.48046800}),
        joints({2.64856121, -2.30805959, -3.14159265, 0.67426625, 0.86039026, 2.66112465}),
        joints({0.00000000, 0.78539816, -3.14159265, -3.14159265, -0.78539816, 3.14159265}),
        joints({0.00000000, 0.78539816, -3.14159265, 0.00000000, 0.78539816, 0.00000000}),
        joints({0.00000000, -0.83353306, 0.09395583, -0.00000000, -0.83121910, -0.00000000}),
        joints({0.00000000, -0.83353306, 0.09395583, 3.14159265, 0.83121910, -3.14159265})}},
      {joints({0.1, 0.2, 0.3, 0.4, 0.5, 0.6}),
       {joints({2.10117673, 1.11634865, 0.30000000, 0.95278670, -1.65052534, -0.98597520}),
        joints({2.10117673, 1.11634865, 0.30000000, -2.18880595, 1.65052534, 2.15561746}),
        joints({2.10117673, 2.94159265, 2.93554849, 1.65264961, -0.95302870, -2.80903623}),
        joints({2.10117673, 2.94159265, 2.93554849, -1.48894304, 0.95302870, 0.33255643}),
        joints({0.10000000, 2.02524400, 2.93554849, -2.89446352, -2.27332828, -2.02470801}),
        joints({0.10000000, 2.02524400, 2.93554849, 0.24712913, 2.27332828, 1.11688464}),
        joints({0.10000000, 0.20000000, 0.30000000, -2.74159265, -0.50000000, -2.54159265}),
        joints({0.10000000, 0.20000000, 0.30000000, 0.40000000, 0.50000000, 0.60000000})}},
      {joints({0.5, -0.7, 1.2, -0.3, 0.8, 1.5}),
       {joints({2.00903704, 1.11256682, 1.20000000, 1.46075613, -1.88024174, 0.48223087}),
        joints({2.00903704, 1.11256682, 1.20000000, -1.68083652, 1.88024174, -2.65936178}),
        joints({2.00903704, -2.44159265, 2.03554849, 1.53951972, -1.24440273, -2.21404985}),
        joints({2.00903704, -2.44159265, 2.03554849, -1.60207293, 1.24440273, 0.92754280}),
        joints({0.50000000, 2.02902583, 2.03554849, 0.55893772, -2.73032503, 1.80829764}),
        joints({0.50000000, 2.02902583, 2.03554849, -2.58265493, 2.73032503, -1.33329502}),
        joints({0.50000000, -0.70000000, 1.20000000, 2.84159265, -0.80000000, -1.64159265}),
        joints({0.50000000, -0.70000000, 1.20000000, -0.30000000, 0.80000000, 1.50000000})}},
  };
  for (const Case& c : cases) {
    const Transform T = forwardKinematics(model, data, c.q);
    std::array<Puma560IkSolution, 8> ours;
    ASSERT_EQ(model.inverseKinematicsAll(T, ours), IkStatus::Solved);
    expectSameSet(ours, c.toolbox);
    for (const Puma560IkSolution& s : ours) {
      const Transform back = forwardKinematics(model, data, s.q);
      EXPECT_LT((back - T).cwiseAbs().maxCoeff(), 1e-10) << s.branchName();
    }
  }
}

// Random joint angles with |q5| in [0.05, pi - 0.05] (off the wrist singularity), its sign alternating.
JointVector randomOffWristSingularity(std::mt19937_64& rng, int trial) {
  std::uniform_real_distribution<double> u(-kPi, kPi);
  JointVector q(6);
  for (int i = 0; i < 6; ++i) q(i) = u(rng);
  q(4) = std::uniform_real_distribution<double>(0.05, kPi - 0.05)(rng) * (trial % 2 ? 1 : -1);
  return q;
}

TEST(Puma560Ik, EveryBranchReproducesRandomPosesAndTheClosestIsChosen) {
  Puma560Model model;
  ManipulatorData data(model);
  std::mt19937_64 rng(99);
  int withinLimits = 0;
  for (int trial = 0; trial < 1000; ++trial) {
    const JointVector q = randomOffWristSingularity(rng, trial);
    const Transform T = forwardKinematics(model, data, q);
    std::array<Puma560IkSolution, 8> all;
    ASSERT_EQ(model.inverseKinematicsAll(T, all), IkStatus::Solved);
    for (const Puma560IkSolution& s : all) {
      ASSERT_LT((forwardKinematics(model, data, s.q) - T).cwiseAbs().maxCoeff(), 1e-10) << s.branchName();
      withinLimits += s.withinLimits;
    }
    if (model.isWithinLimits(q)) {
      JointVector closest(6);
      ASSERT_EQ(model.inverseKinematicsClosest(T, q, closest), IkStatus::Solved);
      for (int i = 0; i < 6; ++i) EXPECT_LT(angleDistance(closest(i), q(i)), 1e-8) << "the original is the closest";
    }
  }
  EXPECT_GT(withinLimits, 0);
}

TEST(Puma560Ik, BranchOfEachSolutionIsItsLabel) {
  // For each of the eight solutions of 2,000 random poses, branchOf() names the branch that
  // inverseKinematicsAll() labelled it with; the eight labels of a pose are all different.
  Puma560Model model;
  ManipulatorData data(model);
  std::mt19937_64 rng(123);
  int checked = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const JointVector q = randomOffWristSingularity(rng, trial);
    const Transform T = forwardKinematics(model, data, q);
    std::array<Puma560IkSolution, 8> all;
    ASSERT_EQ(model.inverseKinematicsAll(T, all), IkStatus::Solved);
    std::set<std::string> names;
    for (const Puma560IkSolution& s : all) {
      const Puma560IkSolution b = model.branchOf(s.q);
      EXPECT_STREQ(b.branchName(), s.branchName()) << "trial " << trial;
      EXPECT_EQ(b.withinLimits, s.withinLimits);
      names.insert(s.branchName());
      ++checked;
    }
    EXPECT_EQ(names.size(), 8u);
    // The configuration the pose came from is the solution labelled with its branch.
    const std::string original = model.branchOf(q).branchName();
    for (const Puma560IkSolution& s : all) {
      if (original != s.branchName()) continue;
      for (int i = 0; i < 6; ++i) EXPECT_LT(angleDistance(s.q(i), q(i)), 1e-8) << original << " joint " << i + 1;
    }
  }
  EXPECT_EQ(checked, 16000);
}

TEST(Puma560Ik, UnreachablePosesSaySoWithoutNaNs) {
  Puma560Model model;
  std::array<Puma560IkSolution, 8> all;
  EXPECT_EQ(model.inverseKinematicsAll(translation(2.0, 0, 0.7), all), IkStatus::Unreachable);
  EXPECT_EQ(model.inverseKinematicsAll(translation(0, 0, 3.0), all), IkStatus::Unreachable);
  JointVector q(6);
  EXPECT_EQ(model.inverseKinematicsClosest(translation(2.0, 0, 0.7), model.getHomePosition(), q), IkStatus::Unreachable);
}

}  // namespace
}  // namespace rp
