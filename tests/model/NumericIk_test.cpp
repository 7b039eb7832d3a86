// Numeric inverse kinematics on seeded random reachable poses (forward kinematics of random joint
// vectors within the limits), each solved from a random seed: solve rate and accuracy.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <stdexcept>

#include "rp/model/InverseKinematics.hpp"
#include "rp/model/Kinematics.hpp"
#include "ModifiedDh.hpp"
#include "PrismaticDhArm.hpp"
#include "rp/model/Puma560Model.hpp"
#include "rp/model/UrdfModel.hpp"
#include "rp/model/WAMModel.hpp"

namespace rp {
namespace {

JointVector randomWithin(const ManipulatorModel& m, std::mt19937_64& rng) {
  JointVector q(m.getNumberOfJoints());
  for (int i = 0; i < m.getNumberOfJoints(); ++i)
    q(i) = std::uniform_real_distribution<double>(m.getPositionMin()(i), m.getPositionMax()(i))(rng);
  return q;
}

double solveRate(const ManipulatorModel& model, int count, bool positionOnly, IkOptions options = IkOptions()) {
  ManipulatorData data(model);
  std::mt19937_64 rng(31337);
  int solved = 0;
  options.positionOnly = positionOnly;
  for (int k = 0; k < count; ++k) {
    const Transform target = forwardKinematics(model, data, randomWithin(model, rng));
    const JointVector seed = randomWithin(model, rng);
    JointVector q(model.getNumberOfJoints());
    options.randomSeed = static_cast<std::uint64_t>(k + 1);
    if (inverseKinematics(model, data, target, seed, q, options) == IkStatus::Solved) {
      ++solved;
      EXPECT_TRUE(model.isWithinLimits(q));
      const Transform back = forwardKinematics(model, data, q);
      EXPECT_LT((back.topRightCorner<3, 1>() - target.topRightCorner<3, 1>()).norm(), 1e-6);
      if (!positionOnly) {
        EXPECT_LT((back.topLeftCorner<3, 3>() - target.topLeftCorner<3, 3>()).norm(), 1e-5);
      }
    }
  }
  return static_cast<double>(solved) / count;
}

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
constexpr int kPoses = 500;  // the sanitizers make every iteration several times slower
#else
constexpr int kPoses = 10000;
#endif

TEST(NumericIk, Wam7SolvesReachablePoses) {
  const double rate = solveRate(WAM7Model(), kPoses, false);
  RecordProperty("solve_rate", std::to_string(rate));
  std::cout << "WAM 7 full-pose solve rate over " << kPoses << " poses: " << rate << std::endl;
  EXPECT_GE(rate, 0.995);
}

// Issue 19/20: a target that is not a rigid transform is refused; a rotation block of zeros used
// to be reported as Solved.
TEST(NumericIk, TargetsThatAreNotRigidTransformsAreRefused) {
  const WAM7Model wam;
  ManipulatorData data(wam);
  JointVector q(7);
  JointVector goal(7);
  goal << 0.3, 0.4, 0.2, 1.1, 0.3, -0.5, 0.7;
  ASSERT_TRUE(wam.isWithinLimits(goal));
  const Transform reachable = forwardKinematics(wam, data, goal);
  auto message = [&](const Transform& target) -> std::string {
    try {
      (void)inverseKinematics(wam, data, target, wam.getHomePosition(), q);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "accepted";
  };
  Transform zeros = reachable;
  zeros.topLeftCorner<3, 3>().setZero();
  EXPECT_EQ(message(zeros),
            "inverseKinematics: the target pose has a rotation block that is not orthonormal (R^T R differs from I by 1; "
            "at most 0.001)");
  Transform twice = reachable;
  twice.topLeftCorner<3, 3>() = 2 * Eigen::Matrix3d::Identity();
  EXPECT_EQ(message(twice),
            "inverseKinematics: the target pose has a rotation block that is not orthonormal (R^T R differs from I by 3; "
            "at most 0.001)");
  Transform mirrored = reachable;
  mirrored.block<3, 1>(0, 2) *= -1;
  EXPECT_EQ(message(mirrored),
            "inverseKinematics: the target pose has a rotation block that is a reflection (determinant -1), not a rotation");
  Transform lastRow = reachable;
  lastRow(3, 2) = 1;
  EXPECT_EQ(message(lastRow), "inverseKinematics: the target pose has a last row other than 0 0 0 1");
  Transform notFinite = reachable;
  notFinite(1, 3) = std::nan("");
  EXPECT_EQ(message(notFinite), "inverseKinematics: the target pose has an element that is not a finite number");
  EXPECT_EQ(message(reachable), "accepted");
  // A rotation typed with four decimals is close enough, and solved to its nearest rotation.
  Transform typed = reachable;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) typed(r, c) = std::round(reachable(r, c) * 1e4) / 1e4;
  EXPECT_EQ(rigidTransformError(typed), "");
  EXPECT_EQ(inverseKinematics(wam, data, typed, wam.getHomePosition(), q), IkStatus::Solved);
  EXPECT_NE(rigidTransformError(zeros), "");
  EXPECT_EQ(rigidTransformError(Transform::unit()), "");
}

TEST(NumericIk, Wam4PositionOnlyAndPuma) {
  const double wam4 = solveRate(WAM4Model(), kPoses / 10, true);
  const double puma = solveRate(Puma560Model(), kPoses / 10, false);
  std::cout << "WAM 4 position-only: " << wam4 << ", Puma 560 full pose: " << puma << std::endl;
  EXPECT_GE(wam4, 0.995);
  // The Puma's programs use its closed-form solver; the numeric one needs the default 100
  // attempts for poses next to the joint limits (98.2 % of these 1,000 with 20 attempts).
  EXPECT_GE(puma, 0.995);
}

TEST(NumericIk, PrismaticArmsInBothConventions) {
  UrdfOptions o;
  o.tip = "tool";
  const std::unique_ptr<ManipulatorModel> arm = loadUrdf(std::string(RP_TEST_DATA_DIR) + "/prismatic_arm.urdf", o);
  const double placement = solveRate(*arm, kPoses / 10, false);
  const double standard = solveRate(*test::prismaticDhArm(), kPoses / 10, false);
  const double modified = solveRate(*test::toModifiedDh(*test::prismaticDhArm()), kPoses / 10, false);
  std::cout << "prismatic arm from URDF full pose: " << placement << std::endl;
  EXPECT_GE(placement, 0.995);
  std::cout << "prismatic arm full pose: " << standard << " (standard DH), " << modified << " (modified DH)" << std::endl;
  EXPECT_GE(standard, 0.995);
  EXPECT_GE(modified, 0.995);
}

TEST(NumericIk, TimeBudgetRestartsUntilSolved) {
  // With a time budget the restarts are not limited by maxAttempts: one attempt alone solves
  // fewer poses than the budget does.
  const WAM7Model wam;
  IkOptions single;
  single.maxAttempts = 1;
  IkOptions budget = single;
  budget.timeBudget = 0.05;
  const double one = solveRate(wam, kPoses / 5, false, single);
  const double timed = solveRate(wam, kPoses / 5, false, budget);
  std::cout << "WAM 7, one attempt: " << one << ", 50 ms budget: " << timed << std::endl;
  EXPECT_GT(timed, one);
  EXPECT_GE(timed, 0.995);
  // An unreachable pose ends when the budget is spent, with the best attempt and no NaNs.
  ManipulatorData data(wam);
  JointVector q(7);
  budget.timeBudget = 0.01;
  EXPECT_EQ(inverseKinematics(wam, data, translation(3.0, 0, 0), wam.getHomePosition(), q, budget),
            IkStatus::NotConverged);
  EXPECT_TRUE(q.allFinite());
  EXPECT_TRUE(wam.isWithinLimits(q));
  EXPECT_THROW(inverseKinematics(wam, data, translation(0.5, 0, 0), JointVector(6), q), std::invalid_argument);
}

}  // namespace
}  // namespace rp
