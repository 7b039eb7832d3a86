// URDF chains are loaded exactly, whatever their axes: the project's own test descriptions (float
// noise in axes, nearly parallel, nearly intersecting and coincident axes, fixed-frame branches,
// prismatic joints, mimic joints, fingers and a jaw off the chain) against Orocos KDL built from
// the same file by kdl_parser (Debian's libkdl-parser-dev, KdlFromUrdf.hpp: treeFromFile, then the
// tree's chain to the tip, the subtrees off the chain lumped with KDL's own arithmetic, mimic
// joints at multiplier * master + offset), at random configurations: forward kinematics,
// Jacobian, gravity, inverse dynamics and mass matrix to 1e-12 relative. And a sweep: every leaf
// link of every test description as the tip either loads and agrees with KDL, or is refused with a
// message naming the file; never a NaN.
#include <gtest/gtest.h>

#include <urdf_parser/urdf_parser.h>

#include <kdl/chain.hpp>
#include <kdl/chaindynparam.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <kdl/chainjnttojacsolver.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>

#include "KdlChain.hpp"
#include "KdlFromUrdf.hpp"
#include "rp/model/Dynamics.hpp"
#include "rp/model/Kinematics.hpp"
#include "UrdfDom.hpp"
#include "rp/model/UrdfModel.hpp"

namespace rp {
namespace {

const std::string kData = RP_TEST_DATA_DIR;

using test::parse;
using test::pose;

using test::KdlArm;
using test::kdlArm;

// Largest difference between a and b relative to the largest entry of b (at least 1e-3, so that
// a quantity that is nearly zero everywhere is compared absolutely).
template <typename A, typename B>
double relative(const A& a, const B& b, int rows, int cols) {
  double err = 0, scale = 1e-3;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      err = std::max(err, std::abs(a(r, c) - b(r, c)));
      scale = std::max(scale, std::abs(b(r, c)));
    }
  return err / scale;
}

// Worst relative differences from KDL over random configurations within the limits.
struct Agreement {
  double fk = 0, jacobian = 0, gravity = 0, rnea = 0, mass = 0;
  bool finite = true;
};

Agreement compare(const ManipulatorModel& model, const KdlArm& arm, int trials, unsigned seed) {
  const int n = model.getNumberOfJoints(), m = arm.joints;
  // The chain's joint values are S q + o (mimic joints follow their master): KDL computes on the
  // whole chain, and J S, S^T g, S^T tau and S^T M S are the model's.
  Eigen::MatrixXd S = Eigen::MatrixXd::Zero(m, n);
  Eigen::VectorXd o(m);
  for (int k = 0; k < m; ++k) {
    const int i = model.findJoint(arm.master[static_cast<std::size_t>(k)]);
    EXPECT_GE(i, 0) << arm.master[static_cast<std::size_t>(k)];
    if (i < 0) return {};
    S(k, i) = arm.multiplier[static_cast<std::size_t>(k)];
    o(k) = arm.offset[static_cast<std::size_t>(k)];
  }
  KDL::ChainFkSolverPos_recursive fk(arm.chain);
  KDL::ChainJntToJacSolver jac(arm.chain);
  KDL::ChainIdSolver_RNE id(arm.chain, KDL::Vector(0, 0, -9.81));
  KDL::ChainDynParam dyn(arm.chain, KDL::Vector(0, 0, -9.81));
  ManipulatorData data(model);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  Agreement w;
  for (int trial = 0; trial < trials; ++trial) {
    JointVector q(n), qd(n), qdd(n);
    for (int i = 0; i < n; ++i) {
      q(i) = model.getPositionMin()(i) + u(rng) * (model.getPositionMax()(i) - model.getPositionMin()(i));
      qd(i) = 2 * u(rng) - 1;
      qdd(i) = 4 * u(rng) - 2;
    }
    const Eigen::VectorXd fq = S * Eigen::VectorXd(q) + o, fqd = S * Eigen::VectorXd(qd), fqdd = S * Eigen::VectorXd(qdd);
    const KDL::JntArray kq = test::kdlJoints(JointVector(fq)), kqd = test::kdlJoints(JointVector(fqd)),
                       kqdd = test::kdlJoints(JointVector(fqdd));
    KDL::Frame f;
    fk.JntToCart(kq, f);
    Eigen::Matrix<double, 3, 4> kf;
    for (int r = 0; r < 3; ++r) {
      kf(r, 3) = f.p(r);
      for (int c = 0; c < 3; ++c) kf(r, c) = f.M(r, c);
    }
    const Transform& T = forwardKinematics(model, data, q);
    w.finite = w.finite && T.allFinite();
    w.fk = std::max(w.fk, relative(T, kf, 3, 4));
    KDL::Jacobian kj(static_cast<unsigned>(m));
    jac.JntToJac(kq, kj);
    const Jacobian& J = jacobian(model, data, q);
    w.finite = w.finite && J.allFinite();
    const Eigen::MatrixXd kJ = kj.data * S;
    w.jacobian = std::max(w.jacobian, relative(J, kJ, 6, n));
    if (!arm.allInertial) continue;
    KDL::JntArray kg(static_cast<unsigned>(m)), ktau(static_cast<unsigned>(m));
    dyn.JntToGravity(kq, kg);
    JointVector g(n);
    gravityTorque(model, data, q, g);
    const Eigen::VectorXd kG = S.transpose() * kg.data;
    w.gravity = std::max(w.gravity, relative(g, kG, n, 1));
    KDL::Wrenches wrenches(arm.chain.getNrOfSegments(), KDL::Wrench::Zero());
    id.CartToJnt(kq, kqd, kqdd, wrenches, ktau);
    const JointVector& tau = inverseDynamics(model, data, q, qd, qdd);
    const Eigen::VectorXd kTau = S.transpose() * ktau.data;
    w.rnea = std::max(w.rnea, relative(tau, kTau, n, 1));
    KDL::JntSpaceInertiaMatrix km(static_cast<unsigned>(m));
    dyn.JntToMass(kq, km);
    const JointMatrix& M = massMatrix(model, data, q);
    const Eigen::MatrixXd kM = S.transpose() * km.data * S;
    w.mass = std::max(w.mass, relative(M, kM, n, n));
    w.finite = w.finite && g.allFinite() && tau.allFinite() && M.allFinite();
  }
  return w;
}

std::unique_ptr<ManipulatorModel> load(const std::string& file, const std::string& tip,
                                       const std::map<std::string, double>& offChain = {}) {
  UrdfOptions options;
  options.tip = tip;
  options.offChainPositions = offChain;
  return loadUrdf(kData + "/" + file, options);
}

// `offChain`: values of joints off the chain (UrdfOptions::offChainPositions) for both.
void expectExact(const std::string& file, const std::string& tip, int joints, int chainJoints = 0,
                 const std::map<std::string, double>& offChain = {}) {
  SCOPED_TRACE(file + " to " + tip);
  const std::unique_ptr<ManipulatorModel> model = load(file, tip, offChain);
  ASSERT_EQ(model->getNumberOfJoints(), joints);
  const KdlArm arm = kdlArm(kData + "/" + file, parse(kData + "/" + file), tip, offChain);
  ASSERT_EQ(arm.joints, chainJoints > 0 ? chainJoints : joints);
  const Agreement w = compare(*model, arm, 300, 11);
  EXPECT_TRUE(w.finite);
  EXPECT_LT(w.fk, 1e-12);
  EXPECT_LT(w.jacobian, 1e-12);
  EXPECT_LT(w.gravity, 1e-12);
  EXPECT_LT(w.rnea, 1e-12);
  EXPECT_LT(w.mass, 1e-12);
  std::printf("%s to %s: worst relative difference from KDL: fk %.1e, J %.1e, g %.1e, tau %.1e, M %.1e\n", file.c_str(),
              tip.c_str(), w.fk, w.jacobian, w.gravity, w.rnea, w.mass);
}

// Float noise in axes, parallel axes with noise, axes 1e-9 rad off parallel, axes 2e-8 m apart
// and coincident axes: the DH re-expression gave NaN, refused the chain or lost five digits.
TEST(UrdfExactness, NoisyNearlyParallelAndNearlyIntersectingAxesLoadExactly) {
  expectExact("noisy_axes_arm.urdf", "tool0", 7);
  expectExact("noisy_axes_arm.urdf", "a5", 5);
}

TEST(UrdfExactness, ArmsWithFixedFrameBranchesAndPrismaticJointsLoadExactly) {
  expectExact("ur_like.urdf", "tool0", 6);
  expectExact("ur_like.urdf", "camera_link", 6);
  expectExact("panda_like.urdf", "hand_tcp", 7);
  expectExact("test_arm.urdf", "tool", 6);
  expectExact("panda_like.urdf", "link7", 7);  // the hand and the fingers (one a mimic) lumped
  expectExact("jaw_arm.urdf", "link06", 6);    // the jaw lumped
  // Lumped where UrdfOptions::offChainPositions puts them: the jaw open, the fingers apart (the
  // second, a mimic, following the first).
  expectExact("jaw_arm.urdf", "link06", 6, 0, {{"jointGripper", -1.2}});
  expectExact("panda_like.urdf", "link7", 7, 0, {{"finger_joint1", 0.03}});
  expectExact("prismatic_arm.urdf", "tool", 6);
}

// The Jacobian is the derivative of the forward kinematics (central differences), on the noisy arm.
TEST(UrdfExactness, JacobianIsTheDerivativeOfTheForwardKinematics) {
  const std::unique_ptr<ManipulatorModel> model = load("noisy_axes_arm.urdf", "tool0");
  const int n = model->getNumberOfJoints();
  ManipulatorData data(*model), probe(*model);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-2, 2);
  for (int trial = 0; trial < 50; ++trial) {
    JointVector q(n);
    for (int i = 0; i < n; ++i) q(i) = u(rng);
    const Jacobian J = jacobian(*model, data, q);
    const double h = 1e-6;
    for (int i = 0; i < n; ++i) {
      JointVector qp = q, qm = q;
      qp(i) += h;
      qm(i) -= h;
      const Transform Tp = forwardKinematics(*model, probe, qp);
      const Transform Tm = forwardKinematics(*model, probe, qm);
      const Eigen::Vector3d v = (Tp.topRightCorner<3, 1>() - Tm.topRightCorner<3, 1>()) / (2 * h);
      const Eigen::Matrix3d dR = (Tp.topLeftCorner<3, 3>() - Tm.topLeftCorner<3, 3>()) / (2 * h);
      const Eigen::Matrix3d W = dR * data.endEffector.topLeftCorner<3, 3>().transpose();  // skew(w)
      const Eigen::Vector3d w(W(2, 1), W(0, 2), W(1, 0));
      EXPECT_LT((J.block<3, 1>(0, i) - v).norm(), 1e-8) << "joint " << i + 1;
      EXPECT_LT((J.block<3, 1>(3, i) - w).norm(), 1e-8) << "joint " << i + 1;
    }
  }
}

// Mimic joints on the chain (issue 20): a parallel-link elbow (multiplier -1, offset 0.3) and a
// coupled wrist (a mimic, and a mimic of that mimic) are no joints of the model; kinematics and
// dynamics are KDL's on the whole chain with the mimic joints at multiplier * master + offset,
// mapped back (J S, S^T g, S^T tau, S^T M S).
TEST(UrdfExactness, MimicJointsOnTheChainFollowTheirMaster) {
  expectExact("mimic_arm.urdf", "tool", 4, 7);
  const std::unique_ptr<ManipulatorModel> model = load("mimic_arm.urdf", "tool");
  ASSERT_TRUE(model->hasMimicJoints());
  EXPECT_EQ(model->getJointName(0), "base_yaw");
  EXPECT_EQ(model->getJointName(1), "shoulder");
  EXPECT_EQ(model->getJointName(2), "wrist_roll");
  EXPECT_EQ(model->getJointName(3), "slide");
  EXPECT_EQ(model->findJoint("elbow_link"), -1);
  EXPECT_EQ(model->getChain().getNumberOfJoints(), 7);
  EXPECT_EQ(model->getChainIndex(2), 3);
  const JointCoupling& yaw = model->getCoupling()[5];  // wrist_yaw = -2 (0.5 roll - 0.1)
  EXPECT_TRUE(yaw.mimic);
  EXPECT_EQ(yaw.joint, 2);
  EXPECT_DOUBLE_EQ(yaw.multiplier, -1);
  EXPECT_DOUBLE_EQ(yaw.offset, 0.2);
  // The elbow's limits [-1, 1.6] at -shoulder + 0.3 leave the shoulder [-1.2, 1.3] (its own: 1.5).
  EXPECT_DOUBLE_EQ(model->getPositionMin()(1), -1.2);
  EXPECT_DOUBLE_EQ(model->getPositionMax()(1), 1.3);
  EXPECT_DOUBLE_EQ(model->getVelocityLimit()(1), 1.5);  // the elbow's 1.5 rad/s at multiplier -1
}

// With mimic joints, the Jacobian is the derivative of the forward kinematics and the gravity
// torque that of the potential energy of every chain link (central differences); forward
// dynamics (composite rigid body and articulated body) inverts the inverse dynamics; friction of
// the mimic joints acts on their master (frictionTorque() equals inverse dynamics with minus
// without friction).
TEST(UrdfExactness, MimicArmAgreesWithFiniteDifferencesAndItsOwnInverse) {
  const std::unique_ptr<ManipulatorModel> model = load("mimic_arm.urdf", "tool");
  const ManipulatorModel& chain = model->getChain();
  const int n = model->getNumberOfJoints();
  ManipulatorData data(*model), probe(*model);
  auto potential = [&](const JointVector& q) {
    forwardKinematics(*model, probe, q);
    double U = 0;
    for (int k = 0; k < chain.getNumberOfJoints(); ++k) {
      const Transform& T = probe.chain->linkTransforms[static_cast<std::size_t>(k)];
      const Eigen::Vector3d c = T.topLeftCorner<3, 3>() * Eigen::Vector3d(chain.getLink(k).com) + T.topRightCorner<3, 1>();
      U -= chain.getLink(k).mass * Eigen::Vector3d(model->getGravity()).dot(c);
    }
    return U;
  };
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  double worstJ = 0, worstG = 0, worstFd = 0, worstAba = 0, worstFriction = 0;
  for (int trial = 0; trial < 50; ++trial) {
    JointVector q(n), qd(n), tau(n);
    for (int i = 0; i < n; ++i) {
      q(i) = model->getPositionMin()(i) + u(rng) * (model->getPositionMax()(i) - model->getPositionMin()(i));
      qd(i) = 2 * u(rng) - 1;
      tau(i) = 20 * u(rng) - 10;
    }
    const Jacobian J = jacobian(*model, data, q);
    JointVector g(n);
    gravityTorque(*model, data, q, g);
    const double h = 1e-6;
    for (int i = 0; i < n; ++i) {
      JointVector qp = q, qm = q;
      qp(i) += h;
      qm(i) -= h;
      const Transform Tp = forwardKinematics(*model, probe, qp);
      const Transform Tm = forwardKinematics(*model, probe, qm);
      const Eigen::Vector3d v = (Tp.topRightCorner<3, 1>() - Tm.topRightCorner<3, 1>()) / (2 * h);
      const Eigen::Matrix3d dR = (Tp.topLeftCorner<3, 3>() - Tm.topLeftCorner<3, 3>()) / (2 * h);
      const Eigen::Matrix3d W = dR * data.endEffector.topLeftCorner<3, 3>().transpose();  // skew(w)
      const Eigen::Vector3d w(W(2, 1), W(0, 2), W(1, 0));
      worstJ = std::max({worstJ, (J.block<3, 1>(0, i) - v).norm(), (J.block<3, 1>(3, i) - w).norm()});
      worstG = std::max(worstG, std::abs(g(i) - (potential(qp) - potential(qm)) / (2 * h)));
    }
    DynamicsOptions options;
    options.friction = true;
    options.motorInertia = true;
    const JointVector qdd = forwardDynamics(*model, data, q, qd, tau, options);
    worstFd = std::max(worstFd, (inverseDynamics(*model, data, q, qd, qdd, options) - tau).cwiseAbs().maxCoeff());
    const JointVector qddAba = forwardDynamicsArticulatedBody(*model, data, q, qd, tau, options);
    worstAba = std::max(worstAba, (qddAba - qdd).cwiseAbs().maxCoeff());
    DynamicsOptions noFriction = options;
    noFriction.friction = false;
    const JointVector withFriction = inverseDynamics(*model, data, q, qd, qdd, options);
    const JointVector without = inverseDynamics(*model, data, q, qd, qdd, noFriction);
    JointVector f(n);
    frictionTorque(*model, qd, f);
    worstFriction = std::max(worstFriction, (withFriction - without - f).cwiseAbs().maxCoeff());
  }
  std::printf("mimic arm: J vs differences %.1e, g vs dU/dq %.1e, ID(FD(tau)) - tau %.1e N m, ABA - CRBA %.1e, friction %.1e\n",
              worstJ, worstG, worstFd, worstAba, worstFriction);
  EXPECT_LT(worstJ, 1e-8);
  EXPECT_LT(worstG, 1e-6);
  EXPECT_LT(worstFd, 1e-10);
  EXPECT_LT(worstAba, 1e-12);
  EXPECT_LT(worstFriction, 1e-12);
  // The shoulder's friction includes the parallel link's: damping 0.4 + 0.2, Coulomb 1.5 + 0.7.
  JointVector qd = JointVector::Zero(n), f(n);
  qd(1) = 2;
  frictionTorque(*model, qd, f);
  EXPECT_NEAR(f(1), 0.6 * 2 + 2.2, 1e-12);
}

// Every leaf link of every test description as the tip: loads and agrees with KDL, or is refused
// with a message that names the file; never a NaN.
TEST(UrdfExactness, EveryLeafOfEveryTestDescriptionLoadsExactlyOrIsRefused) {
  int loaded = 0, refused = 0;
  for (const auto& entry : std::filesystem::directory_iterator(kData)) {
    if (entry.path().extension() != ".urdf") continue;
    const std::string file = entry.path().string();
    const urdf::ModelInterfaceSharedPtr robot = parse(file);
    if (!robot) continue;  // a malformed file: BadFilesGiveClearErrors covers it
    for (const auto& [name, link] : robot->links_) {
      if (!link->child_joints.empty()) continue;
      SCOPED_TRACE(file + " to " + name);
      std::unique_ptr<ManipulatorModel> model;
      try {
        UrdfOptions options;
        options.tip = name;
        model = loadUrdf(file, options);
      } catch (const UrdfError& e) {
        EXPECT_EQ(std::string(e.what()).rfind(file + ": ", 0), 0u) << e.what();
        EXPECT_GT(std::string(e.what()).size(), file.size() + 10) << e.what();
        ++refused;
        continue;
      }
      ++loaded;
      const KdlArm arm = kdlArm(file, robot, name);
      ASSERT_EQ(arm.joints, model->getChain().getNumberOfJoints());
      const Agreement w = compare(*model, arm, 40, 5);
      EXPECT_TRUE(w.finite);
      EXPECT_LT(std::max({w.fk, w.jacobian, w.gravity, w.rnea, w.mass}), 1e-12);
    }
  }
  std::printf("%d tips loaded and agreed with KDL, %d refused with a message\n", loaded, refused);
  EXPECT_GE(loaded, 10);
}

}  // namespace
}  // namespace rp
