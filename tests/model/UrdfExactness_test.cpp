// URDF chains are loaded exactly, whatever their axes: the project's own test descriptions (float
// noise in axes, nearly parallel, nearly intersecting and coincident axes, fixed-frame branches,
// prismatic joints) against Orocos KDL built from the same file through urdfdom (each joint's
// origin, then its motion about or along its axis, the way kdl_parser builds a chain; the inertia
// of links fixed to a chain link off the chain added to it with KDL's own arithmetic), at random
// configurations: forward kinematics, Jacobian, gravity, inverse dynamics and mass matrix to 1e-12
// relative. And a sweep: every leaf link of every test description as the tip either loads and
// agrees with KDL, or is refused with a message naming the file; never a NaN.
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
#include <random>
#include <sstream>

#include "KdlChain.hpp"
#include "rp/model/Dynamics.hpp"
#include "rp/model/Kinematics.hpp"
#include "UrdfDom.hpp"
#include "rp/model/UrdfModel.hpp"

namespace rp {
namespace {

const std::string kData = RP_TEST_DATA_DIR;

using test::parse;
using test::pose;

KDL::RigidBodyInertia kdlInertia(const urdf::Inertial& i) {
  const Transform T = pose(i.origin);
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  Eigen::Matrix3d I;
  I << i.ixx, i.ixy, i.ixz, i.ixy, i.iyy, i.iyz, i.ixz, i.iyz, i.izz;
  const Eigen::Matrix3d Il = R * I * R.transpose();
  return KDL::RigidBodyInertia(i.mass, KDL::Vector(T(0, 3), T(1, 3), T(2, 3)),
                               KDL::RotationalInertia(Il(0, 0), Il(1, 1), Il(2, 2), Il(0, 1), Il(0, 2), Il(1, 2)));
}

// The chain root -> tip of a URDF as KDL segments, and how many movable joints it has.
struct KdlArm {
  KDL::Chain chain;
  int joints = 0;
  bool allInertial = true;  // the child link of every movable joint has inertial data
};

// The value at which a moving joint off the chain is lumped: zero within its limits, or for a
// mimic joint its master's times the multiplier plus the offset.
double offChainValue(const urdf::ModelInterfaceSharedPtr& robot, const urdf::JointConstSharedPtr& j) {
  if (j->mimic) return j->mimic->multiplier * offChainValue(robot, robot->getJoint(j->mimic->joint_name)) + j->mimic->offset;
  return j->limits && j->type != urdf::Joint::CONTINUOUS ? std::clamp(0.0, j->limits->lower, j->limits->upper) : 0.0;
}

KdlArm kdlArm(const urdf::ModelInterfaceSharedPtr& robot, const std::string& tip) {
  std::vector<urdf::JointConstSharedPtr> joints;
  for (auto link = robot->getLink(tip); link->parent_joint; link = robot->getLink(link->parent_joint->parent_link_name))
    joints.push_back(link->parent_joint);
  std::reverse(joints.begin(), joints.end());
  std::set<std::string> onChain;
  for (const auto& j : joints) onChain.insert(j->child_link_name);
  KdlArm arm;
  for (const urdf::JointConstSharedPtr& j : joints) {
    const KDL::Frame origin = test::kdlFrame(pose(j->parent_to_joint_origin_transform));
    // The child link's inertia and that of the links fixed to it off the chain.
    KDL::RigidBodyInertia inertia = KDL::RigidBodyInertia::Zero();
    bool any = false;
    std::vector<std::pair<urdf::LinkConstSharedPtr, KDL::Frame>> todo{{robot->getLink(j->child_link_name), KDL::Frame::Identity()}};
    while (!todo.empty()) {
      const auto [link, frame] = todo.back();
      todo.pop_back();
      if (link->inertial) {
        inertia = inertia + frame * kdlInertia(*link->inertial);
        any = true;
      }
      for (const urdf::JointSharedPtr& c : link->child_joints) {
        if (onChain.count(c->child_link_name)) continue;
        const KDL::Frame o = test::kdlFrame(pose(c->parent_to_joint_origin_transform));
        if (c->type == urdf::Joint::FIXED) {
          todo.emplace_back(robot->getLink(c->child_link_name), frame * o);
        } else if (c->type != urdf::Joint::FLOATING && c->type != urdf::Joint::PLANAR) {
          // A moving link off the chain (a finger, a jaw), lumped at its stated value.
          KDL::Vector axis = o.M * KDL::Vector(c->axis.x, c->axis.y, c->axis.z);
          axis = axis / axis.Norm();
          const KDL::Joint joint(c->name, o.p, axis, c->type == urdf::Joint::PRISMATIC ? KDL::Joint::TransAxis : KDL::Joint::RotAxis);
          todo.emplace_back(robot->getLink(c->child_link_name), frame * KDL::Segment(joint, o).pose(offChainValue(robot, c)));
        }
      }
    }
    if (j->type == urdf::Joint::FIXED) {
      arm.chain.addSegment(KDL::Segment(j->child_link_name, KDL::Joint(j->name, KDL::Joint::Fixed), origin, inertia));
    } else {
      if (!any) arm.allInertial = false;
      ++arm.joints;
      const KDL::Vector axis = origin.M * KDL::Vector(j->axis.x, j->axis.y, j->axis.z);
      const KDL::Joint::JointType type = j->type == urdf::Joint::PRISMATIC ? KDL::Joint::TransAxis : KDL::Joint::RotAxis;
      arm.chain.addSegment(KDL::Segment(j->child_link_name, KDL::Joint(j->name, origin.p, axis / axis.Norm(), type), origin, inertia));
    }
  }
  return arm;
}

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
  const int n = model.getNumberOfJoints();
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
    const KDL::JntArray kq = test::kdlJoints(q), kqd = test::kdlJoints(qd), kqdd = test::kdlJoints(qdd);
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
    KDL::Jacobian kj(static_cast<unsigned>(n));
    jac.JntToJac(kq, kj);
    const Jacobian& J = jacobian(model, data, q);
    w.finite = w.finite && J.allFinite();
    w.jacobian = std::max(w.jacobian, relative(J, kj.data, 6, n));
    if (!arm.allInertial) continue;
    KDL::JntArray kg(static_cast<unsigned>(n)), ktau(static_cast<unsigned>(n));
    dyn.JntToGravity(kq, kg);
    JointVector g(n);
    gravityTorque(model, data, q, g);
    w.gravity = std::max(w.gravity, relative(g, kg.data, n, 1));
    KDL::Wrenches wrenches(arm.chain.getNrOfSegments(), KDL::Wrench::Zero());
    id.CartToJnt(kq, kqd, kqdd, wrenches, ktau);
    const JointVector& tau = inverseDynamics(model, data, q, qd, qdd);
    w.rnea = std::max(w.rnea, relative(tau, ktau.data, n, 1));
    KDL::JntSpaceInertiaMatrix km(static_cast<unsigned>(n));
    dyn.JntToMass(kq, km);
    const JointMatrix& M = massMatrix(model, data, q);
    w.mass = std::max(w.mass, relative(M, km.data, n, n));
    w.finite = w.finite && g.allFinite() && tau.allFinite() && M.allFinite();
  }
  return w;
}

std::unique_ptr<ManipulatorModel> load(const std::string& file, const std::string& tip) {
  UrdfOptions options;
  options.tip = tip;
  return loadUrdf(kData + "/" + file, options);
}

void expectExact(const std::string& file, const std::string& tip, int joints) {
  SCOPED_TRACE(file + " to " + tip);
  const std::unique_ptr<ManipulatorModel> model = load(file, tip);
  ASSERT_EQ(model->getNumberOfJoints(), joints);
  const KdlArm arm = kdlArm(parse(kData + "/" + file), tip);
  ASSERT_EQ(arm.joints, joints);
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
      const KdlArm arm = kdlArm(robot, name);
      ASSERT_EQ(arm.joints, model->getNumberOfJoints());
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
