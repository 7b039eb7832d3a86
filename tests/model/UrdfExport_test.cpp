// The URDF export read back with urdfdom (walking its joints gives the model's forward
// kinematics), loaded by MuJoCo (Debian's libmujoco-dev, linked into this test only: its mass
// matrix and bias forces equal the model's), and reloaded with rp's own loader (the same arm but
// for what URDF cannot carry; a loaded URDF keeps its joint and link names).
#include <gtest/gtest.h>

#include <urdf_parser/urdf_parser.h>

#include <fstream>
#include <random>
#include <set>

#include "MuJoCo.hpp"
#include "rp/model/Dynamics.hpp"
#include "rp/model/Kinematics.hpp"
#include "rp/model/PhysicalModel.hpp"
#include "rp/model/Puma560Model.hpp"
#include "rp/model/UrdfExport.hpp"
#include "rp/model/UrdfModel.hpp"
#include "rp/model/WAMModel.hpp"
#include "ScratchDirectory.hpp"

namespace rp {
namespace {

Transform pose(const urdf::Pose& p) {
  Transform t = Transform::unit();
  const Eigen::Quaterniond q(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z);
  t.topLeftCorner<3, 3>() = q.toRotationMatrix();
  t(0, 3) = p.position.x;
  t(1, 3) = p.position.y;
  t(2, 3) = p.position.z;
  return t;
}

void checkRobot(const ManipulatorModel& model) {
  const std::string xml = toUrdf(model);
  const urdf::ModelInterfaceSharedPtr urdf = urdf::parseURDF(xml);
  ASSERT_TRUE(urdf) << xml;
  const int n = model.getNumberOfJoints();
  ManipulatorData data(model);
  std::mt19937_64 rng(5);
  for (int trial = 0; trial < 200; ++trial) {
    JointVector q(n);
    for (int i = 0; i < n; ++i) {
      q(i) = std::uniform_real_distribution<double>(model.getPositionMin()(i), model.getPositionMax()(i))(rng);
    }
    Transform T = pose(urdf->getJoint("base")->parent_to_joint_origin_transform);
    for (int k = 0; k < n; ++k) {
      const urdf::JointConstSharedPtr j = urdf->getJoint("joint" + std::to_string(k + 1));
      ASSERT_TRUE(j);
      ASSERT_EQ(j->type, urdf::Joint::REVOLUTE);
      EXPECT_DOUBLE_EQ(j->limits->upper, model.getPositionMax()(k));
      EXPECT_DOUBLE_EQ(j->limits->effort, model.getTorqueLimit()(k));
      const Eigen::Vector3d axis(j->axis.x, j->axis.y, j->axis.z);
      T = Transform(T * pose(j->parent_to_joint_origin_transform) * rotation(Vector<3>(axis), q(k)));
    }
    T = Transform(T * pose(urdf->getJoint("tool")->parent_to_joint_origin_transform));
    EXPECT_LT((T - forwardKinematics(model, data, q)).cwiseAbs().maxCoeff(), 1e-12) << model.getName();
  }
  // The masses written are physicalModel()'s: the model's, but for a link with none (the Puma's
  // link 1), which gets kExportMassFloor of the arm's.
  double mass = 0;
  for (int k = 0; k < n; ++k) mass += model.getLink(k).mass;
  for (int k = 0; k < n; ++k) {
    const double written = urdf->getLink("link" + std::to_string(k + 1))->inertial->mass;
    EXPECT_EQ(written, model.getLink(k).mass > 0 ? model.getLink(k).mass : kExportMassFloor * mass);
  }
}

TEST(UrdfExport, ForwardKinematicsOfTheExportedRobotsMatch) {
  checkRobot(Puma560Model());
  checkRobot(Puma560Model(0.67183, translation(1, 2, 0) * zRotation(0.5), translation(0, 0, 0.1)));
  checkRobot(WAM7Model());
  checkRobot(WAM4Model());
}

// MuJoCo loads the URDF export (it refused the Puma's: link 1 was massless with an inertia, link 3's
// inertia broke the triangle inequality), reads its damping and friction, and finds the mass
// matrix, bias forces and gravity of physicalModel() without motor inertia (which URDF has no
// field for; MuJoCo ignores the <transmission>).
void compareUrdfWithMuJoCo(const ManipulatorModel& model) {
  SCOPED_TRACE(model.getName());
  const std::string text = toUrdf(model);
  std::unique_ptr<test::MuJoCoModel> mj;
  ASSERT_NO_THROW(mj = std::make_unique<test::MuJoCoModel>(text, ".urdf")) << text;
  const PhysicalModel exported = physicalModel(model);
  const ManipulatorModel& physical = exported.model;
  const int n = model.getNumberOfJoints();
  ASSERT_EQ(mj->m->nv, n);
  for (int i = 0; i < n; ++i) {
    const LinkParameters& l = model.getLink(i);
    EXPECT_DOUBLE_EQ(mj->m->dof_damping[i], l.viscousFriction * l.gearRatio * l.gearRatio);
    EXPECT_DOUBLE_EQ(mj->m->dof_frictionloss[i],
                     0.5 * std::abs(l.gearRatio) * (l.coulombFrictionPositive - l.coulombFrictionNegative));
    EXPECT_EQ(mj->m->dof_armature[i], 0) << "URDF carries no armature MuJoCo reads";
  }
  ManipulatorData data(physical);
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> u(0, 1);
  double worstM = 0, worstBias = 0, worstGravity = 0;
  for (int trial = 0; trial < 200; ++trial) {
    JointVector q(n), qd(n), zero(n);
    zero.setZero();
    for (int i = 0; i < n; ++i) {
      q(i) = model.getPositionMin()(i) + u(rng) * (model.getPositionMax()(i) - model.getPositionMin()(i));
      qd(i) = (2 * u(rng) - 1) * model.getVelocityLimit()(i);
    }
    mj->forward(q, qd);
    worstM = std::max(worstM, test::relativeError(mj->massMatrix(), massMatrix(physical, data, q)));
    worstBias = std::max(worstBias, test::relativeError(mj->bias(), inverseDynamics(physical, data, q, qd, zero)));
    mj->forward(q, zero);
    JointVector g(n);
    gravityTorque(physical, data, q, g);
    worstGravity = std::max(worstGravity, test::relativeError(mj->bias(), g));
  }
  std::printf("%s URDF in MuJoCo against rp: mass matrix %.2e, bias forces %.2e, gravity %.2e relative\n",
              model.getName().c_str(), worstM, worstBias, worstGravity);
  EXPECT_LT(worstM, 1e-9);
  EXPECT_LT(worstBias, 1e-9);
  EXPECT_LT(worstGravity, 1e-9);
}

TEST(UrdfExport, MuJoCoLoadsTheExportsWithTheModelsDynamics) {
  compareUrdfWithMuJoCo(Puma560Model());
  compareUrdfWithMuJoCo(Puma560Model(0.67183, translation(1, 2, 0) * zRotation(0.5), translation(0, 0, 0.1)));
  compareUrdfWithMuJoCo(WAM7Model());
  compareUrdfWithMuJoCo(WAM4Model());
}

// A URDF loaded and exported keeps its names (issue 20: the ROS 2 bridge publishes joint_states with
// the names of its robot_description). The export read back with urdfdom has the original chain's
// movable joints, in order, each moving the model's link and hanging on the previous one; reloaded
// with loadUrdf() it is the same arm: the same names, forward kinematics, Jacobian, gravity, inverse
// dynamics and mass matrix at random configurations (1e-12 relative).
void checkNamesKept(const std::string& file, const std::string& tip) {
  SCOPED_TRACE(file + " to " + tip);
  UrdfOptions options;
  options.tip = tip;
  options.requireDynamics = true;
  const std::unique_ptr<ManipulatorModel> model = loadUrdf(std::string(RP_TEST_DATA_DIR) + "/" + file, options);
  const int n = model->getNumberOfJoints();
  // The original's movable joints from the root to the tip, and the links they move.
  std::ifstream in(std::string(RP_TEST_DATA_DIR) + "/" + file);
  const std::string original((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const urdf::ModelInterfaceSharedPtr source = urdf::parseURDF(original);
  ASSERT_TRUE(source);
  std::vector<std::string> joints, links;
  for (auto link = source->getLink(tip); link->parent_joint; link = source->getLink(link->parent_joint->parent_link_name)) {
    if (link->parent_joint->type == urdf::Joint::FIXED) continue;
    joints.insert(joints.begin(), link->parent_joint->name);
    links.insert(links.begin(), link->parent_joint->child_link_name);
  }
  ASSERT_EQ(static_cast<int>(joints.size()), n);

  const std::string xml = toUrdf(*model);
  const urdf::ModelInterfaceSharedPtr exported = urdf::parseURDF(xml);
  ASSERT_TRUE(exported) << xml;
  std::string parent = "base_link";
  for (int k = 0; k < n; ++k) {
    const urdf::JointConstSharedPtr j = exported->getJoint(joints[static_cast<std::size_t>(k)]);
    ASSERT_TRUE(j) << joints[static_cast<std::size_t>(k)] << " is not in the export:\n" << xml;
    EXPECT_EQ(j->child_link_name, links[static_cast<std::size_t>(k)]);
    EXPECT_EQ(j->parent_link_name, parent);
    EXPECT_EQ(j->type, model->isPrismatic(k) ? urdf::Joint::PRISMATIC : urdf::Joint::REVOLUTE);
    parent = j->child_link_name;
  }
  EXPECT_EQ(exported->getJoint("tool")->parent_link_name, parent);
  EXPECT_EQ(exported->joints_.size(), static_cast<std::size_t>(n + 2));  // and the fixed base and tool joints

  const test::ScratchFile path("names_kept_" + file);
  std::ofstream(path) << xml;
  UrdfOptions again;
  again.tip = "tool";
  again.requireDynamics = true;
  const std::unique_ptr<ManipulatorModel> back = loadUrdf(path, again);
  ASSERT_EQ(back->getNumberOfJoints(), n);
  for (int k = 0; k < n; ++k) {
    EXPECT_EQ(back->getJointName(k), joints[static_cast<std::size_t>(k)]);
    EXPECT_EQ(back->getLinkName(k), links[static_cast<std::size_t>(k)]);
  }
  ManipulatorData a(*model), b(*back);
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> u(0, 1);
  double worstPose = 0, worstJ = 0, worstG = 0, worstTau = 0, worstM = 0;
  for (int trial = 0; trial < 200; ++trial) {
    JointVector q(n), qd(n), qdd(n), g1(n), g2(n);
    for (int i = 0; i < n; ++i) {
      q(i) = model->getPositionMin()(i) + u(rng) * (model->getPositionMax()(i) - model->getPositionMin()(i));
      qd(i) = 2 * u(rng) - 1;
      qdd(i) = 4 * u(rng) - 2;
    }
    worstPose = std::max(worstPose, test::relativeError(forwardKinematics(*back, b, q), forwardKinematics(*model, a, q)));
    worstJ = std::max(worstJ, test::relativeError(jacobian(*back, b, q), jacobian(*model, a, q)));
    gravityTorque(*back, b, q, g1);
    gravityTorque(*model, a, q, g2);
    worstG = std::max(worstG, test::relativeError(g1, g2));
    worstTau = std::max(worstTau, test::relativeError(inverseDynamics(*back, b, q, qd, qdd), inverseDynamics(*model, a, q, qd, qdd)));
    worstM = std::max(worstM, test::relativeError(massMatrix(*back, b, q), massMatrix(*model, a, q)));
  }
  std::printf("%s to %s exported and reloaded: names kept; fk %.1e, J %.1e, g %.1e, tau %.1e, M %.1e relative\n",
              file.c_str(), tip.c_str(), worstPose, worstJ, worstG, worstTau, worstM);
  EXPECT_LT(worstPose, 1e-12);
  EXPECT_LT(worstJ, 1e-12);
  EXPECT_LT(worstG, 1e-12);
  EXPECT_LT(worstTau, 1e-12);
  EXPECT_LT(worstM, 1e-12);
}

TEST(UrdfExport, ALoadedDescriptionKeepsItsJointAndLinkNames) {
  checkNamesKept("ur_like.urdf", "tool0");
  checkNamesKept("panda_like.urdf", "link7");  // the hand and the fingers lumped into link7
  checkNamesKept("prismatic_arm.urdf", "tool");  // a joint and a link both called 'lift'
  checkNamesKept("test_arm.urdf", "tool");
}

// The frames the export adds (world, base_link, tool and the fixed joints base and tool) are renamed
// where the model has a link or joint of that name: urdfdom refuses two links of one name.
TEST(UrdfExport, AddedFramesAvoidTheModelsNames) {
  const Puma560Model puma;
  std::vector<LinkParameters> links;
  for (int i = 0; i < 6; ++i) links.push_back(puma.getLink(i));
  links[0].linkName = "world";
  links[1].linkName = "base_link";
  links[2].linkName = "tool";
  links[3].jointName = "base";
  links[4].jointName = "tool_2";
  const ManipulatorModel model("clashing", links);
  const urdf::ModelInterfaceSharedPtr urdf = urdf::parseURDF(toUrdf(model));
  ASSERT_TRUE(urdf) << toUrdf(model);
  EXPECT_EQ(urdf->getRoot()->name, "world_2");
  EXPECT_EQ(urdf->getJoint("base_2")->child_link_name, "base_link_2");
  EXPECT_EQ(urdf->getJoint("joint1")->child_link_name, "world");
  EXPECT_EQ(urdf->getJoint("joint1")->parent_link_name, "base_link_2");
  EXPECT_EQ(urdf->getJoint("tool_3")->child_link_name, "tool_3");
  EXPECT_EQ(urdf->getJoint("tool_3")->parent_link_name, "link6");
  EXPECT_EQ(urdf->getJoint("base")->child_link_name, "link4");
}

// A name with XML's special characters (a URDF robot's name may have any) is escaped.
TEST(UrdfExport, NamesAreEscaped) {
  std::vector<LinkParameters> links;
  for (int i = 0; i < 6; ++i) links.push_back(Puma560Model().getLink(i));
  const urdf::ModelInterfaceSharedPtr urdf = urdf::parseURDF(toUrdf(ManipulatorModel("arm \"A\" & <B>", links)));
  ASSERT_TRUE(urdf);
  EXPECT_EQ(urdf->getName(), "arm \"A\" & <B>");
}

// The motor inertia is in the file for the readers that know Drake's extension.
TEST(UrdfExport, MotorInertiaAndGearRatioAreInTheTransmissions) {
  const Puma560Model puma;
  const std::string text = toUrdf(puma);
  for (int k = 0; k < 6; ++k) {
    const LinkParameters& l = puma.getLink(k);
    const std::string joint = "joint" + std::to_string(k + 1);
    const std::size_t at = text.find("<transmission name=\"" + joint + "_transmission\">");
    ASSERT_NE(at, std::string::npos) << joint;
    const std::string transmission = text.substr(at, text.find("</transmission>", at) - at);
    EXPECT_NE(transmission.find("<joint name=\"" + joint + "\">"), std::string::npos);
    char rotor[80], ratio[80];
    std::snprintf(rotor, sizeof rotor, "<drake:rotor_inertia value=\"%.17g\"/>", l.motorInertia);
    std::snprintf(ratio, sizeof ratio, "<drake:gear_ratio value=\"%.17g\"/>", std::abs(l.gearRatio));
    EXPECT_NE(transmission.find(rotor), std::string::npos) << transmission;
    EXPECT_NE(transmission.find(ratio), std::string::npos) << transmission;
  }
  UrdfOptions options;
  options.tip = "tool";
  EXPECT_EQ(toUrdf(*loadUrdf(std::string(RP_TEST_DATA_DIR) + "/test_arm.urdf", options)).find("<transmission name"),
            std::string::npos)
      << "no motor inertia, gear ratio 1: no transmission";
}

// A Puma reloaded from its own URDF with rp's loader is the exported arm (physicalModel()) as far
// as URDF goes: the same kinematics, mass matrix without motor inertia, gravity (that of the
// published Puma too), viscous friction, and the mean Coulomb friction. What differs from the
// published Puma, measured: the motor inertia (URDF has no field for it; the loader does not read
// Drake's <transmission> extension), link 3's inertia, and the two-sided friction.
TEST(UrdfExport, PumaReloadedFromItsExportIsTheSameArmAsFarAsUrdfGoes) {
  const Puma560Model puma;
  const PhysicalModel exported = physicalModel(puma);
  const ManipulatorModel& physical = exported.model;
  const test::ScratchFile file("puma560_export_reload.urdf");
  std::ofstream(file) << toUrdf(puma);
  UrdfOptions options;
  options.tip = "tool";
  options.requireDynamics = true;
  const std::unique_ptr<ManipulatorModel> back = loadUrdf(file, options);
  ASSERT_EQ(back->getNumberOfJoints(), 6);
  for (int i = 0; i < 6; ++i) {
    const LinkParameters& l = puma.getLink(i);
    const LinkParameters& r = back->getLink(i);
    EXPECT_EQ(back->getArmatureInertia()(i), 0) << "lost: URDF has no motor inertia";
    EXPECT_DOUBLE_EQ(r.viscousFriction * r.gearRatio * r.gearRatio, l.viscousFriction * l.gearRatio * l.gearRatio);
    const double mean = 0.5 * std::abs(l.gearRatio) * (l.coulombFrictionPositive - l.coulombFrictionNegative);
    EXPECT_DOUBLE_EQ(std::abs(r.gearRatio) * r.coulombFrictionPositive, mean);
    EXPECT_DOUBLE_EQ(-std::abs(r.gearRatio) * r.coulombFrictionNegative, mean);
    EXPECT_EQ(back->getPositionMin()(i), puma.getPositionMin()(i));
    EXPECT_EQ(back->getPositionMax()(i), puma.getPositionMax()(i));
    EXPECT_EQ(back->getTorqueLimit()(i), puma.getTorqueLimit()(i));
  }
  ManipulatorData a(puma), b(*back), c(physical);
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> u(0, 1);
  double worstPose = 0, worstM = 0, worstGravity = 0, worstBias = 0, armatureShare = 0, link3 = 0;
  for (int trial = 0; trial < 500; ++trial) {
    JointVector q(6), qd(6), zero(6);
    zero.setZero();
    for (int i = 0; i < 6; ++i) {
      q(i) = puma.getPositionMin()(i) + u(rng) * (puma.getPositionMax()(i) - puma.getPositionMin()(i));
      qd(i) = (2 * u(rng) - 1) * puma.getVelocityLimit()(i);
    }
    worstPose = std::max(worstPose, (forwardKinematics(*back, b, q) - forwardKinematics(puma, a, q)).cwiseAbs().maxCoeff());
    const JointMatrix M = massMatrix(*back, b, q);
    worstM = std::max(worstM, test::relativeError(M, massMatrix(physical, c, q)));
    worstBias = std::max(worstBias, test::relativeError(inverseDynamics(*back, b, q, qd, zero),
                                                        inverseDynamics(physical, c, q, qd, zero)));
    JointVector g1(6), g2(6);
    gravityTorque(*back, b, q, g1);
    gravityTorque(puma, a, q, g2);
    worstGravity = std::max(worstGravity, test::relativeError(g1, g2));
    // What the published Puma has on top: the armature on the diagonal, link 3's published inertia.
    const JointMatrix published = massMatrix(puma, a, q, true);
    armatureShare = std::max(armatureShare, puma.getArmatureInertia()(1) / published(1, 1));  // the shoulder
    link3 = std::max(link3, (M - massMatrix(puma, a, q)).cwiseAbs().maxCoeff());
  }
  std::printf("Puma reloaded from its URDF: pose %.2e, mass matrix %.2e, C qd + g %.2e against the export; gravity "
              "%.2e against the published Puma; lost armature up to %.0f%% of the shoulder's inertia; link 3 changes M by "
              "%.5f kg m^2\n",
              worstPose, worstM, worstBias, worstGravity, 100 * armatureShare, link3);
  EXPECT_LT(worstPose, 1e-12);
  EXPECT_LT(worstM, 1e-9);
  EXPECT_LT(worstBias, 1e-9);
  EXPECT_LT(worstGravity, 1e-9);
  EXPECT_GT(armatureShare, 0.4);  // the 45% of the shoulder's inertia
}

}  // namespace
}  // namespace rp
