// Forward kinematics, Jacobians (base and end-effector frame), Newton-Euler torques and mass
// matrices of every built-in robot, of their modified-DH descriptions and of a URDF arm with
// prismatic joints (standard and modified DH) against Orocos KDL on 1,000 seeded random
// configurations each: agreement to 1e-9.
#include <gtest/gtest.h>

#include <kdl/chaindynparam.hpp>
#include <kdl/chainfdsolver_recursive_newton_euler.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <kdl/chainjnttojacsolver.hpp>

#include <memory>
#include <random>

#include "KdlChain.hpp"
#include "ModifiedDh.hpp"
#include "PrismaticDhArm.hpp"
#include "rp/model/Dynamics.hpp"
#include "rp/model/Kinematics.hpp"
#include "rp/model/Puma560Model.hpp"
#include "rp/model/UrdfModel.hpp"
#include "rp/model/WAMModel.hpp"

namespace rp {
namespace {

class KdlComparison : public ::testing::TestWithParam<std::string> {
 protected:
  std::unique_ptr<ManipulatorModel> makeModel() const {
    std::string name = GetParam();
    const bool modified = name.size() > 4 && name.substr(name.size() - 4) == "_mdh";
    if (modified) name = name.substr(0, name.size() - 4);
    std::unique_ptr<ManipulatorModel> m;
    if (name == "puma560") m = std::make_unique<Puma560Model>();
    else if (name == "wam7") m = std::make_unique<WAM7Model>();
    else if (name == "wam4") m = std::make_unique<WAM4Model>();
    else if (name == "prismatic_dh") m = test::prismaticDhArm();
    else {
      UrdfOptions o;
      o.tip = "tool";
      m = loadUrdf(std::string(RP_TEST_DATA_DIR) + "/" + name + ".urdf", o);
    }
    return modified ? test::toModifiedDh(*m) : std::move(m);
  }
};

TEST_P(KdlComparison, AgreesOnRandomConfigurations) {
  const std::unique_ptr<ManipulatorModel> model = makeModel();
  ManipulatorData data(*model);
  const int n = model->getNumberOfJoints();
  const KDL::Chain chain = test::kdlChain(*model);
  KDL::ChainFkSolverPos_recursive fk(chain);
  KDL::ChainJntToJacSolver jac(chain);
  KDL::ChainIdSolver_RNE id(chain, KDL::Vector(0, 0, -9.81));
  KDL::ChainDynParam dyn(chain, KDL::Vector(0, 0, -9.81));
  KDL::ChainFdSolver_RNE fdKdl(chain, KDL::Vector(0, 0, -9.81));
  std::mt19937_64 rng(2024);
  std::uniform_real_distribution<double> u(-1, 1);
  double worstFk = 0, worstJ = 0, worstTau = 0, worstM = 0, worstFd = 0, worstG = 0, worstC = 0;
  for (int trial = 0; trial < 1000; ++trial) {
    JointVector q(n), qd(n), qdd(n);
    for (int i = 0; i < n; ++i) {
      q(i) = model->getPositionMin()(i) + (u(rng) + 1) / 2 * (model->getPositionMax()(i) - model->getPositionMin()(i));
      qd(i) = 2 * u(rng);
      qdd(i) = 5 * u(rng);
    }
    const KDL::JntArray kq = test::kdlJoints(q), kqd = test::kdlJoints(qd), kqdd = test::kdlJoints(qdd);

    KDL::Frame f;
    ASSERT_GE(fk.JntToCart(kq, f), 0);
    const Transform& T = forwardKinematics(*model, data, q);
    for (int r = 0; r < 3; ++r) {
      worstFk = std::max(worstFk, std::abs(T(r, 3) - f.p(r)));
      for (int c = 0; c < 3; ++c) worstFk = std::max(worstFk, std::abs(T(r, c) - f.M(r, c)));
    }

    KDL::Jacobian kj(static_cast<unsigned>(n));
    ASSERT_GE(jac.JntToJac(kq, kj), 0);
    const Jacobian& J = jacobian(*model, data, q);
    for (int r = 0; r < 6; ++r)
      for (int c = 0; c < n; ++c) worstJ = std::max(worstJ, std::abs(J(r, c) - kj(static_cast<unsigned>(r), static_cast<unsigned>(c))));
    // End-effector frame: KDL's base-frame Jacobian turned into KDL's end-effector frame.
    kj.changeBase(f.M.Inverse());
    const Jacobian& Je = jacobian(*model, data, q, ReferenceFrame::EndEffector);
    for (int r = 0; r < 6; ++r)
      for (int c = 0; c < n; ++c) worstJ = std::max(worstJ, std::abs(Je(r, c) - kj(static_cast<unsigned>(r), static_cast<unsigned>(c))));

    KDL::JntArray ktau(static_cast<unsigned>(n));
    KDL::Wrenches noWrench(chain.getNrOfSegments(), KDL::Wrench::Zero());
    ASSERT_GE(id.CartToJnt(kq, kqd, kqdd, noWrench, ktau), 0);
    const JointVector& tau = inverseDynamics(*model, data, q, qd, qdd);
    for (int i = 0; i < n; ++i) worstTau = std::max(worstTau, std::abs(tau(i) - ktau(static_cast<unsigned>(i))));

    KDL::JntSpaceInertiaMatrix km(static_cast<unsigned>(n));
    ASSERT_GE(dyn.JntToMass(kq, km), 0);
    const JointMatrix& M = massMatrix(*model, data, q);
    for (int r = 0; r < n; ++r)
      for (int c = 0; c < n; ++c) worstM = std::max(worstM, std::abs(M(r, c) - km(static_cast<unsigned>(r), static_cast<unsigned>(c))));

    // Gravity torque (ours: forward kinematics and link mass moments) and Coriolis torques.
    KDL::JntArray kg(static_cast<unsigned>(n)), kc(static_cast<unsigned>(n));
    ASSERT_GE(dyn.JntToGravity(kq, kg), 0);
    ASSERT_GE(dyn.JntToCoriolis(kq, kqd, kc), 0);
    JointVector g(n), c(n);
    gravityTorque(*model, data, q, g);
    coriolisTorque(*model, data, q, qd, c);
    for (int i = 0; i < n; ++i) {
      worstG = std::max(worstG, std::abs(g(i) - kg(static_cast<unsigned>(i))));
      worstC = std::max(worstC, std::abs(c(i) - kc(static_cast<unsigned>(i))));
    }

    // Forward dynamics of the torques above (both of our algorithms), relative to the size of qdd.
    KDL::JntArray kqddBack(static_cast<unsigned>(n));
    ASSERT_GE(fdKdl.CartToJnt(kq, kqd, ktau, noWrench, kqddBack), 0);
    const JointVector t = tau;
    const JointVector fd1 = forwardDynamics(*model, data, q, qd, t);
    const JointVector fd2 = forwardDynamicsArticulatedBody(*model, data, q, qd, t);
    for (int i = 0; i < n; ++i) {
      const double k = kqddBack(static_cast<unsigned>(i)), scale = 1 + std::abs(k);
      worstFd = std::max({worstFd, std::abs(fd1(i) - k) / scale, std::abs(fd2(i) - k) / scale});
    }
  }
  EXPECT_LT(worstFd, 1e-9);
  EXPECT_LT(worstFk, 1e-9);
  EXPECT_LT(worstJ, 1e-9);
  EXPECT_LT(worstTau, 1e-9);
  EXPECT_LT(worstM, 1e-9);
  EXPECT_LT(worstG, 1e-9);
  EXPECT_LT(worstC, 1e-9);
  RecordProperty("worst_fk", std::to_string(worstFk));
  RecordProperty("worst_tau", std::to_string(worstTau));
}

INSTANTIATE_TEST_SUITE_P(BuiltInRobots, KdlComparison, ::testing::Values("puma560", "wam7", "wam4"));
INSTANTIATE_TEST_SUITE_P(ModifiedDh, KdlComparison, ::testing::Values("puma560_mdh", "wam7_mdh", "wam4_mdh"));
INSTANTIATE_TEST_SUITE_P(Prismatic, KdlComparison, ::testing::Values("prismatic_arm", "prismatic_dh", "prismatic_dh_mdh"));

}  // namespace
}  // namespace rp
