// The Puma 560 model against the Robotics Toolbox's published values
// (shared/refdata/02_puma560_toolbox_expected_values.txt; Python model, d1 = 0.67183 m).
// Conventions: the toolbox's inertia() and rne() include the armature G^2 Jm, and rne() includes
// friction when qd != 0; gravload() has neither.
#include "rp/model/Puma560Model.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <numbers>
#include <vector>

#include "rp/model/Dynamics.hpp"
#include "rp/model/Kinematics.hpp"

namespace rp {
namespace {

constexpr double kPi = std::numbers::pi;

JointVector joints(std::initializer_list<double> values) {
  JointVector q(static_cast<Eigen::Index>(values.size()));
  int i = 0;
  for (double v : values) q(i++) = v;
  return q;
}

const JointVector kQn = joints({0, kPi / 4, kPi, 0, kPi / 4, 0});

template <typename A, typename B>
void expectNear(const A& actual, const B& expected, double tol, const char* what) {
  ASSERT_EQ(actual.rows(), expected.rows()) << what;
  ASSERT_EQ(actual.cols(), expected.cols()) << what;
  for (Eigen::Index i = 0; i < actual.rows(); ++i)
    for (Eigen::Index j = 0; j < actual.cols(); ++j)
      EXPECT_NEAR(actual(i, j), expected(i, j), tol) << what << " (" << i << ", " << j << ")";
}

TEST(Puma560Model, ForwardKinematicsMatchesToolbox) {
  Puma560Model model;
  ManipulatorData data(model);
  // [NB kinematics.ipynb cell 11] fkine(qn)
  expectNear(forwardKinematics(model, data, kQn),
             Eigen::Matrix4d{{0, 0, 1, 0.5963}, {0, 1, 0, -0.15005}, {-1, 0, 0, 0.65748}, {0, 0, 0, 1}}, 1e-4,
             "fkine(qn)");
  // [NB icra2021] fkine([0.1 .. 0.6])
  expectNear(forwardKinematics(model, data, joints({0.1, 0.2, 0.3, 0.4, 0.5, 0.6})),
             Eigen::Matrix4d{{0.1217, -0.6067, -0.7856, 0.2478},
                             {0.8184, 0.5092, -0.2665, -0.1259},
                             {0.5617, -0.6105, 0.5584, 1.146},
                             {0, 0, 0, 1}},
             1e-3, "fkine(q)");
  // [MR] MATLAB model (d1 = 0): fkine(zeros)
  Puma560Model matlab(0.0);
  ManipulatorData d0(matlab);
  expectNear(forwardKinematics(matlab, d0, joints({0, 0, 0, 0, 0, 0})),
             Eigen::Matrix4d{{1, 0, 0, 0.4521}, {0, 1, 0, -0.15}, {0, 0, 1, 0.4318}, {0, 0, 0, 1}}, 1e-4,
             "fkine(qz), d1 = 0");
}

TEST(Puma560Model, JacobiansMatchToolbox) {
  Puma560Model model;
  ManipulatorData data(model);
  const double s = 0.707106781;
  Eigen::Matrix<double, 6, 6> j0;
  j0 << 0.15005, 0.0143542677, 0.319682976, 0, 0, 0,  //
      0.596303149, 0, 0, 0, 0, 0,                     //
      0, 0.596303149, 0.29097444, 0, 0, 0,            //
      0, 0, 0, s, 0, 1,                               //
      0, -1, -1, 0, -1, 0,                            //
      1, 0, 0, -s, 0, 0;
  expectNear(jacobian(model, data, kQn, ReferenceFrame::Base), j0, 1e-8, "jacob0(qn)");
  Eigen::Matrix<double, 6, 6> je;
  je << 0, -0.596303149, -0.29097444, 0, 0, 0,  //
      0.596303149, 0, 0, 0, 0, 0,               //
      0.15005, 0.0143542677, 0.319682976, 0, 0, 0,  //
      -1, 0, 0, s, 0, 0,                        //
      0, -1, -1, 0, -1, 0,                      //
      0, 0, 0, s, 0, 1;
  expectNear(jacobian(model, data, kQn, ReferenceFrame::EndEffector), je, 1e-8, "jacobe(qn)");
}

TEST(Puma560Model, GravityInertiaAndRneMatchToolbox) {
  Puma560Model model;
  ManipulatorData data(model);
  JointVector g(6);
  gravityTorque(model, data, kQn, g);
  expectNear(g, joints({-1.61532977e-15, 3.16398804e+01, 6.03513802e+00, 8.34761258e-18, 2.82528000e-02, 0}), 1e-7,
             "gravload(qn)");

  const JointMatrix& M = massMatrix(model, data, kQn, true);
  EXPECT_NEAR(M(0, 0), 3.65937541, 1e-8);
  EXPECT_NEAR(M(1, 1), 4.41374193, 1e-8);
  EXPECT_NEAR(M(2, 2), 0.937841575, 1e-8);
  EXPECT_NEAR(M(3, 3), 0.192531706, 1e-8);
  EXPECT_NEAR(M(4, 4), 0.171348452, 1e-8);
  EXPECT_NEAR(M(5, 5), 0.194104506, 1e-8);
  EXPECT_NEAR(M(0, 1), -0.404361246, 1e-8);
  EXPECT_NEAR(M(0, 2), 0.100613648, 1e-8);
  EXPECT_NEAR(M(0, 3), -2.51695583e-03, 1e-10);
  EXPECT_NEAR(M(1, 2), 0.350890665, 1e-8);
  EXPECT_NEAR(M(1, 4), 2.35951307e-03, 1e-10);
  EXPECT_NEAR(M(2, 4), 1.48016639e-03, 1e-10);
  EXPECT_NEAR(M(3, 5), 2.82842712e-05, 1e-12);

  const JointVector z = joints({0, 0, 0, 0, 0, 0}), o = joints({1, 1, 1, 1, 1, 1});
  DynamicsOptions all;
  all.motorInertia = true;
  all.friction = true;
  expectNear(inverseDynamics(model, data, kQn, z, o, all),
             joints({3.35311, 36.0025, 7.42596, 0.190043, 0.203441, 0.194133}), 5e-5, "rne(qn, z, o)");
  expectNear(inverseDynamics(model, data, kQn, o, o, all),
             joints({32.4952, 60.867, 17.7436, 1.45452, 1.29911, 0.713781}), 5e-4, "rne(qn, o, o)");
  expectNear(inverseDynamics(model, data, kQn, o, z, all),
             joints({29.1421, 56.5044, 16.3528, 1.26448, 1.12392, 0.519648}), 5e-4, "rne(qn, o, z)");
  DynamicsOptions noGravity = all;
  noGravity.gravity = false;
  expectNear(inverseDynamics(model, data, kQn, o, o, noGravity),
             joints({32.4952, 29.2271, 11.7085, 1.45452, 1.27086, 0.713781}), 5e-4, "rne(qn, o, o, gravity=0)");
  DynamicsOptions wrench = all;
  wrench.tipWrench = Vector<6>{{1}, {2}, {3}, {1}, {2}, {3}};
  expectNear(inverseDynamics(model, data, kQn, z, z, wrench),
             joints({0.642756, 29.0866, 4.70321, 2.82843, -1.97175, 3}), 5e-5, "rne(qn, z, z, fext)");
}

TEST(Puma560Model, CoriolisAndForwardDynamicsMatchToolbox) {
  Puma560Model model;
  ManipulatorData data(model);
  // [T test_accel] accel(qn, qd, tau) with armature and friction, as the toolbox computes it.
  DynamicsOptions all;
  all.motorInertia = true;
  all.friction = true;
  expectNear(forwardDynamics(model, data, kQn, joints({0.1, 0.2, 0.8, 0.2, 0.5, 1.0}),
                             joints({1.0, 3.2, 1.8, 0.1, 0.7, 4.6}), all),
             joints({-7.4102, -9.8432, -10.9694, -4.4314, -0.9881, 21.0228}), 5e-4, "accel(qn, qd, tau)");
  // [T test_coriolis]: C(qn, qd) qd for qd = [1 2 3 1 2 3], i.e. the row sums weighted by qd.
  const JointVector qd = joints({1, 2, 3, 1, 2, 3});
  Eigen::Matrix<double, 6, 6> C;
  C << -0.1735, -2.0494, -0.1178, -0.0002, -0.0045, 0.0001,  //
      0.6274, 1.1572, 1.9287, -0.0015, -0.0003, -0.0000,     //
      -0.3608, -0.7734, -0.0018, -0.0009, -0.0064, -0.0000,  //
      0.0011, 0.0005, -0.0001, 0.0002, 0.0002, -0.0001,      //
      -0.0002, 0.0028, 0.0046, -0.0002, -0.0000, -0.0000,    //
      0.0001, 0.0000, 0.0000, 0.0000, 0.0000, 0;
  JointVector c(6);
  coriolisTorque(model, data, kQn, qd, c);
  const Eigen::Matrix<double, 6, 1> expected = C * Eigen::Matrix<double, 6, 1>(qd);
  expectNear(c, expected, 2e-3, "coriolis(qn, qd) * qd");  // the table is rounded to 4 decimals
}

// The end-effector frame is the last link frame times the tool transform; a tool that is exactly
// the identity is copied, not multiplied (ManipulatorModel::hasIdentityTool()), and a tool that is
// anything else, however close to the identity, is applied.
TEST(Puma560Model, TheEndEffectorIsTheLastLinkTimesTheToolUnlessTheToolIsExactlyTheIdentity) {
  const Puma560Model puma;
  std::vector<LinkParameters> links;
  for (int i = 0; i < puma.getNumberOfJoints(); ++i) links.push_back(puma.getLink(i));
  Transform tool = Transform::unit();
  tool.topLeftCorner<3, 3>() = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  tool.topRightCorner<3, 1>() << 0.01, -0.02, 0.1;
  Transform tiny = Transform::unit();
  tiny(2, 3) = 1e-300;
  const ManipulatorModel withTool("tool", links, puma.getBaseTransform(), tool, puma.getGravity(), puma.getConvention());
  const ManipulatorModel almost("almost", links, puma.getBaseTransform(), tiny, puma.getGravity(), puma.getConvention());
  EXPECT_TRUE(puma.hasIdentityTool());
  EXPECT_FALSE(withTool.hasIdentityTool());
  EXPECT_FALSE(almost.hasIdentityTool());
  ManipulatorData a(puma), b(withTool);
  const JointVector q = joints({0.1, -0.7, 0.4, 1.1, -0.5, 2.0});
  const Transform& bare = forwardKinematics(puma, a, q);
  EXPECT_EQ(bare, a.linkTransforms[5]);
  const Transform expected = a.linkTransforms[5] * tool;
  const Transform& tipped = forwardKinematics(withTool, b, q);
  EXPECT_LT((tipped - expected).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_GT((tipped - bare).cwiseAbs().maxCoeff(), 0.01);
}

}  // namespace
}  // namespace rp
