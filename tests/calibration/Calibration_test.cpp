// The identification behind rp-calibrate, checked directly: the gravity regressor against the
// library's gravityTorque() (which tests/model checks against Orocos KDL) and against central
// differences of gravityTorque() in each parameter, on standard-DH, modified-DH and prismatic
// arms; the base parameters; the plan's limits; and the fit on synthetic torques.
#include <gtest/gtest.h>

#include <random>

#include "Calibration.hpp"
#include "ModifiedDh.hpp"
#include "PrismaticDhArm.hpp"
#include "rp/model/Model.hpp"

namespace rp::calibration {
namespace {

JointVector randomPose(const ManipulatorModel& model, std::mt19937& rng) {
  JointVector q(model.getNumberOfJoints());
  for (int j = 0; j < q.size(); ++j) {
    const double lo = std::max(model.getPositionMin()(j), -M_PI), hi = std::min(model.getPositionMax()(j), M_PI);
    q(j) = std::uniform_real_distribution<double>(lo, hi)(rng);
  }
  return q;
}

// `model` with standard gravity parameters `theta` (masses and centres of mass).
std::unique_ptr<ManipulatorModel> withParameters(const ManipulatorModel& model, const Eigen::VectorXd& theta) {
  std::vector<LinkParameters> links;
  for (int k = 0; k < model.getNumberOfJoints(); ++k) {
    LinkParameters l = model.getLink(k);
    l.mass = theta(4 * k);
    if (l.mass > 0) l.com = Vector<3>(Eigen::Vector3d(theta.segment<3>(4 * k + 1) / l.mass));
    links.push_back(l);
  }
  return std::make_unique<ManipulatorModel>(model.getName(), links, model.getBaseTransform(), model.getToolTransform(),
                                            model.getGravity(), model.getConvention());
}

// A WAM 7 on a tilted, shifted base with gravity off the vertical: every column of the regressor
// in play.
std::unique_ptr<ManipulatorModel> tiltedWam() {
  WAM7Model wam;
  std::vector<LinkParameters> links;
  for (int k = 0; k < wam.getNumberOfJoints(); ++k) links.push_back(wam.getLink(k));
  Transform base = Transform(xRotation(0.3) * yRotation(-0.2));
  base(0, 3) = 0.2;
  base(2, 3) = 0.5;
  Vector<3> g;
  g = 0.5, -0.3, -9.7;
  return std::make_unique<ManipulatorModel>("tilted_wam", links, base, wam.getToolTransform(), g);
}

void expectRegressorExact(const ManipulatorModel& model) {
  ManipulatorData data(model);
  std::mt19937 rng(7);
  Eigen::MatrixXd Y;
  const int n = model.getNumberOfJoints();
  JointVector tau(n);
  const Eigen::VectorXd theta = gravityParameters(model);
  for (int s = 0; s < 50; ++s) {
    const JointVector q = randomPose(model, rng);
    gravityRegressor(model, data, q, Y);
    gravityTorque(model, data, q, tau);
    const Eigen::VectorXd predicted = Y * theta;
    for (int i = 0; i < n; ++i)
      EXPECT_NEAR(predicted(i), tau(i), 1e-11 * (1 + std::abs(tau(i)))) << model.getName() << " joint " << i + 1;
  }
}

// Central differences of gravityTorque() in each standard parameter (masses moved by 1e-3 kg,
// moments by 1e-4 kg m about the model's values; exact up to rounding since the torque is linear
// in them).
void expectRegressorMatchesDifferences(const ManipulatorModel& model) {
  ManipulatorData data(model);
  std::mt19937 rng(11);
  const int n = model.getNumberOfJoints();
  const Eigen::VectorXd theta = gravityParameters(model);
  Eigen::MatrixXd Y;
  for (int s = 0; s < 5; ++s) {
    const JointVector q = randomPose(model, rng);
    gravityRegressor(model, data, q, Y);
    for (int k = 0; k < 4 * n; ++k) {
      const double h = k % 4 == 0 ? 1e-3 : 1e-4;
      Eigen::VectorXd plus = theta, minus = theta;
      plus(k) += h;
      minus(k) -= h;
      if (theta(k - k % 4) < 2 * h) {  // a massless link: give it mass first
        plus(k - k % 4) += 1;
        minus(k - k % 4) += 1;
      }
      const auto mp = withParameters(model, plus), mm = withParameters(model, minus);
      ManipulatorData dp(*mp), dm(*mm);
      JointVector tp(n), tm(n);
      gravityTorque(*mp, dp, q, tp);
      gravityTorque(*mm, dm, q, tm);
      for (int i = 0; i < n; ++i)
        EXPECT_NEAR((tp(i) - tm(i)) / (2 * h), Y(i, k), 1e-7) << model.getName() << " " << gravityParameterName(k)
                                                              << " joint " << i + 1;
    }
  }
}

TEST(GravityRegressor, TimesTheParametersIsTheGravityTorque) {
  Puma560Model puma;
  expectRegressorExact(puma);
  expectRegressorExact(WAM7Model());
  expectRegressorExact(WAM4Model());
  expectRegressorExact(*tiltedWam());
  expectRegressorExact(*test::toModifiedDh(puma));
  expectRegressorExact(*test::prismaticDhArm());
}

TEST(GravityRegressor, EqualsCentralDifferencesOfGravityTorque) {
  Puma560Model puma;
  expectRegressorMatchesDifferences(puma);
  expectRegressorMatchesDifferences(*tiltedWam());
  expectRegressorMatchesDifferences(*test::toModifiedDh(puma));
  expectRegressorMatchesDifferences(*test::prismaticDhArm());
}

TEST(BaseParameters, Puma560VerticalFirstJointHasNoGravityParameters) {
  Puma560Model puma;
  const BaseParameters bp = findBaseParameters(puma);
  auto contains = [](const std::vector<int>& v, int k) { return std::find(v.begin(), v.end(), k) != v.end(); };
  // Link 1 turns about the vertical: none of its parameters changes a gravity torque.
  for (int k = 0; k < 4; ++k) EXPECT_TRUE(contains(bp.unidentifiable, k)) << gravityParameterName(k);
  // The moments along a joint's own axis of the links it alone turns never act either... and the
  // partition covers every parameter exactly once.
  EXPECT_EQ(bp.base.size() + bp.dependent.size() + bp.unidentifiable.size(), 24u);
  EXPECT_EQ(bp.K.rows(), static_cast<Eigen::Index>(bp.base.size()));
  // The base parameters reproduce the gravity torque of any parameters.
  ManipulatorData data(puma);
  std::mt19937 rng(3);
  Eigen::VectorXd theta = gravityParameters(puma);
  for (int k = 0; k < theta.size(); ++k) theta(k) += std::uniform_real_distribution<double>(-0.5, 0.5)(rng);
  const Eigen::VectorXd thetaBase = bp.project(theta);
  Eigen::MatrixXd Y;
  for (int s = 0; s < 20; ++s) {
    gravityRegressor(puma, data, randomPose(puma, rng), Y);
    Eigen::VectorXd viaBase = Eigen::VectorXd::Zero(6);
    for (std::size_t b = 0; b < bp.base.size(); ++b) viaBase += Y.col(bp.base[b]) * thetaBase(static_cast<Eigen::Index>(b));
    EXPECT_LT((viaBase - Y * theta).norm(), 1e-9);
  }
}

TEST(Plan, StaysWithinTheJointAndTorqueLimits) {
  for (const ManipulatorModel* model : std::initializer_list<const ManipulatorModel*>{new Puma560Model, new WAM7Model}) {
    const std::vector<PlanSegment> plan = makePlan(*model, PlanOptions());
    std::size_t logged = 0;
    ManipulatorData data(*model);
    JointVector g(model->getNumberOfJoints());
    for (std::size_t k = 0; k < plan.size(); ++k) {
      const PlanSegment& s = plan[k];
      logged += s.log;
      // The arm can hold every point of every motion (the first one's end; the others' paths).
      for (int step = k == 0 ? 10 : 0; step <= 10; ++step) {
        gravityTorque(*model, data, k == 0 ? s.target : JointVector(plan[k - 1].target + (s.target - plan[k - 1].target) * (step / 10.0)), g);
        for (int j = 0; j < model->getNumberOfJoints(); ++j)
          EXPECT_LE(std::abs(g(j)), 0.6 * model->getTorqueLimit()(j) + 1e-9) << s.what << " joint " << j + 1;
      }
      for (int j = 0; j < model->getNumberOfJoints(); ++j) {
        EXPECT_GT(s.target(j), model->getPositionMin()(j)) << s.what;
        EXPECT_LT(s.target(j), model->getPositionMax()(j)) << s.what;
        EXPECT_LE(s.vmax(j), 0.5 * model->getVelocityLimit()(j) + 1e-12) << s.what;
      }
    }
    // Two passes per pose and two sweeps per speed and joint.
    EXPECT_EQ(logged, 2u * 8 + 2u * 3 * static_cast<std::size_t>(model->getNumberOfJoints()));
    delete model;
  }
}

// The fit on synthetic torques of a perturbed Puma (no noise): exact recovery.
TEST(Fit, RecoversOffsetsFrictionAndGravityFromExactTorques) {
  Puma560Model puma;
  const int n = 6;
  const BaseParameters bp = findBaseParameters(puma);
  JointVector delta(n);
  delta << 0, 0.005, -0.004, 0.006, 0.003, 0;
  std::mt19937 rng(5);
  std::vector<Sample> samples;
  ManipulatorData data(puma);
  DynamicsOptions inertial;
  inertial.gravity = false;
  inertial.motorInertia = true;
  for (int s = 0; s < 400; ++s) {
    Sample x;
    x.q = randomPose(puma, rng);
    x.qd = JointVector(n);
    for (int j = 0; j < n; ++j) x.qd(j) = (s % 2 ? 1 : -1) * std::uniform_real_distribution<double>(0.05, 0.8)(rng);
    x.qdd = JointVector(n);
    for (int j = 0; j < n; ++j) x.qdd(j) = std::uniform_real_distribution<double>(-0.1, 0.1)(rng);
    JointVector g(n), f(n);
    gravityTorque(puma, data, x.q - delta, g);
    frictionTorque(puma, x.qd, f);
    x.tau = g + 1.5 * f + inverseDynamics(puma, data, x.q, x.qd, x.qdd, inertial);
    samples.push_back(x);
  }
  const Result r = fit(puma, samples, bp, true);
  EXPECT_FALSE(r.offsetObservable[0]) << "a vertical first joint";
  EXPECT_FALSE(r.offsetObservable[5]) << "the last link's centre of mass is on its axis";
  for (int j = 1; j < 5; ++j) {
    EXPECT_TRUE(r.offsetObservable[static_cast<std::size_t>(j)]) << j + 1;
    EXPECT_NEAR(r.offset[static_cast<std::size_t>(j)].value, delta(j), 1e-8) << j + 1;
  }
  for (int j = 0; j < n; ++j) {
    double fv = 0, fc = 0, fa = 0;
    modelFriction(puma, j, fv, fc, fa);
    const auto i = static_cast<std::size_t>(j);
    EXPECT_NEAR(r.viscous[i].value, 1.5 * fv, 1e-7 * (1 + fv)) << j + 1;
    EXPECT_NEAR(r.coulomb[i].value, 1.5 * fc, 1e-7 * (1 + fc)) << j + 1;
    EXPECT_NEAR(r.asymmetry[i].value, 1.5 * fa, 1e-7 * (1 + fc)) << j + 1;
  }
  for (std::size_t b = 0; b < r.gravity.size(); ++b) EXPECT_NEAR(r.gravity[b].value, r.gravity[b].nominal, 1e-7) << b;
  EXPECT_LT(r.residualRms, 1e-8);
}

}  // namespace
}  // namespace rp::calibration
