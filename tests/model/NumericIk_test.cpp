// Numeric inverse kinematics on seeded random reachable poses (forward kinematics of random joint
// vectors within the limits), each solved from a random seed: solve rate and accuracy.
#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "rp/model/InverseKinematics.hpp"
#include "rp/model/Kinematics.hpp"
#include "rp/model/Puma560Model.hpp"
#include "rp/model/WAMModel.hpp"

namespace rp {
namespace {

JointVector randomWithin(const ManipulatorModel& m, std::mt19937_64& rng) {
  JointVector q(m.getNumberOfJoints());
  for (int i = 0; i < m.getNumberOfJoints(); ++i)
    q(i) = std::uniform_real_distribution<double>(m.getPositionMin()(i), m.getPositionMax()(i))(rng);
  return q;
}

double solveRate(const ManipulatorModel& model, int count, bool positionOnly) {
  ManipulatorData data(model);
  std::mt19937_64 rng(31337);
  int solved = 0;
  IkOptions options;
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

TEST(NumericIk, Wam4PositionOnlyAndPuma) {
  const double wam4 = solveRate(WAM4Model(), kPoses / 10, true);
  const double puma = solveRate(Puma560Model(), kPoses / 10, false);
  std::cout << "WAM 4 position-only: " << wam4 << ", Puma 560 full pose: " << puma << std::endl;
  EXPECT_GE(wam4, 0.995);
  // The Puma's programs use its closed-form solver; the numeric one, measured at 98.3 % on these
  // 1,000 poses, misses some poses next to the joint limits with the default 20 attempts.
  EXPECT_GE(puma, 0.97);
}

}  // namespace
}  // namespace rp
