// URDF <visual> elements as shapes of the arm's 3D model (loadUrdfVisuals): every visual, placed
// in its DH frame by the viewer, lands where the URDF's own kinematics puts it, for any joint
// vector (the reference is the URDF chain written out by hand, not the library's conversion).
#include "rp/gui/UrdfVisuals.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <string>
#include <unistd.h>

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

// Issue 20: a mimic joint on the chain moves its link with its master. The shapes hang on the
// chain's frames (`chainK`), and placed by the chain frames of the model's forward kinematics
// (what the Scene Viewer sends) they land where the URDF written out by hand puts them, the
// elbow at -shoulder + 0.2.
TEST(UrdfVisuals, LinksOfMimicJointsMoveWithTheirMaster) {
  const std::string file = (std::filesystem::temp_directory_path() / "rp_urdf_visuals_mimic.urdf").string();
  auto box = [](const char* x) { return std::string("<visual><origin xyz=\"") + x + " 0 0\"/><geometry><box size=\"0.1 0.05 0.05\"/></geometry></visual>"; };
  const std::string limit = "<limit lower=\"-2\" upper=\"2\" effort=\"1\" velocity=\"1\"/>";
  std::ofstream(file) << "<robot name=\"mimic\"><link name=\"base\"/><link name=\"upper\">" << box("0.15")
                      << "</link><link name=\"fore\">" << box("0.1") << "</link><link name=\"hand\">" << box("0.05")
                      << "</link><joint name=\"shoulder\" type=\"revolute\"><parent link=\"base\"/><child link=\"upper\"/>"
                         "<axis xyz=\"0 0 1\"/>" << limit << "</joint>"
                         "<joint name=\"elbow\" type=\"revolute\"><parent link=\"upper\"/><child link=\"fore\"/>"
                         "<origin xyz=\"0.3 0 0\"/><axis xyz=\"0 0 1\"/>" << limit
                      << "<mimic joint=\"shoulder\" multiplier=\"-1\" offset=\"0.2\"/></joint>"
                         "<joint name=\"wrist\" type=\"revolute\"><parent link=\"fore\"/><child link=\"hand\"/>"
                         "<origin xyz=\"0.25 0 0\"/><axis xyz=\"0 1 0\"/>" << limit << "</joint></robot>";
  const auto model = rp::loadUrdf(file);
  ASSERT_EQ(model->getNumberOfJoints(), 2);  // shoulder and wrist; the elbow follows the shoulder
  const auto shapes = rp::loadUrdfVisuals(file);
  ASSERT_EQ(shapes.size(), 3u);
  EXPECT_EQ(shapes[0].frame, "chain1");
  EXPECT_EQ(shapes[1].frame, "chain2");
  EXPECT_EQ(shapes[2].frame, "chain3");
  rp::ManipulatorData data(*model);
  ASSERT_NE(data.chain, nullptr);
  for (const double q1 : {0.0, 0.7, -1.1}) {
    const double q2 = 0.5 - q1;
    rp::JointVector q(2);
    q << q1, q2;
    rp::forwardKinematics(*model, data, q);
    const rp::Transform l1 = rotZ(q1);
    const rp::Transform l2 = rp::Transform(l1 * rp::translation(0.3, 0, 0) * rotZ(-q1 + 0.2));
    const rp::Transform l3 = rp::Transform(l2 * rp::translation(0.25, 0, 0) * rotY(q2));
    const rp::Transform expected[3] = {rp::Transform(l1 * rp::translation(0.15, 0, 0)), rp::Transform(l2 * rp::translation(0.1, 0, 0)),
                                       rp::Transform(l3 * rp::translation(0.05, 0, 0))};
    for (std::size_t i = 0; i < 3; ++i) {
      const rp::Transform frame = data.chain->linkTransforms[static_cast<std::size_t>(std::stoi(shapes[i].frame.substr(5)) - 1)];
      EXPECT_LT((rp::Transform(frame * shapes[i].pose) - expected[i]).cwiseAbs().maxCoeff(), 1e-12) << "shape " << i << " at q1 " << q1;
    }
  }
  std::filesystem::remove(file);
}

// Issue 20: links moved by joints off the chain (two fingers, the second a mimic) are drawn, on
// the chain link they hang on, where loadUrdf() lumps them (and says so in a note): at the
// fingers' lower limit 0.01 m (zero is outside it), the mimic finger at -0.5 * master + 0.05
// along its own axis, or where UrdfVisualOptions::offChainPositions puts them. They used to be
// left out.
TEST(UrdfVisuals, MovingLinksOffTheChainAreDrawnWhereTheyAreLumped) {
  const std::string file = (std::filesystem::temp_directory_path() / "rp_urdf_visuals_fingers.urdf").string();
  const std::string box = "<visual><geometry><box size=\"0.02 0.02 0.06\"/></geometry></visual>";
  const std::string inertial = "<inertial><mass value=\"0.1\"/><inertia ixx=\"1e-4\" ixy=\"0\" ixz=\"0\" iyy=\"1e-4\" iyz=\"0\" izz=\"1e-4\"/></inertial>";
  const std::string limit = "<limit lower=\"0.01\" upper=\"0.04\" effort=\"10\" velocity=\"0.1\"/>";
  std::ofstream(file) << "<robot name=\"fingers\"><link name=\"base\"/><link name=\"upper\">" << inertial
                      << "</link><link name=\"hand\">" << box << "</link><link name=\"left_finger\">" << box << inertial
                      << "</link><link name=\"right_finger\">" << box << inertial
                      << "</link><joint name=\"shoulder\" type=\"revolute\"><parent link=\"base\"/><child link=\"upper\"/>"
                         "<axis xyz=\"0 0 1\"/><limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/></joint>"
                         "<joint name=\"mount\" type=\"fixed\"><parent link=\"upper\"/><child link=\"hand\"/>"
                         "<origin xyz=\"0.3 0 0\" rpy=\"0 1.5707963267948966 0\"/></joint>"
                         "<joint name=\"finger_left\" type=\"prismatic\"><parent link=\"hand\"/><child link=\"left_finger\"/>"
                         "<origin xyz=\"0 0 0.05\"/><axis xyz=\"0 1 0\"/>" << limit << "</joint>"
                      << "<joint name=\"finger_right\" type=\"prismatic\"><parent link=\"hand\"/><child link=\"right_finger\"/>"
                         "<origin xyz=\"0 0 0.05\"/><axis xyz=\"0 -1 0\"/>" << limit
                      << "<mimic joint=\"finger_left\" multiplier=\"-0.5\" offset=\"0.05\"/></joint></robot>";
  std::vector<std::string> notes;
  rp::UrdfOptions modelOptions;
  modelOptions.notes = &notes;
  ASSERT_EQ(rp::loadUrdf(file, modelOptions)->getNumberOfJoints(), 1);  // the fingers are lumped...
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("links 'left_finger', 'right_finger' move off the chain: their mass is lumped into 'upper'"),
            std::string::npos) << notes[0];  // ... and the loader says so
  const rp::Transform hand = rp::Transform(rp::translation(0.3, 0, 0) * rotY(1.5707963267948966));
  // By default; where UrdfVisualOptions::offChainPositions puts the master (in m, or in mm as
  // rp.cfg gives it); the mimic finger named itself.
  struct Case {
    std::map<std::string, double> positions;
    bool millimetres;
    double left, right;
  };
  for (const Case& c : {Case{{}, false, 0.01, -0.5 * 0.01 + 0.05}, Case{{{"finger_left", 0.03}}, false, 0.03, -0.5 * 0.03 + 0.05},
                        Case{{{"finger_left", 25}}, true, 0.025, -0.5 * 0.025 + 0.05},
                        Case{{{"finger_right", 0.02}}, false, 0.01, 0.02}}) {
    rp::UrdfVisualOptions options;
    options.offChainPositions = c.positions;
    options.offChainInDegreesAndMillimetres = c.millimetres;
    const auto visuals = rp::readUrdfVisuals(file, options);
    ASSERT_EQ(visuals.size(), 3u);
    const double left = c.left, right = c.right;
    const rp::Transform expected[3] = {hand, rp::Transform(hand * rp::translation(0, left, 0.05)),
                                       rp::Transform(hand * rp::translation(0, -right, 0.05))};
    for (std::size_t i = 0; i < 3; ++i) {
      EXPECT_EQ(visuals[i].shape.frame, "link1");
      EXPECT_LT((visuals[i].shape.pose - expected[i]).cwiseAbs().maxCoeff(), 1e-12) << visuals[i].link << " at " << left;
    }
    EXPECT_EQ(visuals[1].link, "left_finger");
    EXPECT_EQ(visuals[2].link, "right_finger");
  }
  std::filesystem::remove(file);
}

// The mesh arm of the browser test, in its package folder rp_mesh_arm (package:// URIs).
const std::string kPackages = std::string(RP_TEST_DATA_DIR) + "/packages";
const std::string kMeshArm = kPackages + "/rp_mesh_arm/urdf/mesh_arm.urdf";

// A temporary folder removed at the end of the test; ROS_PACKAGE_PATH unset meanwhile.
class TempDir {
 public:
  TempDir() {
    path_ = std::filesystem::temp_directory_path() / ("rp-urdf-visuals-" + std::to_string(::getpid()) + "-" +
                                                      std::to_string(counter_++));
    std::filesystem::create_directories(path_);
    if (const char* env = std::getenv("ROS_PACKAGE_PATH")) saved_ = env, hadEnv_ = true;
    ::unsetenv("ROS_PACKAGE_PATH");
  }
  ~TempDir() {
    std::filesystem::remove_all(path_);
    if (hadEnv_) ::setenv("ROS_PACKAGE_PATH", saved_.c_str(), 1);
    else ::unsetenv("ROS_PACKAGE_PATH");
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  static inline int counter_ = 0;
  std::filesystem::path path_;
  std::string saved_;
  bool hadEnv_ = false;
};

std::string meshOf(const std::vector<rp::UrdfVisual>& visuals, const std::string& link) {
  for (const auto& v : visuals)
    if (v.link == link) return v.shape.meshFile;
  return "<no visual of " + link + ">";
}

TEST(UrdfVisuals, PackageMeshesFoundInTheFoldersAboveTheDescription) {
  TempDir temp;
  const auto visuals = rp::readUrdfVisuals(kMeshArm, {"hand_link", {}, {}, false});
  ASSERT_EQ(visuals.size(), 7u);
  const auto meshes = std::filesystem::absolute(kPackages + "/rp_mesh_arm/meshes").lexically_normal();
  EXPECT_EQ(meshOf(visuals, "upper_link"), (meshes / "upper_arm.dae").string());
  EXPECT_EQ(meshOf(visuals, "fore_link"), (meshes / "forearm.stl").string());
  EXPECT_EQ(meshOf(visuals, "hand_link"), (meshes / "hand.obj").string());
  EXPECT_EQ(visuals[0].link, "base_link");
  EXPECT_EQ(visuals[0].meshUri, "package://rp_mesh_arm/meshes/base.obj");
  EXPECT_NEAR(visuals[0].shape.color.b, 0.45, 1e-6);  // the robot's material "slate"
  EXPECT_DOUBLE_EQ(visuals[3].shape.size(0), 0.001);  // the STL's scale
  // The hand's texture is found as the meshes are; the forearm's does not exist.
  EXPECT_EQ(visuals[4].textureUri, "package://rp_mesh_arm/textures/checker.png");
  EXPECT_EQ(visuals[4].textureFile, (meshes.parent_path() / "textures/checker.png").string());
  EXPECT_EQ(visuals[4].textureError, "");
  EXPECT_EQ(visuals[3].textureFile, "");
  EXPECT_NE(visuals[3].textureError.find("no such file"), std::string::npos) << visuals[3].textureError;
  EXPECT_EQ(visuals[0].textureUri, "");
  for (const auto& v : visuals)
    EXPECT_EQ(v.meshError, v.link == "sensor_link" || v.link == "tag_link" ? v.meshError : "") << v.link;
}

TEST(UrdfVisuals, MovedDescriptionFindsItsPackagesThroughThePackagePath) {
  TempDir temp;
  const auto moved = temp.path() / "mesh_arm.urdf";
  std::filesystem::copy_file(kMeshArm, moved);
  // Nothing above the moved file holds the package: not found, and the error says where it looked.
  auto lost = rp::readUrdfVisuals(moved.string(), {"hand_link", {}, {}, false});
  ASSERT_EQ(lost.size(), 7u);
  EXPECT_EQ(lost[1].shape.meshFile, "");
  EXPECT_NE(lost[1].meshError.find("no such file"), std::string::npos) << lost[1].meshError;
  EXPECT_NE(lost[1].meshError.find((temp.path() / "rp_mesh_arm/meshes/upper_arm.dae").string()), std::string::npos)
      << lost[1].meshError;
  // The package path (as rp.cfg's packagePath gives it) finds them; a folder without the package is passed over.
  const auto found = rp::readUrdfVisuals(moved.string(), {"hand_link", {"/nonexistent", kPackages}, {}, false});
  EXPECT_EQ(found[1].meshError, "");
  EXPECT_EQ(found[1].shape.meshFile,
            std::filesystem::absolute(kPackages + "/rp_mesh_arm/meshes/upper_arm.dae").lexically_normal().string());
  // So does ROS_PACKAGE_PATH.
  ::setenv("ROS_PACKAGE_PATH", ("/nonexistent:" + kPackages).c_str(), 1);
  EXPECT_EQ(rp::readUrdfVisuals(moved.string(), {"hand_link", {}, {}, false})[1].shape.meshFile, found[1].shape.meshFile);
  // The package path comes before ROS_PACKAGE_PATH, each in its order: a second copy of the
  // package's base.obj in the temporary folder wins when it is listed first.
  std::filesystem::create_directories(temp.path() / "pkgs/rp_mesh_arm/meshes");
  std::ofstream(temp.path() / "pkgs/rp_mesh_arm/meshes/base.obj") << "v 0 0 0\n";
  const auto mine = rp::readUrdfVisuals(moved.string(), {"hand_link", {(temp.path() / "pkgs").string()}, {}, false});
  EXPECT_EQ(mine[0].shape.meshFile, (temp.path() / "pkgs/rp_mesh_arm/meshes/base.obj").string());
  EXPECT_EQ(mine[1].shape.meshFile, found[1].shape.meshFile);  // not in pkgs: from ROS_PACKAGE_PATH
}

TEST(UrdfVisuals, MeshesThatCannotBeDrawnSayWhyAndBringTheCollisionGeometry) {
  TempDir temp;
  const auto visuals = rp::readUrdfVisuals(kMeshArm, {"hand_link", {}, {}, false});
  const rp::UrdfVisual& sensor = visuals[5];
  EXPECT_EQ(sensor.link, "sensor_link");
  EXPECT_EQ(sensor.shape.meshFile, "");
  EXPECT_NE(sensor.meshError.find("no such file"), std::string::npos) << sensor.meshError;
  ASSERT_EQ(sensor.collision.size(), 1u);  // its collision box, in the same frame as the visual
  EXPECT_EQ(sensor.collision[0].kind, rp::ShapeKind::Box);
  EXPECT_EQ(sensor.collision[0].frame, sensor.shape.frame);
  EXPECT_DOUBLE_EQ(sensor.collision[0].size(1), 0.03);
  EXPECT_NEAR((sensor.collision[0].pose - rp::Transform(sensor.shape.pose * rp::translation(0.02, 0, 0))).cwiseAbs().maxCoeff(),
              0, 1e-12);
  EXPECT_TRUE(visuals[1].collision.empty());
  // The tag's collision mesh is found through the package as the visuals are.
  EXPECT_EQ(visuals[6].link, "tag_link");
  ASSERT_EQ(visuals[6].collision.size(), 1u);
  EXPECT_EQ(visuals[6].collision[0].kind, rp::ShapeKind::Mesh);
  EXPECT_EQ(visuals[6].collision[0].meshFile,
            std::filesystem::absolute(kPackages + "/rp_mesh_arm/meshes/base.obj").lexically_normal().string());
  EXPECT_DOUBLE_EQ(visuals[6].collision[0].size(2), 0.25);
  // A format the page does not draw is refused here, naming the formats it draws.
  std::filesystem::copy_file(kMeshArm, temp.path() / "arm.urdf");
  std::ofstream(temp.path() / "part.ply") << "ply\n";
  std::ifstream in(kMeshArm);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string base = "package://rp_mesh_arm/meshes/base.obj";
  text.replace(text.find(base), base.size(), "part.ply");
  std::ofstream(temp.path() / "arm.urdf", std::ios::trunc) << text;
  const auto ply = rp::readUrdfVisuals((temp.path() / "arm.urdf").string(), {"hand_link", {kPackages}, {}, false});
  EXPECT_EQ(ply[0].shape.meshFile, "");
  EXPECT_NE(ply[0].meshError.find("format not drawn"), std::string::npos) << ply[0].meshError;
}

TEST(UrdfVisuals, PackagePathLists) {
  EXPECT_EQ(rp::splitPackagePath("/a::/b/../c:", "/base"), (std::vector<std::string>{"/a", "/c"}));
  EXPECT_EQ(rp::splitPackagePath("rel:/abs", "/base"), (std::vector<std::string>{"/base/rel", "/abs"}));
  EXPECT_TRUE(rp::splitPackagePath("").empty());
  // Not a package URI that names a file: nothing is found.
  EXPECT_EQ(rp::resolveMeshUri("package://rp_mesh_arm", kMeshArm, {kPackages}), "");
  EXPECT_EQ(rp::resolveMeshUri("package://../rp_mesh_arm/meshes/base.obj", kMeshArm, {kPackages}), "");
  EXPECT_EQ(rp::resolveMeshUri("https://example.org/m.dae", kMeshArm, {}), "https://example.org/m.dae");
}

}  // namespace
