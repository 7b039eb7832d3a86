// URDF <visual> elements as Model3D shapes in the frames of the arm's DH model (see UrdfVisuals.hpp).
#include "rp/gui/UrdfVisuals.hpp"

#include <urdf_parser/urdf_parser.h>

#include <Eigen/Geometry>

#include <filesystem>
#include <fstream>
#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <functional>
#include <numbers>
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

bool isRegularFile(const std::filesystem::path& p) {
  std::error_code ec;
  return std::filesystem::is_regular_file(p, ec);
}

// The mesh formats the page draws (by the file's extension, lower case).
bool isDrawnFormat(const std::string& file) {
  std::string ext = std::filesystem::path(file).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".stl" || ext == ".dae" || ext == ".obj" || ext == ".glb" || ext == ".gltf" || ext == ".wrl";
}

// The image formats the page draws as textures (by the file's extension, lower case).
bool isImageFile(const std::string& file) {
  std::string ext = std::filesystem::path(file).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg";
}

// A URDF <geometry> as a shape (kind, size and mesh), false for a kind that is not drawn.
bool geometryShape(const urdf::Geometry& g, const std::string& urdfFile, const std::vector<std::string>& packagePath,
                   Shape& s, std::string& uri, std::string& error) {
  switch (g.type) {
    case urdf::Geometry::BOX: {
      const auto& b = static_cast<const urdf::Box&>(g);
      s.kind = ShapeKind::Box;
      s.size = Vector<3>{{b.dim.x}, {b.dim.y}, {b.dim.z}};
      return true;
    }
    case urdf::Geometry::CYLINDER: {
      const auto& c = static_cast<const urdf::Cylinder&>(g);
      s.kind = ShapeKind::Cylinder;
      s.size = Vector<3>{{c.radius}, {c.length}, {0}};
      return true;
    }
    case urdf::Geometry::SPHERE: {
      const auto& c = static_cast<const urdf::Sphere&>(g);
      s.kind = ShapeKind::Sphere;
      s.size = Vector<3>{{c.radius}, {0}, {0}};
      return true;
    }
    case urdf::Geometry::MESH: {
      const auto& m = static_cast<const urdf::Mesh&>(g);
      s.kind = ShapeKind::Mesh;
      s.size = Vector<3>{{m.scale.x}, {m.scale.y}, {m.scale.z}};
      uri = m.filename;
      std::string searched;
      s.meshFile = resolveMeshUri(m.filename, urdfFile, packagePath, &searched);
      if (s.meshFile.empty()) {
        error = "no such file (looked in " + searched + ")";
      } else if (!isDrawnFormat(s.meshFile)) {
        error = "format not drawn (STL, Collada .dae, Wavefront .obj, glTF .glb/.gltf and VRML .wrl are)";
        s.meshFile.clear();
      }
      return true;
    }
    default:
      return false;
  }
}

}  // namespace

std::vector<std::string> splitPackagePath(const std::string& list, const std::string& base) {
  namespace fs = std::filesystem;
  std::vector<std::string> dirs;
  std::size_t start = 0;
  while (start <= list.size()) {
    std::size_t end = list.find(':', start);
    if (end == std::string::npos) end = list.size();
    const std::string entry = list.substr(start, end - start);
    if (!entry.empty()) {
      fs::path p(entry);
      if (p.is_relative()) p = base.empty() ? fs::absolute(p) : fs::absolute(fs::path(base) / p);
      dirs.push_back(p.lexically_normal().string());
    }
    start = end + 1;
  }
  return dirs;
}

std::string resolveMeshUri(const std::string& uri, const std::string& urdfFile,
                           const std::vector<std::string>& packagePath, std::string* searched) {
  namespace fs = std::filesystem;
  const fs::path urdfDir = fs::absolute(fs::path(urdfFile)).parent_path();
  std::vector<fs::path> candidates;
  if (uri.rfind("http://", 0) == 0 || uri.rfind("https://", 0) == 0) return uri;
  if (uri.rfind("file://", 0) == 0) {
    candidates.push_back(fs::path(uri.substr(7)));
  } else if (uri.rfind("package://", 0) == 0) {
    const std::string rest = uri.substr(10);
    const std::size_t slash = rest.find('/');
    const std::string package = rest.substr(0, slash);
    const std::string inside = slash == std::string::npos ? "" : rest.substr(slash + 1);
    if (!package.empty() && package != "." && package != ".." && !inside.empty()) {
      std::vector<std::string> dirs = packagePath;
      if (const char* env = std::getenv("ROS_PACKAGE_PATH"); env && *env)
        for (const std::string& d : splitPackagePath(env)) dirs.push_back(d);
      for (const std::string& d : dirs) candidates.push_back(fs::path(d) / package / inside);
      // The folders above the description: the package folder itself, or one that holds it.
      for (fs::path dir = urdfDir; !dir.empty(); dir = dir.parent_path()) {
        if (dir.filename() == package) candidates.push_back(dir / inside);
        candidates.push_back(dir / package / inside);
        if (dir == dir.parent_path()) break;
      }
    }
  } else {
    const fs::path p(uri);
    candidates.push_back(p.is_absolute() ? p : urdfDir / p);
  }
  std::string places;
  for (const fs::path& c : candidates) {
    const fs::path file = fs::absolute(c).lexically_normal();
    if (isRegularFile(file)) return file.string();
    if (places.size() < 2000) places += (places.empty() ? "" : ", ") + file.string();
  }
  if (searched) *searched = places.empty() ? "nowhere: not a file name" : places;
  return {};
}

std::vector<Shape> loadUrdfVisuals(const std::string& urdfFile, const std::string& tip) {
  UrdfVisualOptions options;
  options.tip = tip;
  std::vector<Shape> shapes;
  for (UrdfVisual& v : readUrdfVisuals(urdfFile, options)) shapes.push_back(std::move(v.shape));
  return shapes;
}

std::vector<UrdfVisual> readUrdfVisuals(const std::string& urdfFile, const UrdfVisualOptions& visualOptions) {
  const std::string& tip = visualOptions.tip;
  // The model (and the checks) of loadUrdf(): the link frames the shapes are attached to.
  UrdfOptions options;
  options.tip = tip;
  options.offChainPositions = visualOptions.offChainPositions;
  options.offChainInDegreesAndMillimetres = visualOptions.offChainInDegreesAndMillimetres;
  const std::unique_ptr<ManipulatorModel> model = loadUrdf(urdfFile, options);
  std::ifstream in(urdfFile);
  if (!in) throw UrdfError(urdfFile + ": cannot read the file");
  std::stringstream text;
  text << in.rdbuf();
  const urdf::ModelInterfaceSharedPtr robot = urdf::parseURDF(text.str());
  if (!robot || !robot->getRoot()) throw UrdfError(urdfFile + ": not a valid URDF file");

  // The movable joints of the chain root -> tip, in order: the model's own joints and the mimic
  // joints that follow them (loadUrdf() chose the tip and kept the URDF's joint names).
  const ManipulatorModel& chainModel = model->getChain();
  std::vector<std::string> chain;
  for (int i = 0; i < chainModel.getNumberOfJoints(); ++i) chain.push_back(chainModel.getJointName(i));
  const int n = chainModel.getNumberOfJoints();
  // The frames shapes are attached to: the model's link frames `linkK`, or with mimic joints the
  // chain's `chainK` (a link a mimic joint moves has no model link frame).
  const std::string framePrefix = model->hasMimicJoints() ? "chain" : "link";

  // Chain link frames at q = 0 in the URDF root frame (the model's base is the root frame; joint
  // values keep the URDF's zero, so URDF link poses at q = 0 compare directly).
  ManipulatorData data(chainModel);
  forwardKinematics(chainModel, data, JointVector::Zero(n));
  auto frameAtZero = [&](int k) -> Transform {
    return k == 0 ? chainModel.getBaseTransform() : Transform(data.linkTransforms[static_cast<std::size_t>(k - 1)]);
  };

  // Where a moving joint off the chain (a finger, a jaw) stands: where loadUrdf() lumps its links
  // (the position given, which loadUrdf() has checked; a mimic joint at its master's value times
  // the multiplier plus the offset; zero within the limits otherwise).
  auto given = [&](const urdf::Joint& j, double& v) {
    const auto it = visualOptions.offChainPositions.find(j.name);
    if (it == visualOptions.offChainPositions.end()) return false;
    const double scale = !visualOptions.offChainInDegreesAndMillimetres ? 1.0
                         : j.type == urdf::Joint::PRISMATIC             ? 1e-3
                                                                        : std::numbers::pi / 180;
    v = it->second * scale;
    return true;
  };
  auto offChainMotion = [&](const urdf::Joint& joint) {
    const urdf::Joint* j = &joint;
    double multiplier = 1, offset = 0, v = 0;
    for (std::size_t depth = 0; depth <= robot->joints_.size() && j; ++depth) {
      if (given(*j, v)) break;
      if (!j->mimic) {
        if (j->limits && j->type != urdf::Joint::CONTINUOUS) v = std::clamp(0.0, j->limits->lower, j->limits->upper);
        break;
      }
      offset += multiplier * j->mimic->offset;
      multiplier *= j->mimic->multiplier;
      j = robot->getJoint(j->mimic->joint_name).get();
    }
    v = multiplier * v + offset;
    const Eigen::Vector3d axis = Eigen::Vector3d(joint.axis.x, joint.axis.y, joint.axis.z).normalized();
    Transform motion = Transform::unit();
    if (joint.type == urdf::Joint::PRISMATIC) motion.topRightCorner<3, 1>() = v * axis;
    else motion.topLeftCorner<3, 3>() = Eigen::AngleAxisd(v, axis).toRotationMatrix();
    return motion;
  };

  std::vector<UrdfVisual> visuals;
  // Depth-first from the root: the link's pose at q = 0 and how many chain joints lead to it.
  std::function<void(const urdf::LinkConstSharedPtr&, const Transform&, int)> visit =
      [&](const urdf::LinkConstSharedPtr& link, const Transform& pose, int k) {
        const Transform inFrame = Transform(rigidInverse(frameAtZero(k)) * pose);
        const std::string frame = k == 0 ? "base" : framePrefix + std::to_string(k);
        std::vector<Shape> collision;  // the link's collision geometry, the stand-in for a mesh not drawn
        for (const urdf::CollisionSharedPtr& c : link->collision_array) {
          if (!c || !c->geometry) continue;
          Shape s;
          std::string uri, error;
          if (!geometryShape(*c->geometry, urdfFile, visualOptions.packagePath, s, uri, error) || !error.empty()) continue;
          s.frame = frame;
          s.pose = Transform(inFrame * poseOf(c->origin));
          collision.push_back(std::move(s));
        }
        for (const urdf::VisualSharedPtr& v : link->visual_array) {
          if (!v || !v->geometry) continue;
          UrdfVisual visual;
          Shape& s = visual.shape;
          if (!geometryShape(*v->geometry, urdfFile, visualOptions.packagePath, s, visual.meshUri, visual.meshError))
            continue;
          s.frame = frame;
          s.pose = Transform(inFrame * poseOf(v->origin));
          urdf::MaterialSharedPtr material = v->material;
          if (!material && !v->material_name.empty()) material = robot->getMaterial(v->material_name);
          if (material) s.color = Color{material->color.r, material->color.g, material->color.b, material->color.a};
          if (material && !material->texture_filename.empty()) {
            visual.textureUri = material->texture_filename;
            std::string searched;
            visual.textureFile = resolveMeshUri(visual.textureUri, urdfFile, visualOptions.packagePath, &searched);
            if (visual.textureFile.empty() || visual.textureFile.rfind("http", 0) == 0) {
              visual.textureError = visual.textureFile.empty() ? "no such file (looked in " + searched + ")"
                                                               : "only local image files are drawn";
              visual.textureFile.clear();
            } else if (!isImageFile(visual.textureFile)) {
              visual.textureError = "format not drawn (PNG and JPEG are)";
              visual.textureFile.clear();
            }
          }
          visual.link = link->name;
          visual.collision = collision;
          visuals.push_back(std::move(visual));
        }
        for (const urdf::JointSharedPtr& j : link->child_joints) {
          const urdf::LinkConstSharedPtr child = robot->getLink(j->child_link_name);
          if (!child) continue;
          int childK = k;
          Transform motion = Transform::unit();
          if (isMovable(j)) {
            if (k < n && chain[static_cast<std::size_t>(k)] == j->name) {
              childK = k + 1;  // the chain's next joint moves the next frame
            } else {
              // A moving link off the chain (a finger, a jaw) is drawn on the link it hangs on,
              // where its mass is lumped.
              motion = offChainMotion(*j);
            }
          } else if (j->type != urdf::Joint::FIXED) {
            continue;  // floating or planar: not part of the arm
          }
          visit(child, Transform(pose * poseOf(j->parent_to_joint_origin_transform) * motion), childK);
        }
      };
  visit(robot->getRoot(), Transform::unit(), 0);
  return visuals;
}

}  // namespace rp
