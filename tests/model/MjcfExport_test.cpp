// The MJCF export loaded by MuJoCo (Debian's libmujoco-dev, linked into this test only): MuJoCo's
// mass matrix (mj_fullM, with armature), bias forces (qfrc_bias = C qd + g), gravity, damping and
// tool pose equal the model's own at random states, and the file carries the joint ranges,
// armature, damping, friction loss, torque limits and home position.
#include <gtest/gtest.h>

#include <cstdio>
#include <memory>
#include <random>

#include "ModifiedDh.hpp"
#include "MuJoCo.hpp"
#include "rp/model/Dynamics.hpp"
#include "rp/model/Kinematics.hpp"
#include "rp/model/MjcfExport.hpp"
#include "rp/model/PhysicalModel.hpp"
#include "rp/model/Puma560Model.hpp"
#include "rp/model/UrdfModel.hpp"
#include "rp/model/WAMModel.hpp"

namespace rp {
namespace {

using test::MuJoCoModel;
using test::relativeError;

const std::string kData = RP_TEST_DATA_DIR;

std::unique_ptr<ManipulatorModel> urdfArm(const std::string& name) {
  UrdfOptions o;
  o.tip = "tool";
  o.requireDynamics = true;
  return loadUrdf(kData + "/" + name + ".urdf", o);
}

// A copy of `model` with gravity off the vertical.
std::unique_ptr<ManipulatorModel> withGravity(const ManipulatorModel& model, double gx, double gy, double gz) {
  std::vector<LinkParameters> links;
  for (int i = 0; i < model.getNumberOfJoints(); ++i) links.push_back(model.getLink(i));
  Vector<3> g;
  g = gx, gy, gz;
  return std::make_unique<ManipulatorModel>(model.getName() + "_tilted_gravity", links, model.getBaseTransform(),
                                            model.getToolTransform(), g, model.getConvention());
}

// Loads exportMjcf(model) in MuJoCo and compares, on 300 random states within the limits, the mass
// matrix, bias forces, gravity, damping and tool pose with those of physicalModel(model).
void compareWithMuJoCo(const ManipulatorModel& model) {
  SCOPED_TRACE(model.getName());
  const std::string xml = exportMjcf(model);
  std::unique_ptr<MuJoCoModel> mj;
  ASSERT_NO_THROW(mj = std::make_unique<MuJoCoModel>(xml, ".xml")) << xml;
  const PhysicalModel exported = physicalModel(model);
  const ManipulatorModel& physical = exported.model;
  const int n = model.getNumberOfJoints();
  ASSERT_EQ(mj->m->nq, n);
  ASSERT_EQ(mj->m->nv, n);
  // The tree: world, base_link, then the model's links, each the parent of the next, one joint each.
  ASSERT_EQ(mj->m->nbody, n + 2);
  for (int b = 1; b < n + 2; ++b) EXPECT_EQ(mj->m->body_parentid[b], b - 1);
  EXPECT_EQ(mj->m->body_jntnum[1], 0);
  ASSERT_EQ(mj->m->nu, n);
  ASSERT_EQ(mj->m->nkey, 1);
  const int tool = mj_name2id(mj->m, mjOBJ_SITE, "tool");
  ASSERT_GE(tool, 0);
  for (int i = 0; i < n; ++i) {
    const LinkParameters& l = model.getLink(i);
    // The model's names (a URDF arm's own, joint1.../link1... for the built-in arms).
    EXPECT_STREQ(mj_id2name(mj->m, mjOBJ_JOINT, i), model.getJointName(i).c_str());
    EXPECT_STREQ(mj_id2name(mj->m, mjOBJ_BODY, i + 2), model.getLinkName(i).c_str());
    EXPECT_EQ(mj->m->jnt_bodyid[i], i + 2);
    EXPECT_EQ(mj->m->jnt_type[i], model.isPrismatic(i) ? mjJNT_SLIDE : mjJNT_HINGE);
    EXPECT_EQ(mj->m->jnt_limited[i], 1);
    EXPECT_EQ(mj->m->jnt_range[2 * i], l.positionMin);
    EXPECT_EQ(mj->m->jnt_range[2 * i + 1], l.positionMax);
    EXPECT_EQ(mj->m->dof_armature[i], model.getArmatureInertia()(i));
    EXPECT_DOUBLE_EQ(mj->m->dof_damping[i], l.viscousFriction * l.gearRatio * l.gearRatio);
    EXPECT_DOUBLE_EQ(mj->m->dof_frictionloss[i],
                     0.5 * std::abs(l.gearRatio) * (l.coulombFrictionPositive - l.coulombFrictionNegative));
    EXPECT_EQ(mj->m->actuator_ctrlrange[2 * i + 1], l.torqueLimit);
    EXPECT_EQ(mj->m->actuator_ctrlrange[2 * i], -l.torqueLimit);
    EXPECT_EQ(mj->m->key_qpos[i], model.getHomePosition()(i));
  }
  for (int a = 0; a < 3; ++a) EXPECT_EQ(mj->m->opt.gravity[a], model.getGravity()(a));

  ManipulatorData data(physical);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0, 1);
  double worstM = 0, worstBias = 0, worstGravity = 0, worstDamping = 0, worstPose = 0;
  for (int trial = 0; trial < 300; ++trial) {
    JointVector q(n), qd(n), zero(n);
    zero.setZero();
    for (int i = 0; i < n; ++i) {
      q(i) = model.getPositionMin()(i) + u(rng) * (model.getPositionMax()(i) - model.getPositionMin()(i));
      qd(i) = (2 * u(rng) - 1) * model.getVelocityLimit()(i);
    }
    mj->forward(q, qd);
    worstM = std::max(worstM, relativeError(mj->massMatrix(), massMatrix(physical, data, q, /*motorInertia=*/true)));
    const JointVector h = inverseDynamics(physical, data, q, qd, zero);  // C qd + g
    worstBias = std::max(worstBias, relativeError(mj->bias(), h));
    // Damping: MuJoCo's passive force is -B G^2 qd (the joint-side viscous friction).
    const JointVector passive = mj->passive();
    for (int i = 0; i < n; ++i) {
      const LinkParameters& l = model.getLink(i);
      const double expected = -l.viscousFriction * l.gearRatio * l.gearRatio * qd(i);
      worstDamping = std::max(worstDamping, std::abs(passive(i) - expected) / std::max(std::abs(expected), 1e-300));
    }
    const Transform& T = forwardKinematics(physical, data, q);
    for (int r = 0; r < 3; ++r) {
      worstPose = std::max(worstPose, std::abs(mj->d->site_xpos[3 * tool + r] - T(r, 3)));
      for (int c = 0; c < 3; ++c) worstPose = std::max(worstPose, std::abs(mj->d->site_xmat[9 * tool + 3 * r + c] - T(r, c)));
    }
    mj->forward(q, zero);
    JointVector g(n);
    gravityTorque(physical, data, q, g);
    worstGravity = std::max(worstGravity, relativeError(mj->bias(), g));
  }
  std::printf("%s: MuJoCo against rp, largest relative error: mass matrix %.2e, bias forces %.2e, gravity %.2e, "
              "damping %.2e; tool pose %.2e\n",
              model.getName().c_str(), worstM, worstBias, worstGravity, worstDamping, worstPose);
  EXPECT_LT(worstM, 1e-9);
  EXPECT_LT(worstBias, 1e-9);
  EXPECT_LT(worstGravity, 1e-9);
  EXPECT_LT(worstDamping, 1e-12);
  EXPECT_LT(worstPose, 1e-12);
}

TEST(MjcfExport, MuJoCoAgreesOnThePuma560) {
  compareWithMuJoCo(Puma560Model());
  compareWithMuJoCo(Puma560Model(0.67183, translation(1, 2, 0.3) * zRotation(0.5) * xRotation(0.2),
                                 translation(0.01, 0.02, 0.1) * yRotation(0.3)));
  compareWithMuJoCo(*withGravity(Puma560Model(), 1.2, -0.7, -9.7));
  compareWithMuJoCo(*test::toModifiedDh(Puma560Model()));
}

TEST(MjcfExport, MuJoCoAgreesOnTheWam) {
  compareWithMuJoCo(WAM7Model());
  compareWithMuJoCo(WAM4Model());
}

TEST(MjcfExport, MuJoCoAgreesOnUrdfArms) {
  compareWithMuJoCo(*urdfArm("test_arm"));
  compareWithMuJoCo(*urdfArm("prismatic_arm"));  // slide joints
}

// The Puma exported is the published Puma but for link 3's inertia: link 1's corrections (a rod
// along joint 1's axis, a tiny mass at a centre on that axis) change no joint torque, and gravity
// is unchanged. Link 3's rod lies along joint 3's axis, which is parallel to joint 2's and
// perpendicular to joint 1's, so it adds its c = 0.00375 kg m^2 to M11 alone, at every pose, and
// changes no Coriolis or centrifugal torque (docs/models.md quotes this).
TEST(MjcfExport, ThePumaDiffersFromThePublishedOneOnlyByLink3) {
  const Puma560Model puma;
  const PhysicalModel exported = physicalModel(puma);
  const ManipulatorModel& physical = exported.model;
  std::vector<LinkParameters> links;
  for (int i = 0; i < 6; ++i) links.push_back(puma.getLink(i));
  links[0] = physical.getLink(0);
  const ManipulatorModel link1Only("puma560_link1", links, puma.getBaseTransform(), puma.getToolTransform());
  ManipulatorData a(puma), b(link1Only), c(physical);
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-2, 2);
  double worstLink1 = 0, worstGravity = 0, worstM = 0, largestM = 0, worstBias = 0, worstRod = 0;
  const double rodInertia = physical.getLink(2).inertia(0, 0) - puma.getLink(2).inertia(0, 0);
  EXPECT_NEAR(rodInertia, 0.00375, 1e-9);
  for (int trial = 0; trial < 1000; ++trial) {
    JointVector q(6), qd(6), zero(6);
    zero.setZero();
    for (int i = 0; i < 6; ++i) {
      q(i) = u(rng);
      qd(i) = u(rng);
    }
    const JointMatrix M = massMatrix(puma, a, q, true);
    worstLink1 = std::max(worstLink1, relativeError(massMatrix(link1Only, b, q, true), M));
    const JointVector h = inverseDynamics(puma, a, q, qd, zero);
    worstLink1 = std::max(worstLink1, relativeError(inverseDynamics(link1Only, b, q, qd, zero), h));
    JointVector g1(6), g2(6);
    gravityTorque(puma, a, q, g1);
    gravityTorque(physical, c, q, g2);
    worstGravity = std::max(worstGravity, relativeError(g2, g1));
    const JointMatrix Mc = massMatrix(physical, c, q, true);
    worstM = std::max(worstM, (Mc - M).cwiseAbs().maxCoeff());
    JointMatrix rod(6, 6);
    rod.setZero();
    rod(0, 0) = rodInertia;
    worstRod = std::max(worstRod, (Mc - M - rod).cwiseAbs().maxCoeff());
    largestM = std::max(largestM, relativeError(Mc, M));
    worstBias = std::max(worstBias, relativeError(inverseDynamics(physical, c, q, qd, zero), h));
  }
  std::printf("Puma 560 as exported against the published model: link 1's corrections %.2e relative; gravity %.2e; "
              "mass matrix (with motor inertia) up to %.5f kg m^2 (%.2e relative; %.1e besides the rod's M11), C qd + g "
              "%.2e relative\n",
              worstLink1, worstGravity, worstM, largestM, worstRod, worstBias);
  EXPECT_LT(worstLink1, 1e-9);
  EXPECT_LT(worstGravity, 1e-12);
  EXPECT_GT(worstM, 1e-3);  // link 3's rod is there
  EXPECT_LT(worstRod, 1e-12) << "link 3's rod changes more than M11";
  EXPECT_LT(worstBias, 1e-12);
}

TEST(MjcfExport, OptionsAndBadModels) {
  const Puma560Model puma;
  MjcfOptions options;
  options.timestep = 0.0005;
  options.integrator = "RK4";
  MuJoCoModel mj(exportMjcf(puma, options), ".xml");
  EXPECT_EQ(mj.m->opt.timestep, 0.0005);
  EXPECT_EQ(mj.m->opt.integrator, mjINT_RK4);
  options.timestep = 0;
  EXPECT_THROW(exportMjcf(puma, options), std::invalid_argument);
  options.timestep = std::nan("");
  EXPECT_THROW(exportMjcf(puma, options), std::invalid_argument);
  options = MjcfOptions();
  options.integrator = "leapfrog";
  EXPECT_THROW(exportMjcf(puma, options), std::invalid_argument);
  // A name with XML's special characters (a URDF robot's name may have any) is escaped.
  std::vector<LinkParameters> links;
  for (int i = 0; i < 6; ++i) links.push_back(puma.getLink(i));
  const ManipulatorModel named("arm \"A\" & <B>", links);
  MuJoCoModel escaped(exportMjcf(named), ".xml");
  EXPECT_STREQ(escaped.m->names, "arm \"A\" & <B>");  // the model's name comes first
  // Kinematics only: no mass anywhere, nothing MuJoCo could simulate.
  LinkParameters massless;
  const ManipulatorModel kinematic("kinematic", {massless, massless});
  try {
    exportMjcf(kinematic);
    ADD_FAILURE() << "a massless model was exported";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'kinematic' has no mass"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rp
