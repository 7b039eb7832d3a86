// Loading arms from URDF: forward kinematics against a direct walk of the URDF (urdfdom),
// dynamics against Orocos KDL built from the same URDF by kdl_parser, a round trip through
// the exporter, and clear errors for bad files.
#include <gtest/gtest.h>

#include <urdf_parser/urdf_parser.h>

#include <kdl/chain.hpp>
#include <kdl/chaindynparam.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <kdl/chainjnttojacsolver.hpp>

#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <numbers>
#include <random>
#include <sstream>
#include <tuple>

#include "KdlChain.hpp"
#include "KdlFromUrdf.hpp"
#include "ModifiedDh.hpp"
#include "rp/model/Dynamics.hpp"
#include "rp/model/Kinematics.hpp"
#include "rp/model/PhysicalModel.hpp"
#include "rp/model/Puma560Model.hpp"
#include "rp/model/UrdfExport.hpp"
#include "UrdfDom.hpp"
#include "rp/model/UrdfModel.hpp"
#include "ScratchDirectory.hpp"

namespace rp {
namespace {

const std::string kData = RP_TEST_DATA_DIR;

using test::parse;
using test::pose;

std::vector<urdf::JointConstSharedPtr> chainTo(const urdf::ModelInterfaceSharedPtr& robot, const std::string& tip) {
  std::vector<urdf::JointConstSharedPtr> chain;
  for (auto link = robot->getLink(tip); link->parent_joint; link = robot->getLink(link->parent_joint->parent_link_name))
    chain.push_back(link->parent_joint);
  std::reverse(chain.begin(), chain.end());
  return chain;
}

TEST(UrdfModel, ForwardKinematicsAndDynamicsMatchUrdfdomAndKdl) {
  UrdfOptions options;
  options.tip = "tool";
  options.requireDynamics = true;
  const std::unique_ptr<ManipulatorModel> model = loadUrdf(kData + "/test_arm.urdf", options);
  ASSERT_EQ(model->getNumberOfJoints(), 6);
  EXPECT_EQ(model->getName(), "test_arm");
  EXPECT_DOUBLE_EQ(model->getTorqueLimit()(0), 80);
  EXPECT_DOUBLE_EQ(model->getPositionMax()(1), 2.0);
  const urdf::ModelInterfaceSharedPtr robot = parse(kData + "/test_arm.urdf");
  const KDL::Chain chain = test::kdlArm(kData + "/test_arm.urdf", robot, "tool").chain;  // the camera lumped into l3
  KDL::ChainIdSolver_RNE id(chain, KDL::Vector(0, 0, -9.81));
  KDL::ChainJntToJacSolver jac(chain);
  KDL::ChainDynParam dyn(chain, KDL::Vector(0, 0, -9.81));
  ManipulatorData data(*model);
  std::mt19937_64 rng(77);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 500; ++trial) {
    JointVector q(6), qd(6), qdd(6);
    for (int i = 0; i < 6; ++i) {
      q(i) = 2 * u(rng);
      qd(i) = u(rng);
      qdd(i) = 3 * u(rng);
    }
    // Walk the URDF: T = prod origin_j * Rot(axis_j, q_j).
    Transform T = Transform::unit();
    int k = 0;
    for (const urdf::JointConstSharedPtr& j : chainTo(robot, "tool")) {
      T = Transform(T * pose(j->parent_to_joint_origin_transform));
      if (j->type != urdf::Joint::FIXED) T = Transform(T * rotation(Vector<3>{{j->axis.x}, {j->axis.y}, {j->axis.z}}, q(k++)));
    }
    ASSERT_LT((forwardKinematics(*model, data, q) - T).cwiseAbs().maxCoeff(), 1e-12);

    const KDL::JntArray kq = test::kdlJoints(q), kqd = test::kdlJoints(qd), kqdd = test::kdlJoints(qdd);
    KDL::Jacobian kj(6);
    jac.JntToJac(kq, kj);
    const Jacobian& J = jacobian(*model, data, q);
    for (int r = 0; r < 6; ++r)
      for (int c = 0; c < 6; ++c) ASSERT_NEAR(J(r, c), kj(static_cast<unsigned>(r), static_cast<unsigned>(c)), 1e-10);
    KDL::JntArray ktau(6);
    KDL::Wrenches w(chain.getNrOfSegments(), KDL::Wrench::Zero());
    id.CartToJnt(kq, kqd, kqdd, w, ktau);
    const JointVector& tau = inverseDynamics(*model, data, q, qd, qdd);
    for (int i = 0; i < 6; ++i) ASSERT_NEAR(tau(i), ktau(static_cast<unsigned>(i)), 1e-9) << "joint " << i + 1;
    KDL::JntSpaceInertiaMatrix km(6);
    dyn.JntToMass(kq, km);
    const JointMatrix& M = massMatrix(*model, data, q);
    for (int r = 0; r < 6; ++r)
      for (int c = 0; c < 6; ++c) ASSERT_NEAR(M(r, c), km(static_cast<unsigned>(r), static_cast<unsigned>(c)), 1e-9);
  }
}

// The URDF walk: T = prod origin_j * Rot(axis_j, q_j) or Trans(axis_j, q_j).
Transform walk(const urdf::ModelInterfaceSharedPtr& robot, const std::string& tip, const JointVector& q) {
  Transform T = Transform::unit();
  int k = 0;
  for (const urdf::JointConstSharedPtr& j : chainTo(robot, tip)) {
    T = Transform(T * pose(j->parent_to_joint_origin_transform));
    const Vector<3> axis{{j->axis.x}, {j->axis.y}, {j->axis.z}};
    if (j->type == urdf::Joint::PRISMATIC) T = Transform(T * translation(Vector<3>(q(k++) * axis.normalized())));
    else if (j->type != urdf::Joint::FIXED) T = Transform(T * rotation(axis, q(k++)));
  }
  return T;
}

TEST(UrdfModel, PrismaticJointsMatchUrdfWalkAndKdl) {
  UrdfOptions options;
  options.tip = "tool";
  options.requireDynamics = true;
  const std::unique_ptr<ManipulatorModel> model = loadUrdf(kData + "/prismatic_arm.urdf", options);
  ASSERT_EQ(model->getNumberOfJoints(), 6);
  EXPECT_TRUE(model->isPrismatic(1));
  EXPECT_TRUE(model->isPrismatic(3));
  EXPECT_FALSE(model->isPrismatic(0));
  EXPECT_DOUBLE_EQ(model->getPositionMin()(1), -0.2);
  EXPECT_DOUBLE_EQ(model->getPositionMax()(3), 0.35);
  EXPECT_DOUBLE_EQ(model->getTorqueLimit()(1), 300);
  const urdf::ModelInterfaceSharedPtr robot = parse(kData + "/prismatic_arm.urdf");
  const KDL::Chain chain = test::kdlArm(kData + "/prismatic_arm.urdf", robot, "tool").chain;
  KDL::ChainFkSolverPos_recursive fk(chain);
  KDL::ChainIdSolver_RNE id(chain, KDL::Vector(0, 0, -9.81));
  KDL::ChainJntToJacSolver jac(chain);
  KDL::ChainDynParam dyn(chain, KDL::Vector(0, 0, -9.81));
  ManipulatorData data(*model);
  std::mt19937_64 rng(78);
  std::uniform_real_distribution<double> u(0, 1);
  double worstFk = 0, worstJ = 0, worstTau = 0, worstM = 0;
  for (int trial = 0; trial < 1000; ++trial) {
    JointVector q(6), qd(6), qdd(6);
    for (int i = 0; i < 6; ++i) {
      q(i) = model->getPositionMin()(i) + u(rng) * (model->getPositionMax()(i) - model->getPositionMin()(i));
      qd(i) = 2 * u(rng) - 1;
      qdd(i) = 6 * u(rng) - 3;
    }
    const Transform& T = forwardKinematics(*model, data, q);
    worstFk = std::max(worstFk, (T - walk(robot, "tool", q)).cwiseAbs().maxCoeff());
    const KDL::JntArray kq = test::kdlJoints(q), kqd = test::kdlJoints(qd), kqdd = test::kdlJoints(qdd);
    KDL::Frame f;
    ASSERT_GE(fk.JntToCart(kq, f), 0);
    for (int r = 0; r < 3; ++r) {
      worstFk = std::max(worstFk, std::abs(T(r, 3) - f.p(r)));
      for (int c = 0; c < 3; ++c) worstFk = std::max(worstFk, std::abs(T(r, c) - f.M(r, c)));
    }
    KDL::Jacobian kj(6);
    ASSERT_GE(jac.JntToJac(kq, kj), 0);
    const Jacobian& J = jacobian(*model, data, q);
    for (int r = 0; r < 6; ++r)
      for (int c = 0; c < 6; ++c) worstJ = std::max(worstJ, std::abs(J(r, c) - kj(static_cast<unsigned>(r), static_cast<unsigned>(c))));
    kj.changeBase(f.M.Inverse());
    const Jacobian& Je = jacobian(*model, data, q, ReferenceFrame::EndEffector);
    for (int r = 0; r < 6; ++r)
      for (int c = 0; c < 6; ++c) worstJ = std::max(worstJ, std::abs(Je(r, c) - kj(static_cast<unsigned>(r), static_cast<unsigned>(c))));
    KDL::JntArray ktau(6);
    KDL::Wrenches w(chain.getNrOfSegments(), KDL::Wrench::Zero());
    ASSERT_GE(id.CartToJnt(kq, kqd, kqdd, w, ktau), 0);
    const JointVector& tau = inverseDynamics(*model, data, q, qd, qdd);
    for (int i = 0; i < 6; ++i) worstTau = std::max(worstTau, std::abs(tau(i) - ktau(static_cast<unsigned>(i))));
    KDL::JntSpaceInertiaMatrix km(6);
    ASSERT_GE(dyn.JntToMass(kq, km), 0);
    const JointMatrix& M = massMatrix(*model, data, q);
    for (int r = 0; r < 6; ++r)
      for (int c = 0; c < 6; ++c) worstM = std::max(worstM, std::abs(M(r, c) - km(static_cast<unsigned>(r), static_cast<unsigned>(c))));
  }
  EXPECT_LT(worstFk, 1e-9);
  EXPECT_LT(worstJ, 1e-9);
  EXPECT_LT(worstTau, 1e-9);
  EXPECT_LT(worstM, 1e-9);
}

TEST(UrdfModel, ExportedPrismaticAndModifiedDhArmsLoadBack) {
  UrdfOptions options;
  options.tip = "tool";
  const std::unique_ptr<ManipulatorModel> arm = loadUrdf(kData + "/prismatic_arm.urdf", options);
  const std::unique_ptr<ManipulatorModel> mdh = test::toModifiedDh(Puma560Model());
  for (const ManipulatorModel* model : {arm.get(), mdh.get()}) {
    const std::string text = toUrdf(*model);
    const test::ScratchFile file(model->getName() + "_roundtrip.urdf");
    std::ofstream(file) << text;
    const std::unique_ptr<ManipulatorModel> back = loadUrdf(file, options);
    ASSERT_EQ(back->getNumberOfJoints(), model->getNumberOfJoints());
    const int n = model->getNumberOfJoints();
    for (int i = 0; i < n; ++i) EXPECT_EQ(back->isPrismatic(i), model->isPrismatic(i)) << model->getName();
    // The export writes physicalModel()'s inertias (the Puma's links 1 and 3 are not physical).
    const PhysicalModel exported = physicalModel(*model);
    ManipulatorData a(exported.model), b(*back);
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(0, 1);
    for (int trial = 0; trial < 200; ++trial) {
      JointVector q(n), qd(n), qdd(n);
      for (int i = 0; i < n; ++i) {
        q(i) = model->getPositionMin()(i) + u(rng) * (model->getPositionMax()(i) - model->getPositionMin()(i));
        qd(i) = 2 * u(rng) - 1;
        qdd(i) = 2 * u(rng) - 1;
      }
      ASSERT_LT((forwardKinematics(exported.model, a, q) - forwardKinematics(*back, b, q)).cwiseAbs().maxCoeff(), 1e-12);
      const JointVector t1 = inverseDynamics(exported.model, a, q, qd, qdd), t2 = inverseDynamics(*back, b, q, qd, qdd);
      for (int i = 0; i < n; ++i) ASSERT_NEAR(t1(i), t2(i), 1e-9) << model->getName();
    }
  }
}

TEST(UrdfModel, ExportedPumaLoadsBackWithTheSameKinematicsAndDynamics) {
  const Puma560Model puma;
  const test::ScratchFile file("puma560_roundtrip.urdf");
  std::ofstream(file) << toUrdf(puma);
  UrdfOptions options;
  options.tip = "tool";
  const std::unique_ptr<ManipulatorModel> back = loadUrdf(file, options);
  // The export writes physicalModel()'s inertias (the Puma's links 1 and 3 are not physical).
  const PhysicalModel exported = physicalModel(puma);
  ManipulatorData a(exported.model), b(*back);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-2, 2);
  for (int trial = 0; trial < 200; ++trial) {
    JointVector q(6), qd(6), qdd(6);
    for (int i = 0; i < 6; ++i) {
      q(i) = u(rng);
      qd(i) = u(rng);
      qdd(i) = u(rng);
    }
    ASSERT_LT((forwardKinematics(exported.model, a, q) - forwardKinematics(*back, b, q)).cwiseAbs().maxCoeff(), 1e-12);
    const JointVector t1 = inverseDynamics(exported.model, a, q, qd, qdd), t2 = inverseDynamics(*back, b, q, qd, qdd);
    for (int i = 0; i < 6; ++i) ASSERT_NEAR(t1(i), t2(i), 1e-9);
  }
}

TEST(UrdfModel, BadFilesGiveClearErrors) {
  auto message = [](const std::string& file, const UrdfOptions& o = UrdfOptions()) -> std::string {
    try {
      loadUrdf(file, o);
    } catch (const UrdfError& e) {
      return e.what();
    }
    return "no error";
  };
  EXPECT_EQ(message(kData + "/missing.urdf"), kData + "/missing.urdf: cannot read the file");
  // Malformed XML: where TinyXML found it (the document ends inside <robot>, line 3 column 1).
  EXPECT_EQ(message(kData + "/bad_xml.urdf"),
            kData + "/bad_xml.urdf:3:1: not a valid URDF document: malformed XML (Error reading end tag)");
  EXPECT_NE(message(kData + "/floating.urdf").find("joint 'free' is floating or planar"), std::string::npos);
  UrdfOptions unknownTip;
  unknownTip.tip = "gripper";
  EXPECT_NE(message(kData + "/test_arm.urdf", unknownTip).find("there is no link 'gripper'"), std::string::npos);
  UrdfOptions dynamics;
  dynamics.requireDynamics = true;
  EXPECT_NE(message(kData + "/no_inertia.urdf", dynamics).find("link 'b' has no inertial data"), std::string::npos);
  EXPECT_EQ(message(kData + "/no_inertia.urdf"), "no error") << "kinematics only is fine";
}

// A URDF given as text (a robot_description from the network): the same model as from the file,
// the same errors with the given source name in place of the file's, and the velocity limits
// scaled where UrdfOptions::velocityLimitScale says (limits the file leaves out keep the default).
TEST(UrdfModel, TextLoadsAsTheFileDoesAndVelocityLimitsScale) {
  auto read = [](const std::string& file) {
    std::ifstream in(file);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  };
  const std::string text = read(kData + "/test_arm.urdf");
  ASSERT_FALSE(text.empty());
  const auto fromFile = loadUrdf(kData + "/test_arm.urdf");
  const auto fromText = loadUrdfString(text);
  ASSERT_EQ(fromText->getNumberOfJoints(), fromFile->getNumberOfJoints());
  ManipulatorData a(*fromFile), b(*fromText);
  JointVector q(fromFile->getNumberOfJoints());
  for (int i = 0; i < q.size(); ++i) q(i) = 0.3 * (i + 1) - 0.7;
  EXPECT_TRUE(forwardKinematics(*fromText, b, q).isApprox(forwardKinematics(*fromFile, a, q), 0));
  EXPECT_EQ(fromText->getVelocityLimit(), fromFile->getVelocityLimit());

  UrdfOptions slower;
  slower.velocityLimitScale = 0.8;
  const auto scaled = loadUrdfString(text, slower);
  const urdf::ModelInterfaceSharedPtr robot = parse(kData + "/test_arm.urdf");
  int given = 0;
  for (int i = 0; i < scaled->getNumberOfJoints(); ++i) {
    const urdf::JointConstSharedPtr j = robot->getJoint(scaled->getJointName(i));
    ASSERT_TRUE(j);
    if (j->limits && j->limits->velocity > 0) {
      ++given;
      EXPECT_EQ(scaled->getVelocityLimit()(i), 0.8 * j->limits->velocity) << scaled->getJointName(i);
    } else {  // the default, unscaled (j4 is continuous, without a velocity)
      EXPECT_EQ(scaled->getVelocityLimit()(i), fromFile->getVelocityLimit()(i)) << scaled->getJointName(i);
    }
  }
  EXPECT_GE(given, 4);
  EXPECT_LT(given, scaled->getNumberOfJoints()) << "both cases are covered";

  auto message = [](const std::string& text, const UrdfOptions& o, const std::string& source) -> std::string {
    try {
      loadUrdfString(text, o, source);
    } catch (const UrdfError& e) {
      return e.what();
    }
    return "no error";
  };
  EXPECT_EQ(message(read(kData + "/bad_xml.urdf"), UrdfOptions(), "<string>"),
            "<string>:3:1: not a valid URDF document: malformed XML (Error reading end tag)");
  EXPECT_EQ(message(text, slower, "rt/cell/puma/robot_description"), "no error");
  for (const double bad : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    UrdfOptions o;
    o.velocityLimitScale = bad;
    try {
      loadUrdfString(text, o, "desc");
      ADD_FAILURE() << "velocityLimitScale " << bad << " taken";
    } catch (const UrdfOptionError& e) {
      EXPECT_EQ(e.option(), "velocityLimitScale");
      EXPECT_EQ(std::string(e.what()).rfind("desc: UrdfOptions::velocityLimitScale: must be a positive number", 0), 0u) << e.what();
    }
  }
}

// Issue 20: a branch that carries only fixed frames (a camera, tool0, a base frame) is no branch:
// without a tip the arm runs to its last moving link, and stops before a gripper, whose moving
// links are lumped with a note.
TEST(UrdfModel, DefaultTipIgnoresBranchesOfFixedFramesAndStopsBeforeGrippers) {
  std::vector<std::string> notes;
  UrdfOptions options;
  options.notes = &notes;
  std::unique_ptr<ManipulatorModel> model = loadUrdf(kData + "/test_arm.urdf", options);  // a camera on l3
  ASSERT_EQ(model->getNumberOfJoints(), 6);
  EXPECT_EQ(model->getLinkName(5), "l6");
  model = loadUrdf(kData + "/ur_like.urdf", options);  // fixed frames at the base and the wrist
  ASSERT_EQ(model->getNumberOfJoints(), 6);
  EXPECT_EQ(model->getJointName(0), "shoulder_pan_joint");
  EXPECT_EQ(model->getLinkName(5), "wrist_3_link");
  UrdfOptions explicitTip;
  explicitTip.tip = "wrist_3_link";
  const std::unique_ptr<ManipulatorModel> same = loadUrdf(kData + "/ur_like.urdf", explicitTip);
  ManipulatorData a(*model), b(*same);
  const JointVector q = JointVector::Constant(6, 0.3);
  EXPECT_EQ(forwardKinematics(*model, a, q), forwardKinematics(*same, b, q));
  EXPECT_TRUE(notes.empty());
  model = loadUrdf(kData + "/jaw_arm.urdf", options);
  ASSERT_EQ(model->getNumberOfJoints(), 6);
  EXPECT_EQ(model->getLinkName(5), "link06");
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_EQ(notes[0], kData + "/jaw_arm.urdf: links 'gripperMover' move off the chain: their mass is lumped into 'link06' "
                              "at jointGripper = 0 rad (other values: UrdfOptions::offChainPositions, rp.cfg "
                              "offChainPositions, rp-model --offchain)");
  notes.clear();
  model = loadUrdf(kData + "/panda_like.urdf", options);
  ASSERT_EQ(model->getNumberOfJoints(), 7);
  EXPECT_EQ(model->getLinkName(6), "link7");
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("links 'leftfinger', 'rightfinger' move off the chain: their mass is lumped into 'link7' at "
                          "finger_joint1 = 0 m, finger_joint2 = 0 m"),
            std::string::npos)
      << notes[0];
}

// Moving links off the chain are lumped at the stated configuration: the jaw arm's gravity torque
// with its jaw lumped equals the seven-joint arm's (jaw a joint) at the same jaw angle; a mimic
// finger follows its master (multiplier and offset); mimics naming a missing joint, going round in
// a circle or lying on the chain are refused.
TEST(UrdfModel, MovingLinksOffTheChainAreLumpedAtTheStatedConfiguration) {
  UrdfOptions withJaw;
  withJaw.tip = "gripperMover";
  withJaw.requireDynamics = true;
  const std::unique_ptr<ManipulatorModel> seven = loadUrdf(kData + "/jaw_arm.urdf", withJaw);
  ASSERT_EQ(seven->getNumberOfJoints(), 7);
  ManipulatorData d7(*seven);
  for (const double jaw : {0.0, -0.8}) {
    UrdfOptions lumped;
    lumped.tip = "link06";
    lumped.requireDynamics = true;
    if (jaw != 0.0) lumped.offChainPositions["jointGripper"] = jaw;
    const std::unique_ptr<ManipulatorModel> six = loadUrdf(kData + "/jaw_arm.urdf", lumped);
    ASSERT_EQ(six->getNumberOfJoints(), 6);
    ManipulatorData d6(*six);
    JointVector q6(6), q7(7), g6(6), g7(7);
    for (int i = 0; i < 6; ++i) q6(i) = q7(i) = 0.3 * (i + 1) - 1;
    q7(6) = jaw;
    gravityTorque(*six, d6, q6, g6);
    gravityTorque(*seven, d7, q7, g7);
    for (int i = 0; i < 6; ++i) EXPECT_NEAR(g6(i), g7(i), 1e-12 * (1 + std::abs(g7(i)))) << "joint " << i + 1 << " jaw " << jaw;
    // Link 6 carries the stator and the 0.276 kg jaw (the jaw used to be dropped).
    EXPECT_NEAR(six->getLink(5).mass, 0.34 + 0.52 + 0.276, 1e-12);
  }
  const std::string text = [] {
    std::ifstream in(kData + "/panda_like.urdf");
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }();
  const test::ScratchFile file("panda_variant.urdf");
  auto variant = [&](const std::string& from, const std::string& to) -> std::string {
    std::string t = text;
    const std::size_t at = t.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    t.replace(at, from.size(), to);
    std::ofstream(file.path()) << t;
    return file;
  };
  auto error = [](const std::string& file, const std::string& tip = "") -> std::string {
    try {
      UrdfOptions o;
      o.tip = tip;
      loadUrdf(file, o);
    } catch (const UrdfError& e) {
      return e.what();
    }
    return "no error";
  };
  // The mimic finger at multiplier 2 and offset 0.01 with its master at 0.015: the right finger sits
  // at 0.04 along -y, which moves the lumped centre of mass by the same as moving it by hand.
  std::string f = variant("<mimic joint=\"finger_joint1\"/>", "<mimic joint=\"finger_joint1\" multiplier=\"2\" offset=\"0.01\"/>");
  UrdfOptions open;
  open.offChainPositions["finger_joint1"] = 0.015;
  std::vector<std::string> notes;
  open.notes = &notes;
  const std::unique_ptr<ManipulatorModel> a = loadUrdf(f, open);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("finger_joint1 = 0.015 m, finger_joint2 = 0.04 m"), std::string::npos) << notes[0];
  const std::unique_ptr<ManipulatorModel> closed = loadUrdf(kData + "/panda_like.urdf");
  // Finger masses 0.015 each, hand rotated -45 deg about z in link7: the fingers open along the
  // hand's y axis by 0.015 (left, +y) and 0.04 (right, -y).
  const double m = a->getLink(6).mass;
  const Eigen::Vector3d shift = (Eigen::Vector3d(a->getLink(6).com) - Eigen::Vector3d(closed->getLink(6).com)) * m;
  const Eigen::Vector3d handY(std::sin(0.7853981633974483), std::cos(0.7853981633974483), 0);  // Rz(-45 deg) y
  EXPECT_LT((shift - 0.015 * (0.015 - 0.04) * handY).norm(), 1e-12) << shift.transpose();
  f = variant("<mimic joint=\"finger_joint1\"/>", "<mimic joint=\"no_such_joint\"/>");
  EXPECT_EQ(error(f), f + ": joint 'finger_joint2' mimics joint 'no_such_joint', which does not exist");
  f = variant("<mimic joint=\"finger_joint1\"/>", "<mimic joint=\"finger_joint2\"/>");
  EXPECT_EQ(error(f), f + ": joint 'finger_joint2' mimics 'finger_joint2': the mimic joints go round in a circle");
  // The right finger as the tip puts the mimic finger_joint2 on the chain, its master off it.
  EXPECT_EQ(error(kData + "/panda_like.urdf", "rightfinger"),
            kData + "/panda_like.urdf: joint 'finger_joint2' mimics joint 'finger_joint1', which is not a joint of the "
                    "chain; a mimic joint on the chain follows a joint of the chain");
}

// UrdfOptions::offChainPositions: each entry must name a moving joint off the chain that moves a
// lumped link, with a finite value within its limits; else UrdfOptionError names the file, the
// option and the joint (and lists the moving joints off the chain). In rp.cfg's units (degrees
// and millimetres) the same positions lump the same masses.
TEST(UrdfModel, OffChainPositionsAreCheckedAndNamed) {
  const std::string jaw = kData + "/jaw_arm.urdf", panda = kData + "/panda_like.urdf";
  auto error = [](const std::string& file, const std::map<std::string, double>& positions, bool degrees = false) {
    UrdfOptions o;
    o.offChainPositions = positions;
    o.offChainInDegreesAndMillimetres = degrees;
    try {
      loadUrdf(file, o);
    } catch (const UrdfOptionError& e) {
      EXPECT_EQ(e.option(), "offChainPositions");
      EXPECT_EQ(std::string(e.what()), file + ": UrdfOptions::offChainPositions: " + e.problem());
      return e.problem();
    }
    return std::string("no error");
  };
  EXPECT_EQ(error(jaw, {{"jointGripper", -1.2}}), "no error");
  EXPECT_EQ(error(jaw, {{"nosuch", 0}}), "there is no joint 'nosuch' (moving joints off the chain: jointGripper)");
  EXPECT_EQ(error(jaw, {{"jointGripper", std::nan("")}}), "joint 'jointGripper': the value is not finite");
  EXPECT_EQ(error(jaw, {{"joint3", 0.1}}), "joint 'joint3' is a joint of the arm, not off the chain (moving joints off "
                                           "the chain: jointGripper)");
  EXPECT_EQ(error(jaw, {{"jointGripper", 0.5}}), "joint 'jointGripper': 0.5 rad is outside its limits -1.57 .. 0 rad");
  EXPECT_EQ(error(jaw, {{"jointGripper", -100}}, true), "joint 'jointGripper': -100 deg is outside its limits -89.9544 .. 0 deg");
  EXPECT_EQ(error(panda, {{"finger_joint1", 50}}, true), "joint 'finger_joint1': 50 mm is outside its limits 0 .. 40 mm");
  EXPECT_EQ(error(panda, {{"joint8", 0}}), "joint 'joint8' is fixed, floating or planar: it has no position (moving "
                                           "joints off the chain: finger_joint1, finger_joint2)");
  // Degrees and millimetres: the same lumped masses as radians and metres.
  for (const auto& [file, joint, si, cfg] : {std::tuple{jaw, "jointGripper", -1.2, -1.2 * 180 / std::numbers::pi},
                                             std::tuple{panda, "finger_joint1", 0.03, 30.0}}) {
    UrdfOptions a, b;
    a.offChainPositions[joint] = si;
    b.offChainPositions[joint] = cfg;
    b.offChainInDegreesAndMillimetres = true;
    const std::unique_ptr<ManipulatorModel> ma = loadUrdf(file, a), mb = loadUrdf(file, b), closed = loadUrdf(file);
    const int last = ma->getNumberOfJoints() - 1;
    // The lumped link's mass distribution: its first moment and inertia (the Panda's fingers open
    // symmetrically, which keeps the centre of mass and changes the inertia).
    auto differ = [&](const ManipulatorModel& x, const ManipulatorModel& y) {
      const LinkParameters &l = x.getLink(last), &r = y.getLink(last);
      return (Eigen::Vector3d(l.com) - Eigen::Vector3d(r.com)).norm() + (Eigen::Matrix3d(l.inertia) - Eigen::Matrix3d(r.inertia)).norm();
    };
    EXPECT_LT(differ(*ma, *mb), 1e-15) << file;
    EXPECT_GT(differ(*ma, *closed), 1e-6) << file << ": the position changes the lumped link";
  }
}

// A mimic joint on the chain that names a missing joint is refused, naming the file and both
// joints; one whose limits leave its master no position too; the arm loads with its own mimics.
TEST(UrdfModel, MimicJointOnTheChainNamingAMissingJointIsRefused) {
  std::ifstream in(kData + "/mimic_arm.urdf");
  std::stringstream text;
  text << in.rdbuf();
  const test::ScratchFile file("mimic_variant.urdf");
  auto variant = [&](const std::string& from, const std::string& to) -> std::string {
    std::string t = text.str();
    const std::size_t at = t.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    t.replace(at, from.size(), to);
    std::ofstream(file.path()) << t;
    return file;
  };
  auto error = [](const std::string& file) -> std::string {
    try {
      loadUrdf(file);
    } catch (const UrdfError& e) {
      return e.what();
    }
    return "no error";
  };
  EXPECT_EQ(error(kData + "/mimic_arm.urdf"), "no error");
  std::string f = variant("<mimic joint=\"shoulder\"", "<mimic joint=\"shoulder_motor\"");
  EXPECT_EQ(error(f), f + ": joint 'elbow_link' mimics joint 'shoulder_motor', which does not exist");
  f = variant("<mimic joint=\"shoulder\" multiplier=\"-1\" offset=\"0.3\"/>", "<mimic joint=\"shoulder\" offset=\"5\"/>");
  EXPECT_EQ(error(f), f + ": ManipulatorModel 'mimic_arm': mimic joint 'elbow_link': its position limits leave joint "
                          "'shoulder' no position");
}

// Issue 19: bad URDF files never hang or crash the process.
class UrdfInputTest : public ::testing::Test {
 protected:
  std::string write(const std::string& name, const std::string& text) {
    const std::string file = (dir_ / name).string();
    std::ofstream(file) << text;
    return file;
  }
  static std::string message(const std::string& file, const UrdfOptions& o = UrdfOptions()) {
    try {
      loadUrdf(file, o);
    } catch (const UrdfError& e) {
      return e.what();
    }
    return "no error";
  }
  static std::string joint(const std::string& name, const std::string& type, const std::string& parent,
                           const std::string& child) {
    return "<joint name=\"" + name + "\" type=\"" + type + "\"><parent link=\"" + parent + "\"/><child link=\"" + child +
           "\"/><origin xyz=\"0 0 0.001\"/><axis xyz=\"0 0 1\"/><limit lower=\"-1\" upper=\"1\" effort=\"1\" "
           "velocity=\"1\"/></joint>\n";
  }
  static std::string inertial(const std::string& mass, const std::string& ixx = "1", const std::string& origin = "") {
    return "<inertial>" + origin + "<mass value=\"" + mass + "\"/><inertia ixx=\"" + ixx +
           "\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/></inertial>";
  }
  // A revolute joint a -> l0, then `n` fixed links l0 -> l1 -> ... -> ln, each 1 g.
  std::string fixedChain(int n) {
    std::string text = "<robot name=\"long\"><link name=\"a\"/>\n";
    for (int i = 0; i <= n; ++i) text += "<link name=\"l" + std::to_string(i) + "\">" + inertial("0.001") + "</link>\n";
    text += joint("j", "revolute", "a", "l0");
    for (int i = 1; i <= n; ++i)
      text += joint("f" + std::to_string(i), "fixed", "l" + std::to_string(i - 1), "l" + std::to_string(i));
    return write("long.urdf", text + "</robot>\n");
  }
  std::filesystem::path dir_ = [] {
    auto d = std::filesystem::temp_directory_path() / ("rp_urdf_input_" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  ~UrdfInputTest() override { std::filesystem::remove_all(dir_); }
};

TEST_F(UrdfInputTest, KinematicLoopsAreRefused) {
  // Used to hang: the walk from the root to the tip went round the loop for ever.
  EXPECT_EQ(message(kData + "/kinematic_loop.urdf"),
            kData + "/kinematic_loop.urdf: link 'b' is the child of two joints ('j1' and 'j3'): a kinematic loop; "
                    "a manipulator's links must form a tree");
  // A loop away from the root: each link has one parent, but the loop hangs off nothing.
  const std::string island =
      write("island.urdf", "<robot name=\"island\"><link name=\"r\"/><link name=\"x\"/><link name=\"y\"/>" +
                               joint("jx", "revolute", "y", "x") + joint("jy", "revolute", "x", "y") + "</robot>");
  UrdfOptions tipX;
  tipX.tip = "x";
  EXPECT_EQ(message(island, tipX), island + ": link 'x' cannot be reached from the root link 'r': a kinematic loop; "
                                            "a manipulator's links must form a tree");
  // Found by rp_urdf_fuzzer: a link that is its own parent next to a joint urdfdom then refused
  // (its parent element has no link attribute); urdfdom leaked the looped link.
  const std::string self = write("self.urdf", "<robot name=\"self\"><link name=\"a\"/><link name=\"b\"/>" +
                                                  joint("j1", "revolute", "a", "b") + joint("j2", "revolute", "b", "b") +
                                                  "<joint name=\"j3\" type=\"fixed\"><parent lnk=\"b\"/><child link=\"a\"/></joint>"
                                                  "</robot>");
  EXPECT_EQ(message(self), self + ": link 'b' is the child of two joints ('j1' and 'j2'): a kinematic loop; "
                                  "a manipulator's links must form a tree");
  const std::string noRoot = write("noroot.urdf", "<robot name=\"n\"><link name=\"a\"/>" +
                                                      joint("j", "revolute", "a", "a") + "</robot>");
  EXPECT_EQ(message(noRoot), noRoot + ": there is no root link (every link is the child of a joint): a kinematic "
                                      "loop; a manipulator's links must form a tree");
}

// What urdfdom would refuse only after building part of the tree is refused before it.
// Issue 20: two moving chains that are not a gripper are a real choice: the message lists the tips.
TEST_F(UrdfInputTest, ARealBranchListsTheCandidateTips) {
  const std::string f = write("two.urdf", "<robot name=\"two\"><link name=\"base\"/><link name=\"torso\"/><link name=\"left1\"/>"
                                          "<link name=\"left2\"/><link name=\"right1\"/><link name=\"camera\"/>" +
                                              joint("waist", "revolute", "base", "torso") + joint("l1", "revolute", "torso", "left1") +
                                              joint("l2", "revolute", "left1", "left2") + joint("r1", "revolute", "torso", "right1") +
                                              joint("cam", "fixed", "torso", "camera") + "</robot>");
  EXPECT_EQ(message(f), f + ": the robot branches at link 'torso' into 2 moving chains; name the tip link, one of "
                            "'camera', 'left2', 'right1'");
  UrdfOptions tip;
  tip.tip = "left2";
  EXPECT_EQ(message(f, tip), "no error");
}

TEST_F(UrdfInputTest, JointsMustNameDefinedLinksAndOneRoot) {
  const std::string base = "<robot name=\"r\"><link name=\"a\"/><link name=\"b\"/>";
  std::string f = write("j.urdf", base + joint("j", "revolute", "a", "c") + "</robot>");
  EXPECT_EQ(message(f), f + ": joint 'j': there is no link 'c'");
  f = write("j.urdf", base + "<joint name=\"j\" type=\"fixed\"><child link=\"b\"/></joint></robot>");
  EXPECT_EQ(message(f), f + ": joint 'j' has no parent link");
  f = write("j.urdf", base + "<link name=\"c\"/>" + joint("j", "revolute", "a", "b") + "</robot>");
  EXPECT_EQ(message(f), f + ": links 'a' and 'c' both have no parent joint; a robot has one root link");
}

// What urdfdom itself refuses, it names (through console_bridge): the UrdfError carries its
// errors (without its follow-up "joint xml is not initialized correctly"), and where the XML is
// malformed the line and column.
TEST_F(UrdfInputTest, UrdfdomsOwnErrorsAndTheLineOfMalformedXmlAreInTheMessage) {
  const std::string base = "<robot name=\"r\"><link name=\"a\"/><link name=\"b\"/>";
  std::string f = write("u.urdf", base + "<joint name=\"ball\" type=\"spherical\"><parent link=\"a\"/>"
                                           "<child link=\"b\"/></joint></robot>");
  EXPECT_EQ(message(f), f + ": not a valid URDF document: Joint [ball] has no known type [spherical]");
  f = write("u.urdf", base + "<joint name=\"elbow\" type=\"revolute\"><parent link=\"a\"/><child link=\"b\"/>"
                             "</joint></robot>");
  EXPECT_EQ(message(f), f + ": not a valid URDF document: Joint [elbow] is of type REVOLUTE but it does not specify limits");
  f = write("u.urdf", "<notrobot/>");
  EXPECT_EQ(message(f), f + ": not a valid URDF document: Could not find the 'robot' element in the xml file");
  f = write("u.urdf", "<robot name=\"r\">\n  <link name=\"a\">\n  <link name=\"b\"/>\n</robot>\n");
  EXPECT_EQ(message(f), f + ":4:1: not a valid URDF document: malformed XML (Error reading end tag)");
  // Loading again works: the collector of urdfdom's errors was taken off again.
  EXPECT_EQ(message(kData + "/test_arm.urdf"), "no error");
}

// Found by rp_urdf_fuzzer: limits the model refuses were thrown as a bare std::invalid_argument
// without the file (the fuzzer, catching UrdfError only, aborted).
TEST_F(UrdfInputTest, LimitsTheModelRefusesNameTheFileAndJoint) {
  const std::string f = write("limits.urdf",
                              "<robot name=\"r\"><link name=\"a\"/><link name=\"b\"/><joint name=\"j\" type=\"revolute\">"
                              "<parent link=\"a\"/><child link=\"b\"/><axis xyz=\"0 0 1\"/>"
                              "<limit lower=\"1\" upper=\"-1\" effort=\"1\" velocity=\"1\"/></joint></robot>");
  EXPECT_EQ(message(f), f + ": joint 'j': <limit> lower 1 is above upper -1");
  // The same on a moving joint off the chain (a finger lumped into the arm's last link): it used
  // to go to std::clamp(0, 1, -1), which is undefined behaviour.
  const std::string g = write("offchain.urdf",
                              "<robot name=\"r\"><link name=\"a\"/><link name=\"b\"/>"
                              "<link name=\"c\"><inertial><mass value=\"1\"/>"
                              "<inertia ixx=\"0.01\" ixy=\"0\" ixz=\"0\" iyy=\"0.01\" iyz=\"0\" izz=\"0.01\"/></inertial></link>" +
                                  joint("j", "revolute", "a", "b") +
                                  "<joint name=\"finger\" type=\"revolute\"><parent link=\"b\"/><child link=\"c\"/>"
                                  "<axis xyz=\"0 0 1\"/><limit lower=\"1\" upper=\"-1\" effort=\"1\" velocity=\"1\"/></joint>"
                                  "</robot>");
  UrdfOptions tipB;
  tipB.tip = "b";
  EXPECT_EQ(message(g, tipB), g + ": joint 'finger': <limit> lower 1 is above upper -1");
}

TEST_F(UrdfInputTest, LongChainsOfFixedLinksAreWalkedWithoutRecursion) {
  // Used to overflow the stack: one recursive call per fixed link (and one more per link when
  // urdfdom's model was freed).
  const int n = 100000;
  const std::string file = fixedChain(n);
  std::unique_ptr<ManipulatorModel> model = loadUrdf(file);
  ASSERT_EQ(model->getNumberOfJoints(), 1);
  EXPECT_NEAR(model->getLink(0).mass, 0.001 * (n + 1), 1e-9);
  // The same chain to its last link: every fixed joint on the chain itself.
  UrdfOptions tip;
  tip.tip = "l" + std::to_string(n);
  model = loadUrdf(file, tip);
  ASSERT_EQ(model->getNumberOfJoints(), 1);
  EXPECT_NEAR(model->getLink(0).mass, 0.001 * (n + 1), 1e-9);
  ManipulatorData data(*model);
  EXPECT_NEAR(forwardKinematics(*model, data, JointVector(1))(2, 3), 0.001 * (n + 1), 1e-6);
}

TEST_F(UrdfInputTest, NonFiniteInertialsAreRefusedWithTheLinkName) {
  // urdfdom drops an inertial it cannot parse (with a message of its own) and loads the link
  // without mass: the arm used to load with exit 0.
  EXPECT_EQ(message(kData + "/nan_mass.urdf"),
            kData + "/nan_mass.urdf: link 'b': <inertial> mass value is not a finite number ('nan')");
  auto arm = [&](const std::string& inertialXml) {
    return write("arm.urdf", "<robot name=\"arm\"><link name=\"base\"/><link name=\"upper\">" + inertialXml +
                                 "</link>" + joint("j", "revolute", "base", "upper") + "</robot>");
  };
  std::string f = arm(inertial("inf"));
  EXPECT_EQ(message(f), f + ": link 'upper': <inertial> mass value is not a finite number ('inf')");
  f = arm(inertial("1e999"));
  EXPECT_EQ(message(f), f + ": link 'upper': <inertial> mass value is not a finite number ('1e999')");
  f = arm(inertial("-2"));
  EXPECT_EQ(message(f), f + ": link 'upper': <inertial> mass '-2' is negative");
  f = arm(inertial("2", "nan"));
  EXPECT_EQ(message(f), f + ": link 'upper': <inertial> inertia ixx is not a finite number ('nan')");
  f = arm("<inertial><mass value=\"2\"/></inertial>");
  EXPECT_EQ(message(f), f + ": link 'upper': <inertial> inertia ixx is not a finite number (missing)");
  f = arm(inertial("2", "1", "<origin xyz=\"0 nan 0\"/>"));
  EXPECT_EQ(message(f), f + ": link 'upper': <inertial> origin xyz '0 nan 0' is not three finite numbers");
  f = arm(inertial("2", "1", "<origin xyz=\"0 0.1 0\" rpy=\"0 0 1\"/>"));
  EXPECT_EQ(message(f), "no error");
  EXPECT_NEAR(loadUrdf(f)->getLink(0).mass, 2.0, 1e-12);
}

// Issue 20: a joint with a number that is not finite is refused naming the file and the joint
// (urdfdom refused a <limit> of nan only as "not a valid URDF document").
TEST_F(UrdfInputTest, NonFiniteJointNumbersAreRefusedWithTheJointName) {
  auto arm = [&](const std::string& jointXml) {
    return write("arm.urdf", "<robot name=\"arm\"><link name=\"base\"/><link name=\"upper\"/><joint name=\"shoulder\" "
                             "type=\"revolute\"><parent link=\"base\"/><child link=\"upper\"/>" +
                                 jointXml + "</joint></robot>");
  };
  std::string f = arm("<axis xyz=\"0 0 1\"/><limit lower=\"-1\" upper=\"1\" effort=\"nan\" velocity=\"1\"/>");
  EXPECT_EQ(message(f), f + ": joint 'shoulder': <limit> effort is not a finite number ('nan')");
  f = arm("<axis xyz=\"0 0 1\"/><limit lower=\"-inf\" upper=\"1\" effort=\"1\" velocity=\"1\"/>");
  EXPECT_EQ(message(f), f + ": joint 'shoulder': <limit> lower is not a finite number ('-inf')");
  f = arm("<axis xyz=\"0 0 1\"/><dynamics damping=\"1e999\"/>");
  EXPECT_EQ(message(f), f + ": joint 'shoulder': <dynamics> damping is not a finite number ('1e999')");
  f = arm("<axis xyz=\"0 nan 1\"/>");
  EXPECT_EQ(message(f), f + ": joint 'shoulder': <axis> xyz '0 nan 1' is not three finite numbers");
  f = arm("<origin xyz=\"0 0 0.1\" rpy=\"0 inf 0\"/><axis xyz=\"0 0 1\"/>");
  EXPECT_EQ(message(f), f + ": joint 'shoulder': <origin> rpy '0 inf 0' is not three finite numbers");
  f = arm("<axis xyz=\"0 0 1\"/><mimic joint=\"shoulder\" multiplier=\"nan\"/>");
  EXPECT_EQ(message(f), f + ": joint 'shoulder': <mimic> multiplier is not a finite number ('nan')");
  f = arm("<axis xyz=\"0 -1 -4.37114e-08\"/><limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/>");
  EXPECT_EQ(message(f), "no error");
}

// A negative <limit> velocity or effort was replaced by the ManipulatorModel default (3 rad/s,
// 100 N m) without a word; it is refused naming the file and the joint. Zero is "not given" (a
// placeholder some tools write): the default, unscaled by velocityLimitScale.
TEST_F(UrdfInputTest, NegativeVelocityAndEffortLimitsAreRefusedWithTheJointName) {
  auto arm = [&](const std::string& type, const std::string& limit) {
    return write("arm.urdf", "<robot name=\"arm\"><link name=\"base\"/><link name=\"upper\"/><joint name=\"shoulder\" "
                             "type=\"" + type + "\"><parent link=\"base\"/><child link=\"upper\"/><axis xyz=\"0 0 1\"/>" +
                                 limit + "</joint></robot>");
  };
  std::string f = arm("revolute", "<limit lower=\"-1\" upper=\"1\" effort=\"10\" velocity=\"-2\"/>");
  EXPECT_EQ(message(f), f + ": joint 'shoulder': <limit> velocity -2 is negative");
  f = arm("prismatic", "<limit lower=\"0\" upper=\"0.5\" effort=\"-50\" velocity=\"0.3\"/>");
  EXPECT_EQ(message(f), f + ": joint 'shoulder': <limit> effort -50 is negative");
  f = arm("continuous", "<limit effort=\"10\" velocity=\"-0.5\"/>");
  EXPECT_EQ(message(f), f + ": joint 'shoulder': <limit> velocity -0.5 is negative");
  f = arm("revolute", "<limit lower=\"-1\" upper=\"1\" effort=\"0\" velocity=\"0\"/>");
  UrdfOptions slower;
  slower.velocityLimitScale = 0.8;
  ASSERT_EQ(message(f, slower), "no error");
  const std::unique_ptr<ManipulatorModel> model = loadUrdf(f, slower);
  EXPECT_EQ(model->getVelocityLimit()(0), 3.0);
  EXPECT_EQ(model->getTorqueLimit()(0), 100.0);
}

// An inertia that is not positive semi-definite (a negative principal moment) gave a mass matrix
// with negative diagonal entries and confusing errors later on; it is refused naming the file and
// the link. The triangle inequality is not enforced (real descriptions break it slightly, as the
// published Puma 560 does), and a zero inertia (a point mass, a massless link) loads.
TEST_F(UrdfInputTest, InertiasThatAreNotPositiveSemiDefiniteAreRefusedWithTheLinkName) {
  auto arm = [&](const std::string& mass, const std::string& inertia) {
    return write("arm.urdf", "<robot name=\"arm\"><link name=\"base\"/><link name=\"upper\"><inertial><mass value=\"" +
                                 mass + "\"/><inertia " + inertia + "/></inertial></link>" +
                                 joint("j", "revolute", "base", "upper") + "</robot>");
  };
  std::string f = arm("2", "ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"-0.5\" iyz=\"0\" izz=\"1\"");
  EXPECT_EQ(message(f), f + ": link 'upper': <inertial> inertia is not positive semi-definite (smallest eigenvalue "
                            "-0.5 kg m^2)");
  f = arm("2", "ixx=\"0.1\" ixy=\"5\" ixz=\"5\" iyy=\"0.1\" iyz=\"5\" izz=\"0.1\"");
  EXPECT_EQ(message(f), f + ": link 'upper': <inertial> inertia is not positive semi-definite (smallest eigenvalue "
                            "-4.9 kg m^2)");
  for (const char* inertia : {"ixx=\"0.066\" ixy=\"0\" ixz=\"0\" iyy=\"0.086\" iyz=\"0\" izz=\"0.0125\"",  // Puma link 3
                              "ixx=\"0\" ixy=\"0\" ixz=\"0\" iyy=\"0\" iyz=\"0\" izz=\"0\"",
                              "ixx=\"0.01\" ixy=\"0\" ixz=\"0\" iyy=\"-1e-12\" iyz=\"0\" izz=\"0.01\"",  // rounding
                              // a thin rod written with 5 significant digits: smallest moment -1e-7
                              "ixx=\"0.00375\" ixy=\"-0.0037501\" ixz=\"0\" iyy=\"0.00375\" iyz=\"0\" izz=\"0.0075\""}) {
    f = arm("2", inertia);
    EXPECT_EQ(message(f), "no error") << inertia;
  }
  f = arm("0", "ixx=\"0\" ixy=\"0\" ixz=\"0\" iyy=\"0\" iyz=\"0\" izz=\"0\"");
  EXPECT_EQ(message(f), "no error");
}

// Finite numbers too large for a robot gave NaN torques with exit status 0 (rp-model gravity
// printed null): lengths beyond 1e6 m, masses above 1e9 kg and inertias above 1e12 kg m^2 are
// refused naming the file, the joint or link and the element.
TEST_F(UrdfInputTest, HugeLengthsMassesAndInertiasAreRefusedWithTheElement) {
  auto arm = [&](const std::string& origin, const std::string& inertialXml) {
    return write("arm.urdf", "<robot name=\"arm\"><link name=\"base\"/><link name=\"upper\">" + inertialXml +
                                 "</link><joint name=\"shoulder\" type=\"revolute\"><parent link=\"base\"/><child "
                                 "link=\"upper\"/>" + origin + "<axis xyz=\"0 0 1\"/><limit lower=\"-1\" upper=\"1\" "
                                 "effort=\"1\" velocity=\"1\"/></joint></robot>");
  };
  std::string f = arm("<origin xyz=\"0 0 1e308\"/>", inertial("1"));
  EXPECT_EQ(message(f), f + ": joint 'shoulder': <origin> xyz '0 0 1e308' has a coordinate larger than 1e6 m in magnitude");
  f = arm("", inertial("1", "1", "<origin xyz=\"1e200 0 0\"/>"));
  EXPECT_EQ(message(f), f + ": link 'upper': <inertial> origin xyz '1e200 0 0' has a coordinate larger than 1e6 m in "
                            "magnitude");
  f = arm("", inertial("2e9"));
  EXPECT_EQ(message(f), f + ": link 'upper': <inertial> mass '2e9' is larger than 1e9 kg");
  f = arm("", inertial("1", "1e13"));
  EXPECT_EQ(message(f), f + ": link 'upper': <inertial> inertia ixx '1e13' is larger than 1e12 kg m^2 in magnitude");
  f = arm("", "<inertial><mass value=\"1\"/><inertia ixx=\"1\" ixy=\"-2e12\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/></inertial>");
  EXPECT_EQ(message(f), f + ": link 'upper': <inertial> inertia ixy '-2e12' is larger than 1e12 kg m^2 in magnitude");
  // At the bounds the arm loads and its dynamics are finite.
  f = arm("<origin xyz=\"-1e6 0 1e6\"/>",
          "<inertial><origin xyz=\"1e6 0 0\"/><mass value=\"1e9\"/><inertia ixx=\"1e12\" ixy=\"0\" ixz=\"0\" iyy=\"1e12\" "
          "iyz=\"0\" izz=\"1e12\"/></inertial>");
  ASSERT_EQ(message(f), "no error");
  const std::unique_ptr<ManipulatorModel> model = loadUrdf(f);
  ManipulatorData data(*model);
  JointVector q(1), qd(1);
  q(0) = 0.5;
  qd(0) = 1;
  EXPECT_TRUE(massMatrix(*model, data, q).allFinite());
  EXPECT_TRUE(inverseDynamics(*model, data, q, qd, qd).allFinite());
  // Joint limits of +-1.7e308 ("none", as some exporters write it) failed the load's own check
  // as an "internal error"; they are refused naming the joint (and +-1e6 loads).
  const std::string limited = "<robot name=\"arm\"><link name=\"base\"/><link name=\"upper\">" + inertial("1") +
                              "</link><joint name=\"shoulder\" type=\"revolute\"><parent link=\"base\"/><child "
                              "link=\"upper\"/><axis xyz=\"0 0 1\"/><limit lower=\"LO\" upper=\"1.7e308\" "
                              "effort=\"1\" velocity=\"1\"/></joint></robot>";
  std::string text = limited;
  text.replace(text.find("LO"), 2, "-1.7e308");
  f = write("limits.urdf", text);
  EXPECT_EQ(message(f), f + ": joint 'shoulder': <limit> lower -1.7e+308 is beyond 1e6 in magnitude (a joint without "
                            "limits is type=\"continuous\")");
  text = limited;
  text.replace(text.find("LO"), 2, "-1e6");
  text.replace(text.find("1.7e308"), 7, "1e6");
  f = write("limits.urdf", text);
  EXPECT_EQ(message(f), "no error");
}

TEST_F(UrdfInputTest, SpecialDeepAndHugeFilesAreRefused) {
  EXPECT_EQ(message("/dev/zero"), "/dev/zero: cannot read the file: it is not a regular file");
  const std::string fifo = (dir_ / "arm.urdf").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_EQ(message(fifo), fifo + ": cannot read the file: it is not a regular file");  // without blocking
  // The XML parser recurses once per nesting level.
  std::string deep = "<robot name=\"deep\">";
  for (int i = 0; i < 200000; ++i) deep += "<a>";
  const std::string f = write("deep.urdf", deep);
  EXPECT_EQ(message(f), f + ": elements nest deeper than 100 levels");
  const std::string big = write("big.urdf", "<robot name=\"big\">" + std::string(std::size_t{65} << 20, ' ') + "</robot>");
  EXPECT_EQ(message(big), big + ": the file is larger than 64 MiB");
}

}  // namespace
}  // namespace rp
