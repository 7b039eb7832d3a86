// The URDF export read back with urdfdom: walking its joints gives the model's forward kinematics.
#include <gtest/gtest.h>

#include <urdf_parser/urdf_parser.h>

#include <random>

#include "rp/model/Kinematics.hpp"
#include "rp/model/Puma560Model.hpp"
#include "rp/model/UrdfExport.hpp"
#include "rp/model/WAMModel.hpp"

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
  double mass = 0, urdfMass = 0;
  for (int k = 0; k < n; ++k) {
    mass += model.getLink(k).mass;
    urdfMass += urdf->getLink("link" + std::to_string(k + 1))->inertial->mass;
  }
  EXPECT_DOUBLE_EQ(urdfMass, mass);
}

TEST(UrdfExport, ForwardKinematicsOfTheExportedRobotsMatch) {
  checkRobot(Puma560Model());
  checkRobot(Puma560Model(0.67183, translation(1, 2, 0) * zRotation(0.5), translation(0, 0, 0.1)));
  checkRobot(WAM7Model());
  checkRobot(WAM4Model());
}

}  // namespace
}  // namespace rp
