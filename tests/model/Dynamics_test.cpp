// Internal consistency of the dynamics on seeded random states of every built-in robot, of the
// modified-DH Puma 560 and of a URDF arm with prismatic joints (standard and modified DH):
// RNEA = M qdd + C + g, forward dynamics inverts inverse dynamics (and is exactly zero at the
// gravity equilibrium), the gravity torque is the gradient of the potential energy, the Jacobian
// matches finite differences of forward kinematics, and J^T F matches the Newton-Euler tip wrench;
// massMatrixAndBias() gives the two sides of the system forwardDynamics() solves.
#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "rp/model/Dynamics.hpp"
#include "rp/model/Kinematics.hpp"
#include "ModifiedDh.hpp"
#include "PrismaticDhArm.hpp"
#include "rp/model/Puma560Model.hpp"
#include "rp/model/UrdfModel.hpp"
#include "rp/model/WAMModel.hpp"

namespace rp {
namespace {

std::vector<std::unique_ptr<ManipulatorModel>> robots() {
  std::vector<std::unique_ptr<ManipulatorModel>> r;
  r.push_back(std::make_unique<Puma560Model>());
  r.push_back(std::make_unique<WAM7Model>());
  r.push_back(std::make_unique<WAM4Model>());
  r.push_back(test::toModifiedDh(Puma560Model()));
  UrdfOptions o;
  o.tip = "tool";
  o.requireDynamics = true;
  r.push_back(loadUrdf(std::string(RP_TEST_DATA_DIR) + "/prismatic_arm.urdf", o));  // the Placement form
  o.tip = "tool0";
  r.push_back(loadUrdf(std::string(RP_TEST_DATA_DIR) + "/noisy_axes_arm.urdf", o));
  r.push_back(test::prismaticDhArm());
  r.push_back(test::toModifiedDh(*r.back()));
  // The WAM 7 on a tilted, shifted base with gravity off the vertical: the world-frame algorithms
  // (gravity from mass moments, forward dynamics) against the Newton-Euler one, which works in
  // link coordinates from the base's rotation.
  const WAM7Model wam;
  std::vector<LinkParameters> links;
  for (int i = 0; i < wam.getNumberOfJoints(); ++i) links.push_back(wam.getLink(i));
  Vector<3> g;
  g << 1.5, -2.0, -9.5;
  r.push_back(std::make_unique<ManipulatorModel>("wam7_tilted", links,
                                                 translation(0.3, -0.2, 0.5) * rpyToTransform(0.4, -0.7, 1.1),
                                                 wam.getToolTransform(), g));
  return r;
}

JointVector randomJoints(const ManipulatorModel& m, std::mt19937_64& rng, double scale = 1.0) {
  JointVector q(m.getNumberOfJoints());
  for (int i = 0; i < m.getNumberOfJoints(); ++i) {
    std::uniform_real_distribution<double> d(m.getPositionMin()(i) * scale, m.getPositionMax()(i) * scale);
    q(i) = d(rng);
  }
  return q;
}

TEST(Dynamics, NewtonEulerEqualsMassMatrixPlusBiasTerms) {
  std::mt19937_64 rng(1);
  for (auto& robot : robots()) {
    ManipulatorData data(*robot);
    const int n = robot->getNumberOfJoints();
    for (int trial = 0; trial < 200; ++trial) {
      const JointVector q = randomJoints(*robot, rng), qd = randomJoints(*robot, rng), qdd = randomJoints(*robot, rng);
      DynamicsOptions opt;
      opt.motorInertia = true;
      const JointVector tau = inverseDynamics(*robot, data, q, qd, qdd, opt);
      const JointMatrix M = massMatrix(*robot, data, q, true);
      JointVector c(n), g(n);
      coriolisTorque(*robot, data, q, qd, c);
      gravityTorque(*robot, data, q, g);
      const JointVector sum = M * qdd + c + g;
      for (int i = 0; i < n; ++i) EXPECT_NEAR(tau(i), sum(i), 1e-10 * (1 + std::abs(tau(i)))) << robot->getName();
      // M is symmetric positive definite.
      EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(Eigen::MatrixXd(M)).eigenvalues().minCoeff(), 0.0);
    }
  }
}

// The mass matrix uses each link's Cholesky factor where there is one: the factor gives the
// inertia back, and a tensor that is only semidefinite (the Puma's first link, a point mass), not
// symmetric or not finite has none, so the plain form serves it. Both forms give the same matrix.
TEST(Dynamics, InertiaFactorsAreCholeskyFactorsWhereTheInertiaIsPositiveDefinite) {
  const Puma560Model puma;
  EXPECT_EQ(puma.getInertiaFactor(0), nullptr) << "the Puma's link 1: Ixx = Izz = 0";
  const WAM7Model wam;
  for (const ManipulatorModel* m : {static_cast<const ManipulatorModel*>(&puma), static_cast<const ManipulatorModel*>(&wam)}) {
    for (int i = 0; i < m->getNumberOfJoints(); ++i) {
      const Eigen::Matrix3d& I = m->getLink(i).inertia;
      const Eigen::Matrix3d* L = m->getInertiaFactor(i);
      if (Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(I).eigenvalues().minCoeff() > 1e-12 * I.norm()) {
        ASSERT_NE(L, nullptr) << m->getName() << " link " << i + 1;
        EXPECT_TRUE(L->isLowerTriangular());
        EXPECT_LT((*L * L->transpose() - I).norm(), 1e-15 * I.norm()) << m->getName() << " link " << i + 1;
      } else {
        EXPECT_EQ(L, nullptr) << m->getName() << " link " << i + 1;
      }
    }
  }
  // The same links, a point mass at the end and an inertia that is not symmetric.
  std::vector<LinkParameters> links;
  for (int i = 0; i < wam.getNumberOfJoints(); ++i) links.push_back(wam.getLink(i));
  links[6].inertia.setZero();
  links[5].inertia(0, 1) += 1e-3;
  const ManipulatorModel odd("odd", links, wam.getBaseTransform(), wam.getToolTransform(), wam.getGravity());
  EXPECT_EQ(odd.getInertiaFactor(6), nullptr) << "a point mass";
  EXPECT_EQ(odd.getInertiaFactor(5), nullptr) << "not symmetric";
  ASSERT_NE(odd.getInertiaFactor(4), nullptr);
  // A model that mixes both forms (the point mass plain, the other links factored): its mass
  // matrix against Newton-Euler with gravity and velocity off.
  links[5].inertia = wam.getLink(5).inertia;
  const ManipulatorModel pointMass("point_mass", links, wam.getBaseTransform(), wam.getToolTransform(), wam.getGravity());
  ManipulatorData a(pointMass), b(pointMass);
  std::mt19937_64 rng(3);
  for (int trial = 0; trial < 50; ++trial) {
    const JointVector q = randomJoints(pointMass, rng), qdd = randomJoints(pointMass, rng);
    const JointMatrix M = massMatrix(pointMass, a, q);
    DynamicsOptions opt;
    opt.gravity = false;
    const JointVector tau = inverseDynamics(pointMass, b, q, JointVector::Zero(7), qdd, opt);
    const JointVector Mq = M * qdd;
    for (int i = 0; i < 7; ++i) EXPECT_NEAR(Mq(i), tau(i), 1e-12 * (1 + std::abs(tau(i))));
  }
}

TEST(Dynamics, ForwardDynamicsInvertsInverseDynamics) {
  std::mt19937_64 rng(2);
  for (auto& robot : robots()) {
    ManipulatorData data(*robot);
    for (int trial = 0; trial < 200; ++trial) {
      const JointVector q = randomJoints(*robot, rng), qd = randomJoints(*robot, rng), qdd = randomJoints(*robot, rng);
      DynamicsOptions opt;
      opt.motorInertia = trial % 2 == 0;
      opt.friction = trial % 3 == 0;
      if (trial % 4 == 0) opt.tipWrench << 3, -2, 1, 0.5, -0.4, 0.3;
      const JointVector tau = inverseDynamics(*robot, data, q, qd, qdd, opt);
      const JointVector back = forwardDynamics(*robot, data, q, qd, tau, opt);
      for (int i = 0; i < robot->getNumberOfJoints(); ++i) EXPECT_NEAR(back(i), qdd(i), 1e-8) << robot->getName();
      // The articulated-body algorithm (a second algorithm) agrees.
      const JointVector viaM = forwardDynamicsArticulatedBody(*robot, data, q, qd, tau, opt);
      for (int i = 0; i < robot->getNumberOfJoints(); ++i) EXPECT_NEAR(viaM(i), qdd(i), 1e-8) << robot->getName();
    }
  }
}

TEST(Dynamics, GravityTorqueIsTheGradientOfThePotentialEnergy) {
  // A third reference for gravityTorque(): central differences of U(q) = -sum_k m_k g . c_k(q).
  std::mt19937_64 rng(5);
  const double h = 1e-6;
  for (auto& robot : robots()) {
    ManipulatorData data(*robot), fk(*robot);
    const int n = robot->getNumberOfJoints();
    const Eigen::Vector3d g = robot->getGravity();
    const auto energy = [&](const JointVector& q) {
      forwardKinematics(*robot, fk, q);
      double U = 0;
      for (int k = 0; k < n; ++k) {
        const Transform& T = fk.linkTransforms[static_cast<std::size_t>(k)];
        const LinkParameters& l = robot->getLink(k);
        const Eigen::Vector3d c = T.topLeftCorner<3, 3>() * Eigen::Vector3d(l.com) + T.topRightCorner<3, 1>();
        U -= l.mass * g.dot(c);
      }
      return U;
    };
    for (int trial = 0; trial < 50; ++trial) {
      const JointVector q = randomJoints(*robot, rng);
      JointVector tau(n);
      gravityTorque(*robot, data, q, tau);
      for (int j = 0; j < n; ++j) {
        JointVector qp = q, qm = q;
        qp(j) += h;
        qm(j) -= h;
        EXPECT_NEAR(tau(j), (energy(qp) - energy(qm)) / (2 * h), 1e-6 * (1 + std::abs(tau(j)))) << robot->getName();
      }
    }
  }
}

TEST(Dynamics, ForwardDynamicsIsExactlyZeroAtTheGravityEquilibrium) {
  // Holding torque = gravityTorque() at rest: forwardDynamics() subtracts the very same numbers
  // (its gravity part is the same routine on the same forward kinematics), so the accelerations
  // are exactly zero, with and without motor inertia and friction. The simulation relies on it.
  std::mt19937_64 rng(6);
  for (auto& robot : robots()) {
    ManipulatorData control(*robot), sim(*robot);
    const int n = robot->getNumberOfJoints();
    for (int trial = 0; trial < 100; ++trial) {
      const JointVector q = randomJoints(*robot, rng), rest(n);
      JointVector g(n);
      gravityTorque(*robot, control, q, g);
      DynamicsOptions opt;
      opt.motorInertia = trial % 2 == 0;
      opt.friction = trial % 3 == 0;
      const JointVector& qdd = forwardDynamics(*robot, sim, q, rest, g, opt);
      for (int i = 0; i < n; ++i) EXPECT_EQ(qdd(i), 0.0) << robot->getName() << " joint " << i + 1;
    }
  }
}

// massMatrixAndBias(): the bias torque is the Newton-Euler recursion's torque at zero
// acceleration (a second algorithm, in link coordinates) with every effect of the options, the
// mass matrix is massMatrix()'s, and tau - h is exactly the right-hand side forwardDynamics()
// solves (its solution times M gives it back; at the gravity equilibrium it is exactly zero).
// Also for an arm with mimic joints, where both go through the full chain.
TEST(Dynamics, MassMatrixAndBiasAreTheTwoSidesForwardDynamicsSolves) {
  std::mt19937_64 rng(8);
  auto all = robots();
  UrdfOptions o;
  o.tip = "tool";
  o.requireDynamics = true;
  all.push_back(loadUrdf(std::string(RP_TEST_DATA_DIR) + "/mimic_arm.urdf", o));
  ASSERT_TRUE(all.back()->hasMimicJoints());
  for (auto& robot : all) {
    ManipulatorData data(*robot), ref(*robot);
    const int n = robot->getNumberOfJoints();
    const JointVector zero = JointVector::Zero(n);
    for (int trial = 0; trial < 100; ++trial) {
      const JointVector q = randomJoints(*robot, rng), qd = randomJoints(*robot, rng), tau = randomJoints(*robot, rng);
      DynamicsOptions opt;
      opt.motorInertia = trial % 2 == 0;
      opt.friction = trial % 3 == 0;
      opt.gravity = trial % 5 != 0;
      if (trial % 4 == 0) opt.tipWrench << 3, -2, 1, 0.5, -0.4, 0.3;
      const JointVector h = massMatrixAndBias(*robot, data, q, qd, opt);
      const JointMatrix M = data.massMatrix;
      const JointVector rnea = inverseDynamics(*robot, ref, q, qd, zero, opt);  // (the motor inertia times qdd = 0)
      for (int i = 0; i < n; ++i) EXPECT_NEAR(h(i), rnea(i), 1e-10 * (1 + std::abs(rnea(i)))) << robot->getName();
      const JointMatrix Mref = massMatrix(*robot, ref, q, opt.motorInertia);
      EXPECT_LT((M - Mref).cwiseAbs().maxCoeff(), 1e-12 * (1 + Mref.cwiseAbs().maxCoeff())) << robot->getName();
      const JointVector qdd = forwardDynamics(*robot, ref, q, qd, tau, opt);
      const JointVector back = M * qdd;
      for (int i = 0; i < n; ++i)
        EXPECT_NEAR(back(i), tau(i) - h(i), 1e-9 * (1 + std::abs(tau(i) - h(i)))) << robot->getName();
      for (int i = 0; i < n; ++i) EXPECT_EQ(ref.bias(i), h(i)) << robot->getName() << ": forwardDynamics()'s h";
    }
    // At the gravity equilibrium tau - h is exactly zero.
    const JointVector q = randomJoints(*robot, rng);
    JointVector g(n);
    gravityTorque(*robot, ref, q, g);
    DynamicsOptions opt;
    opt.motorInertia = true;
    const JointVector& h = massMatrixAndBias(*robot, data, q, zero, opt);
    for (int i = 0; i < n; ++i) EXPECT_EQ(g(i) - h(i), 0.0) << robot->getName() << " joint " << i + 1;
  }
}

TEST(Dynamics, ForwardDynamicsLeavesTheMassMatrixAndTheLinkFrames) {
  // What forwardDynamics() documents it leaves in the data, against massMatrix() and
  // forwardKinematics() run on their own.
  std::mt19937_64 rng(7);
  for (auto& robot : robots()) {
    ManipulatorData data(*robot), ref(*robot);
    const int n = robot->getNumberOfJoints();
    for (int trial = 0; trial < 20; ++trial) {
      const JointVector q = randomJoints(*robot, rng), qd = randomJoints(*robot, rng), tau = randomJoints(*robot, rng);
      DynamicsOptions opt;
      opt.motorInertia = trial % 2 == 0;
      forwardDynamics(*robot, data, q, qd, tau, opt);
      const JointMatrix M = massMatrix(*robot, ref, q, opt.motorInertia);
      EXPECT_LT((data.massMatrix - M).cwiseAbs().maxCoeff(), 1e-12 * (1 + M.cwiseAbs().maxCoeff())) << robot->getName();
      for (int k = 0; k < n; ++k) {
        const auto i = static_cast<std::size_t>(k);
        EXPECT_LT((data.linkTransforms[i] - ref.linkTransforms[i]).cwiseAbs().maxCoeff(), 1e-15) << robot->getName();
      }
      EXPECT_LT((data.endEffector - ref.endEffector).cwiseAbs().maxCoeff(), 1e-15) << robot->getName();
    }
  }
}

TEST(Dynamics, JacobianMatchesFiniteDifferencesOfForwardKinematics) {
  std::mt19937_64 rng(3);
  const double h = 1e-6;
  for (auto& robot : robots()) {
    ManipulatorData data(*robot), fd(*robot);
    for (int trial = 0; trial < 100; ++trial) {
      const JointVector q = randomJoints(*robot, rng);
      const Jacobian J = jacobian(*robot, data, q);
      const Transform T0 = forwardKinematics(*robot, fd, q);
      for (int j = 0; j < robot->getNumberOfJoints(); ++j) {
        JointVector qp = q, qm = q;
        qp(j) += h;
        qm(j) -= h;
        const Transform Tp = forwardKinematics(*robot, fd, qp);
        const Transform Tm = forwardKinematics(*robot, fd, qm);
        const Eigen::Vector3d v = (Tp.topRightCorner<3, 1>() - Tm.topRightCorner<3, 1>()) / (2 * h);
        // Angular velocity from dR/dq R^T (a skew matrix).
        const Eigen::Matrix3d S = (Tp.topLeftCorner<3, 3>() - Tm.topLeftCorner<3, 3>()) / (2 * h) *
                                  T0.topLeftCorner<3, 3>().transpose();
        const Eigen::Vector3d w(S(2, 1), S(0, 2), S(1, 0));
        for (int r = 0; r < 3; ++r) {
          EXPECT_NEAR(J(r, j), v(r), 1e-7) << robot->getName();
          EXPECT_NEAR(J(r + 3, j), w(r), 1e-7) << robot->getName();
        }
      }
    }
  }
}

TEST(Dynamics, TransposedJacobianMatchesNewtonEulerTipWrench) {
  // A wrench exerted by the last link on its environment costs J^T F in joint torque: compare
  // with the Newton-Euler algorithm's own tip-wrench path (gravity and motion off).
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-5, 5);
  for (auto& robot : robots()) {
    if (!robot->getToolTransform().isIdentity(0.0)) continue;  // the tip wrench acts at link frame n
    ManipulatorData data(*robot);
    const int n = robot->getNumberOfJoints();
    for (int trial = 0; trial < 100; ++trial) {
      const JointVector q = randomJoints(*robot, rng), z = JointVector(n);
      Vector<6> w;
      for (int i = 0; i < 6; ++i) w(i) = u(rng);
      DynamicsOptions opt;
      opt.gravity = false;
      opt.tipWrench = w;
      const JointVector tau = inverseDynamics(*robot, data, q, z, z, opt);
      JointVector viaJ(n);
      endEffectorForceToJointTorque(*robot, data, q, w, viaJ, ReferenceFrame::EndEffector);
      for (int i = 0; i < n; ++i) EXPECT_NEAR(tau(i), viaJ(i), 1e-10) << robot->getName();
    }
  }
}

}  // namespace
}  // namespace rp
