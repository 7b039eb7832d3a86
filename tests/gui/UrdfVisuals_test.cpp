// URDF <visual> elements as shapes of the arm's 3D model (loadUrdfVisuals): every visual, placed
// in its DH frame by the viewer, lands where the URDF's own kinematics puts it, for any joint
// vector (the reference is the URDF chain written out by hand, not the library's conversion).
#include "rp/gui/UrdfVisuals.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "rp/model/Kinematics.hpp"
#include "rp/model/ManipulatorData.hpp"
#include "rp/model/UrdfModel.hpp"

namespace {

const std::string kArm = std::string(RP_TEST_DATA_DIR) + "/visual_arm.urdf";

rp::Transform rotY(double a) {
  rp::Transform t = rp::Transform::unit();
  t.block<3, 3>(0, 0) = Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).toRotationMatrix();
  return t;
}

rp::Transform rotZ(double a) {
  rp::Transform t = rp::Transform::unit();
  t.block<3, 3>(0, 0) = Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return t;
}

rp::Transform rpy(double x, double y, double z, double r, double p, double w) {
  rp::Transform t = rp::Transform::unit();
  t.block<3, 3>(0, 0) = (Eigen::AngleAxisd(w, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(p, Eigen::Vector3d::UnitY()) *
                         Eigen::AngleAxisd(r, Eigen::Vector3d::UnitX()))
                            .toRotationMatrix();
  t(0, 3) = x;
  t(1, 3) = y;
  t(2, 3) = z;
  return t;
}

TEST(UrdfVisuals, ShapesOfEveryKindInTheirFrames) {
  const auto shapes = rp::loadUrdfVisuals(kArm);
  ASSERT_EQ(shapes.size(), 6u);
  EXPECT_EQ(shapes[0].kind, rp::ShapeKind::Cylinder);
  EXPECT_EQ(shapes[0].frame, "base");
  EXPECT_DOUBLE_EQ(shapes[0].size(0), 0.1);
  EXPECT_DOUBLE_EQ(shapes[0].size(1), 0.1);
  EXPECT_NEAR(shapes[0].color.r, 0.6, 1e-6);  // the robot's material "steel"
  EXPECT_EQ(shapes[1].kind, rp::ShapeKind::Box);
  EXPECT_EQ(shapes[1].frame, "link1");
  EXPECT_DOUBLE_EQ(shapes[1].size(2), 0.3);
  EXPECT_NEAR(shapes[1].color.g, 0.5, 1e-6);
  EXPECT_EQ(shapes[2].kind, rp::ShapeKind::Cylinder);
  EXPECT_EQ(shapes[2].frame, "link2");
  EXPECT_EQ(shapes[3].kind, rp::ShapeKind::Sphere);
  EXPECT_EQ(shapes[3].frame, "link3");
  EXPECT_DOUBLE_EQ(shapes[3].size(0), 0.06);
  EXPECT_EQ(shapes[4].kind, rp::ShapeKind::Mesh);
  EXPECT_EQ(shapes[4].frame, "link3");
  EXPECT_EQ(std::filesystem::path(shapes[4].meshFile),
            std::filesystem::absolute(std::string(RP_TEST_DATA_DIR) + "/wedge.stl").lexically_normal());
  EXPECT_DOUBLE_EQ(shapes[4].size(0), 0.2);
  EXPECT_EQ(shapes[5].frame, "link3");  // the tool, fixed to l3
  EXPECT_DOUBLE_EQ(shapes[5].color.r, 0.7);  // no material: the default grey
}

TEST(UrdfVisuals, PosesFollowTheUrdfKinematics) {
  const auto shapes = rp::loadUrdfVisuals(kArm);
  const auto model = rp::loadUrdf(kArm, {});
  rp::ManipulatorData data(*model);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(-2.0, 2.0);
  for (int trial = 0; trial < 20; ++trial) {
    const double q1 = angle(rng), q2 = angle(rng), q3 = angle(rng);
    rp::JointVector q(3);
    q << q1, q2, q3;
    rp::forwardKinematics(*model, data, q);
    // The URDF chain by hand: link poses, then each visual's origin.
    const rp::Transform base = rp::Transform::unit();
    const rp::Transform l1 = rp::Transform(rp::translation(0, 0, 0.1) * rotZ(q1));
    const rp::Transform l2 = rp::Transform(l1 * rp::translation(0, 0, 0.3) * rotY(q2));
    const rp::Transform l3 = rp::Transform(l2 * rp::translation(0.4, 0, 0) * rotY(q3));
    const rp::Transform tool = rp::Transform(l3 * rp::translation(0.3, 0, 0));
    const rp::Transform expected[6] = {
        rp::Transform(base * rp::translation(0, 0, 0.05)),
        rp::Transform(l1 * rp::translation(0, 0, 0.15)),
        rp::Transform(l2 * rpy(0.2, 0, 0, 0, 1.5707963267948966, 0)),
        l3,
        rp::Transform(l3 * rpy(0.1, -0.05, -0.05, 0.3, 0, 0.2)),
        tool,
    };
    for (std::size_t i = 0; i < shapes.size(); ++i) {
      const std::string& f = shapes[i].frame;
      const rp::Transform frame = f == "base" ? model->getBaseTransform()
                                              : rp::Transform(data.linkTransforms[static_cast<std::size_t>(std::stoi(f.substr(4)) - 1)]);
      const rp::Transform world = rp::Transform(frame * shapes[i].pose);
      EXPECT_LT((world - expected[i]).cwiseAbs().maxCoeff(), 1e-9) << "shape " << i << " at trial " << trial;
    }
  }
}

TEST(UrdfVisuals, ErrorsNameTheFile) {
  try {
    rp::loadUrdfVisuals("/no/such/arm.urdf");
    FAIL() << "no error";
  } catch (const rp::UrdfError& e) {
    EXPECT_NE(std::string(e.what()).find("/no/such/arm.urdf"), std::string::npos) << e.what();
  }
  EXPECT_THROW(rp::loadUrdfVisuals(kArm, "no_such_link"), rp::UrdfError);
  EXPECT_TRUE(rp::loadUrdfVisuals(std::string(RP_SOURCE_DIR) + "/tests/model/data/prismatic_arm.urdf").empty());
}

// Issue 20: the visuals hang on the model's own joints, whatever tip loadUrdf() chose: an arm whose
// last joint is a jaw ends before it (the jaw is lumped), and its shapes used to be refused with
// "the chain to the tip does not match the model".
TEST(UrdfVisuals, FollowTheDefaultTipOfTheModel) {
  const std::string file = (std::filesystem::temp_directory_path() / "rp_urdf_visuals_jaw.urdf").string();
  const std::string box = "<visual><geometry><box size=\"0.1 0.1 0.1\"/></geometry></visual>";
  const std::string inertial = "<inertial><mass value=\"1\"/><inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/></inertial>";
  std::ofstream(file) << "<robot name=\"jaw\"><link name=\"base\"/><link name=\"upper\">" << box << inertial
                      << "</link><link name=\"stator\">" << box << "</link><link name=\"jaw_link\">" << inertial
                      << "</link><joint name=\"shoulder\" type=\"revolute\"><parent link=\"base\"/><child link=\"upper\"/>"
                         "<axis xyz=\"0 0 1\"/><limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/></joint>"
                         "<joint name=\"mount\" type=\"fixed\"><parent link=\"upper\"/><child link=\"stator\"/>"
                         "<origin xyz=\"0.2 0 0\"/></joint><joint name=\"jaw_joint\" type=\"revolute\"><parent link=\"stator\"/>"
                         "<child link=\"jaw_link\"/><axis xyz=\"0 1 0\"/><limit lower=\"-1\" upper=\"0\" effort=\"1\" "
                         "velocity=\"1\"/></joint></robot>";
  ASSERT_EQ(rp::loadUrdf(file)->getNumberOfJoints(), 1);
  const auto shapes = rp::loadUrdfVisuals(file);
  ASSERT_EQ(shapes.size(), 2u);
  for (const auto& s : shapes) EXPECT_EQ(s.frame, "link1");
  std::filesystem::remove(file);
}

}  // namespace
