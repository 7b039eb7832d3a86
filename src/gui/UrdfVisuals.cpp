// URDF <visual> elements as Model3D shapes in the frames of the arm's DH model (see UrdfVisuals.hpp).
#include "rp/gui/UrdfVisuals.hpp"

#include <urdf_parser/urdf_parser.h>

#include <Eigen/Geometry>

#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>

#include "rp/model/Kinematics.hpp"
#include "rp/model/ManipulatorData.hpp"
#include "rp/model/UrdfModel.hpp"

namespace rp {

namespace {

Transform poseOf(const urdf::Pose& p) {
  Transform t = Transform::unit();
  const Eigen::Quaterniond q(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z);
  t.block<3, 3>(0, 0) = q.normalized().toRotationMatrix();
  t(0, 3) = p.position.x;
  t(1, 3) = p.position.y;
  t(2, 3) = p.position.z;
  return t;
}

bool isMovable(const urdf::JointConstSharedPtr& j) {
  return j->type == urdf::Joint::REVOLUTE || j->type == urdf::Joint::CONTINUOUS || j->type == urdf::Joint::PRISMATIC;
}

// A mesh file name of the URDF as a path the server can open (or an http(s) URL, kept).
std::string resolveMesh(const std::string& name, const std::filesystem::path& urdfDir) {
  namespace fs = std::filesystem;
  if (name.rfind("http://", 0) == 0 || name.rfind("https://", 0) == 0) return name;
  if (name.rfind("file://", 0) == 0) return name.substr(7);
  if (name.rfind("package://", 0) == 0) {
    const std::string rest = name.substr(10);
    const std::string package = rest.substr(0, rest.find('/'));
    const std::string inside = rest.find('/') == std::string::npos ? "" : rest.substr(rest.find('/') + 1);
    for (fs::path dir = fs::absolute(urdfDir); !dir.empty(); dir = dir.parent_path()) {
      if (dir.filename() == package) return (dir / inside).string();
      if (fs::is_directory(dir / package)) return (dir / package / inside).string();
      if (dir == dir.parent_path()) break;
    }
    return (fs::absolute(urdfDir) / inside).string();  // best guess: next to the URDF file
  }
  const fs::path p(name);
  return p.is_absolute() ? name : (fs::absolute(urdfDir) / p).lexically_normal().string();
}

}  // namespace

std::vector<Shape> loadUrdfVisuals(const std::string& urdfFile, const std::string& tip) {
  // The model (and the checks) of loadUrdf(): the link frames the shapes are attached to.
  UrdfOptions options;
  options.tip = tip;
  const std::unique_ptr<ManipulatorModel> model = loadUrdf(urdfFile, options);
  std::ifstream in(urdfFile);
  if (!in) throw UrdfError(urdfFile + ": cannot read the file");
  std::stringstream text;
  text << in.rdbuf();
  const urdf::ModelInterfaceSharedPtr robot = urdf::parseURDF(text.str());
  if (!robot || !robot->getRoot()) throw UrdfError(urdfFile + ": not a valid URDF file");

  // The movable joints of the chain root -> tip, in order: the model's own joints (loadUrdf()
  // chose the tip and kept the URDF's joint names).
  std::vector<std::string> chain;
  for (int i = 0; i < model->getNumberOfJoints(); ++i) chain.push_back(model->getJointName(i));
  const int n = model->getNumberOfJoints();

  // Model link frames at q = 0 in the URDF root frame (the model's base is the root frame; joint
  // values keep the URDF's zero, so URDF link poses at q = 0 compare directly).
  ManipulatorData data(*model);
  forwardKinematics(*model, data, JointVector::Zero(n));
  auto frameAtZero = [&](int k) -> Transform {
    return k == 0 ? model->getBaseTransform() : Transform(data.linkTransforms[static_cast<std::size_t>(k - 1)]);
  };

  const std::filesystem::path urdfDir = std::filesystem::path(urdfFile).parent_path();
  std::vector<Shape> shapes;
  // Depth-first from the root: the link's pose at q = 0 and how many chain joints lead to it.
  std::function<void(const urdf::LinkConstSharedPtr&, const Transform&, int)> visit =
      [&](const urdf::LinkConstSharedPtr& link, const Transform& pose, int k) {
        const Transform inFrame = Transform(rigidInverse(frameAtZero(k)) * pose);
        for (const urdf::VisualSharedPtr& v : link->visual_array) {
          if (!v || !v->geometry) continue;
          Shape s;
          s.frame = k == 0 ? "base" : "link" + std::to_string(k);
          s.pose = Transform(inFrame * poseOf(v->origin));
          switch (v->geometry->type) {
            case urdf::Geometry::BOX: {
              const auto& b = static_cast<const urdf::Box&>(*v->geometry);
              s.kind = ShapeKind::Box;
              s.size = Vector<3>{{b.dim.x}, {b.dim.y}, {b.dim.z}};
              break;
            }
            case urdf::Geometry::CYLINDER: {
              const auto& c = static_cast<const urdf::Cylinder&>(*v->geometry);
              s.kind = ShapeKind::Cylinder;
              s.size = Vector<3>{{c.radius}, {c.length}, {0}};
              break;
            }
            case urdf::Geometry::SPHERE: {
              const auto& c = static_cast<const urdf::Sphere&>(*v->geometry);
              s.kind = ShapeKind::Sphere;
              s.size = Vector<3>{{c.radius}, {0}, {0}};
              break;
            }
            case urdf::Geometry::MESH: {
              const auto& m = static_cast<const urdf::Mesh&>(*v->geometry);
              s.kind = ShapeKind::Mesh;
              s.meshFile = resolveMesh(m.filename, urdfDir);
              s.size = Vector<3>{{m.scale.x}, {m.scale.y}, {m.scale.z}};
              break;
            }
            default:
              continue;
          }
          urdf::MaterialSharedPtr material = v->material;
          if (!material && !v->material_name.empty()) material = robot->getMaterial(v->material_name);
          if (material) s.color = Color{material->color.r, material->color.g, material->color.b, material->color.a};
          shapes.push_back(std::move(s));
        }
        for (const urdf::JointSharedPtr& j : link->child_joints) {
          const urdf::LinkConstSharedPtr child = robot->getLink(j->child_link_name);
          if (!child) continue;
          int childK = k;
          if (isMovable(j)) {
            // Only the chain's next joint moves a frame we have; other moving branches are left out.
            if (k >= n || chain[static_cast<std::size_t>(k)] != j->name) continue;
            childK = k + 1;
          } else if (j->type != urdf::Joint::FIXED) {
            continue;  // floating or planar: not part of the arm
          }
          visit(child, Transform(pose * poseOf(j->parent_to_joint_origin_transform)), childK);
        }
      };
  visit(robot->getRoot(), Transform::unit(), 0);
  return shapes;
}

}  // namespace rp
