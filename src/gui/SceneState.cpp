// Scene description and binary state frames for the Scene Viewer (see SceneState.hpp).
#include "SceneState.hpp"

#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <set>

#include "../core/PhysicalObjectViews.hpp"
#include "../manipulator/ArmSnapshot.hpp"
#include "rp/core/ObjectManager.hpp"
#include "rp/effector/Gripper.hpp"
#include "rp/gui/SceneViewer.hpp"
#include "rp/gui/UrdfVisuals.hpp"
#include "rp/manipulator/DefaultManipulator.hpp"
#include "rp/manipulator/Manipulator.hpp"
#include "rp/manipulator/UrdfManipulator.hpp"
#include "rp/model/Kinematics.hpp"
#include "rp/model/ManipulatorData.hpp"
#include "rp/rt/ControlProgram.hpp"

namespace rp::internal {

namespace {

using nlohmann::json;

json transformJson(const Transform& t) {
  json a = json::array();
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) a.push_back(t(r, c));  // column-major, as three.js Matrix4.fromArray
  return a;
}

const char* shapeKindName(ShapeKind k) {
  switch (k) {
    case ShapeKind::Box: return "box";
    case ShapeKind::Cylinder: return "cylinder";
    case ShapeKind::Sphere: return "sphere";
    case ShapeKind::Mesh: return "mesh";
  }
  return "box";
}

json shapeJson(const Shape& s) {
  return json{{"kind", shapeKindName(s.kind)},
              {"frame", s.frame},
              {"pose", transformJson(s.pose)},
              {"size", {s.size(0), s.size(1), s.size(2)}},
              {"mesh", s.meshFile},
              {"color", {s.color.r, s.color.g, s.color.b, s.color.a}}};
}

// An object not published, of which only the name is read: no class, state, panel or commands.
json listedByName(const std::string& name) {
  return {{"path", "/objects/" + name},
          {"name", name},
          {"className", ""},
          {"kind", "unpublished"},
          {"published", false},
          {"physical", false},
          {"hasControlLoop", false},
          {"error", {{"code", 0}, {"message", ""}}},
          {"commands", json::array()},
          {"panel", {{"title", name}, {"fields", json::array()}}}};
}

const char* displayName(DisplayMode m) {
  switch (m) {
    case DisplayMode::Off: return "off";
    case DisplayMode::Solid: return "solid";
    case DisplayMode::Wireframe: return "wireframe";
  }
  return "solid";
}

const char* fieldKindName(FieldKind k) {
  switch (k) {
    case FieldKind::Number: return "number";
    case FieldKind::Vector: return "vector";
    case FieldKind::Boolean: return "boolean";
    case FieldKind::Text: return "text";
    case FieldKind::Choice: return "choice";
  }
  return "number";
}

json vectorJson(const JointVector& v) {
  json a = json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(v(i));
  return a;
}

void put32(std::string& out, std::uint32_t v) {
  char b[4];
  for (int i = 0; i < 4; ++i) b[i] = static_cast<char>((v >> (8 * i)) & 0xffu);
  out.append(b, 4);
}

void putDouble(std::string& out, double v) {
  static_assert(sizeof(double) == 8);
  std::uint64_t bits;
  std::memcpy(&bits, &v, 8);
  char b[8];
  for (int i = 0; i < 8; ++i) b[i] = static_cast<char>((bits >> (8 * i)) & 0xffu);
  out.append(b, 8);
}

void putTransform(std::string& out, const Transform& t) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) putDouble(out, t(r, c));
}

}  // namespace

// The <visual> elements of a UrdfManipulator's URDF file (made in code or from rp.cfg), read
// once per object; a mesh that cannot be drawn is reported on stderr (once per file).
void SceneState::loadVisuals(Entry& e) {
  e.urdfLoaded = true;
  const auto* arm = dynamic_cast<const UrdfManipulator*>(e.object);
  if (arm == nullptr || arm->getUrdfFile().empty()) return;
  try {
    UrdfVisualOptions options;
    options.tip = arm->getTip();
    options.packagePath = arm->getPackagePath();
    options.offChainPositions = arm->getOffChainPositions();
    options.offChainInDegreesAndMillimetres = true;
    e.urdfVisuals = readUrdfVisuals(arm->getUrdfFile(), options);
  } catch (const std::exception& ex) {
    e.urdfError = ex.what();
    reportOnce(arm->getUrdfFile(), "rp: Scene Viewer: '" + e.name + "' is drawn without its URDF visuals: " + ex.what());
    return;
  }
  for (const UrdfVisual& v : e.urdfVisuals) {
    if (!v.textureError.empty())
      reportOnce(v.textureUri, "rp: Scene Viewer: texture " + v.textureUri + " of link '" + v.link + "' of '" + e.name +
                                   "' (" + arm->getUrdfFile() + "): " + v.textureError + "; drawn in its colour");
    if (!v.meshError.empty())
      reportOnce(v.meshUri, "rp: Scene Viewer: mesh " + v.meshUri + " of link '" + v.link + "' of '" + e.name +
                                "' (" + arm->getUrdfFile() + "): " + v.meshError + "; drawn " +
                                (v.collision.empty() ? "as a placeholder" : "with its collision geometry"));
  }
}

bool SceneState::reportOnce(const std::string& file, const std::string& what) {
  if (!reportedMeshes_.insert(file).second) return false;
  std::cerr << what << std::endl;
  return true;
}

bool SceneState::reportMeshFailure(const std::string& name, std::size_t shape, const std::string& why) {
  const std::string file = meshFile(name, shape);
  if (file.empty()) return false;
  std::string text;  // the page's words, without control characters
  for (char c : why.substr(0, 200)) text += std::iscntrl(static_cast<unsigned char>(c)) ? ' ' : c;
  std::string ext = std::filesystem::path(file).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const bool image = ext == ".png" || ext == ".jpg" || ext == ".jpeg";  // a URDF texture
  return reportOnce(file, std::string("rp: Scene Viewer: ") + (image ? "texture " : "mesh ") + file + " of '" + name +
                              "' cannot be drawn: " + text +
                              (image ? "; drawn in its colour" : "; drawn with its collision geometry or a placeholder"));
}

SceneState::SceneState() = default;
SceneState::~SceneState() = default;

json SceneState::describe(Entry& e) {
  RoboticObject& o = *e.object;
  json j;
  j["path"] = "/objects/" + e.name;
  j["name"] = e.name;
  j["className"] = o.getClassName();
  e.program = o.getControlProgram();
  j["hasControlLoop"] = e.program != nullptr;
  e.physical = dynamic_cast<PhysicalObject*>(&o);
  e.manipulator = dynamic_cast<Manipulator*>(&o);
  j["physical"] = e.physical != nullptr;
  j["kind"] = e.manipulator ? "manipulator"
              : dynamic_cast<Gripper*>(&o) ? "gripper"
              : e.physical                 ? "physical"
                                           : "functional";
  ErrorStatus err = o.getErrorStatus();
  j["error"] = {{"code", err.code}, {"message", err.message}};
  json commands = json::array();
  for (const CommandInfo& c : o.getCommands()) commands.push_back({{"name", c.name}, {"description", c.description}});
  j["commands"] = commands;

  ControlPanel panel = o.getControlPanel();
  json fields = json::array();
  ControlProgram* program = e.program;
  for (const ControlPanelField& f : panel.fields) {
    json jf = {{"name", f.name},       {"label", f.label},       {"kind", fieldKindName(f.kind)},
               {"size", f.size},       {"unit", f.unit},         {"min", f.min},
               {"max", f.max},         {"tunable", f.tunable},   {"stateIndex", f.stateIndex},
               {"choices", f.choices}};
    if (f.tunable && program) {
      try {
        jf["value"] = program->getParameter(f.name);
      } catch (const std::exception&) {
        // a panel field that is not a parameter of the program: shown without a value
      }
    }
    if (f.name == "errorCode") jf["value"] = std::vector<double>{static_cast<double>(err.code)};
    fields.push_back(std::move(jf));
  }
  j["panel"] = {{"title", panel.title}, {"fields", fields}};
  if (program) {
    json logs = json::array();
    for (const LogVariableInfo& v : program->getLogVariables()) logs.push_back({{"name", v.name}, {"size", v.size}, {"unit", v.unit}});
    j["logVariables"] = logs;
    j["rate"] = program->getRate();
  }

  e.frames.clear();
  if (e.physical) {
    Model3D m = e.physical->get3DModel();
    // A UrdfManipulator (loadVisuals() checks) is drawn with its URDF visuals.
    if (e.manipulator && !e.urdfLoaded) loadVisuals(e);
    const bool urdf = e.manipulator && !e.urdfVisuals.empty();
    if (urdf) {
      m.shapes.clear();  // the URDF's own look instead of the generic links
      for (const UrdfVisual& v : e.urdfVisuals) m.shapes.push_back(v.shape);
      j["urdfVisuals"] = true;
    } else if (m.linksDrawn) {
      j["linksDrawn"] = true;  // the object's shapes draw its links (no generic links between frames)
    }
    if (!e.urdfError.empty()) j["urdfError"] = e.urdfError;
    e.frames = m.frames;
    json shapes = json::array();
    e.meshes.clear();
    for (const Shape& s : m.shapes) {
      e.meshes.push_back(s.kind == ShapeKind::Mesh ? s.meshFile : std::string());
      shapes.push_back(shapeJson(s));
    }
    if (urdf) {
      // Each visual's link, its mesh as the URDF names it, why it cannot be drawn, and the link's
      // collision shapes to draw instead (their meshes served as shapes after the visuals).
      for (std::size_t i = 0; i < e.urdfVisuals.size(); ++i) {
        const UrdfVisual& v = e.urdfVisuals[i];
        json& js = shapes[i];
        js["link"] = v.link;
        if (v.shape.kind == ShapeKind::Mesh) {
          js["mesh"] = v.shape.meshFile.empty() ? v.meshUri : v.shape.meshFile;
          js["uri"] = v.meshUri;
          if (!v.meshError.empty()) js["meshError"] = v.meshError;
        }
        if (!v.textureUri.empty()) {
          json texture = {{"uri", v.textureUri}};
          if (!v.textureError.empty()) {
            texture["error"] = v.textureError;
          } else {
            texture["meshShape"] = e.meshes.size();  // served as the meshes are
            e.meshes.push_back(v.textureFile);
          }
          js["texture"] = std::move(texture);
        }
        json fallback = json::array();
        for (const Shape& c : v.collision) {
          json jc = shapeJson(c);
          jc["color"] = js["color"];
          if (c.kind == ShapeKind::Mesh) {
            jc["meshShape"] = e.meshes.size();
            e.meshes.push_back(c.meshFile);
          }
          fallback.push_back(std::move(jc));
        }
        js["fallback"] = std::move(fallback);
      }
    }
    j["frames"] = m.frames;
    j["shapes"] = shapes;
    j["display"] = displayName(e.physical->getDisplayMode());
    if (PhysicalObject* mount = e.physical->getConnection())
      j["connection"] = {{"object", mount->getName()}, {"frame", e.physical->getConnectionFrame()}};
    else
      j["connection"] = nullptr;
  }
  if (e.manipulator) {
    const ManipulatorModel& model = e.manipulator->getModel();
    if (!e.data) e.data = std::make_unique<ManipulatorData>(model);
    j["joints"] = model.getNumberOfJoints();
    json names = json::array();  // a URDF arm's own joint names; joint1, joint2, ... otherwise
    for (int i = 0; i < model.getNumberOfJoints(); ++i) names.push_back(model.getJointName(i));
    j["jointNames"] = names;
    json prismatic = json::array();  // the panels show revolute joints in degrees, prismatic ones in mm
    for (int i = 0; i < model.getNumberOfJoints(); ++i) prismatic.push_back(model.isPrismatic(i));
    j["prismatic"] = prismatic;
    j["qmin"] = vectorJson(model.getPositionMin());
    j["qmax"] = vectorJson(model.getPositionMax());
    j["vmax"] = vectorJson(model.getVelocityLimit());
    j["home"] = vectorJson(model.getHomePosition());
    j["servoRate"] = 1.0 / e.manipulator->getServoPeriod();
    if (const auto* arm = dynamic_cast<const DefaultManipulator*>(e.manipulator)) {
      // The panel's servo-control switch: the controls offered, the one in use.
      j["servoControls"] = arm->getServoControlNames();
      j["servoControl"] = arm->getServoControlName();
    }
  }
  return j;
}

bool SceneState::refresh() {
  ObjectManager om;
  // The names first: no reference is held while the registry's lock is taken (a thread that
  // withdraws an object never waits for references with that lock held, but this keeps it simple).
  const std::vector<std::string> names = om.getObjectNames();
  // References keep the published objects from being withdrawn (destroyed) while we read them.
  std::vector<ObjectReference> published = om.getPublishedObjects();
  std::map<std::string, RoboticObject*> byName;  // published objects
  for (const ObjectReference& r : published) byName[r->getName()] = r.get();
  std::map<std::string, PhysicalObjectView> unpublished;  // physical objects that do not publish themselves
  for (PhysicalObjectView& v : unpublishedPhysicalObjects()) unpublished.emplace(v.name, std::move(v));
  unpublishedIndex_.clear();
  json objects = json::array();
  std::set<RoboticObject*> present;
  for (auto& [object, e] : entries_) e.index = -1;  // set again below for the objects listed now
  // In creation order; only names are read of objects not published (being constructed, or of a
  // class that does not publish itself) or withdrawn (being destroyed): safe at any time.
  for (const std::string& name : names) {
    auto live = byName.find(name);
    if (live != byName.end()) {
      RoboticObject* o = live->second;
      present.insert(o);
      auto it = entries_.find(o);
      if (it == entries_.end() || it->second.name != name) {
        Entry e;  // new (or a new object at the address of a destroyed one)
        e.object = o;
        e.name = name;
        it = entries_.insert_or_assign(o, std::move(e)).first;
      }
      Entry& e = it->second;
      e.index = static_cast<int>(objects.size());
      e.description = describe(e);
      e.described = true;
      objects.push_back(e.description);
      continue;
    }
    Entry* last = nullptr;
    for (auto& [object, e] : entries_)
      if (e.name == name && e.described && !present.count(object)) last = &e;
    if (last) {
      objects.push_back(last->description);  // withdrawn: as last described, without state
      present.insert(last->object);
    } else if (const auto v = unpublished.find(name); v != unpublished.end()) {
      // A physical object of a class that does not publish itself: drawn from its
      // PhysicalObject part (PhysicalObject's own look, its pose and mount), no panel.
      objects.push_back(describeUnpublished(v->second, byName));
      unpublishedIndex_[name] = static_cast<int>(objects.size()) - 1;
    } else {
      objects.push_back(listedByName(name));
    }
  }
  for (auto it = entries_.begin(); it != entries_.end();)
    it = present.count(it->first) ? std::next(it) : entries_.erase(it);
  std::string dump = objects.dump();
  if (dump == lastObjects_ && !sceneMessage_.empty()) return false;
  lastObjects_ = std::move(dump);
  ++version_;
  json msg = {{"type", "scene"}, {"protocol", kSceneViewerProtocolVersion}, {"version", version_}, {"objects", objects}};
  sceneMessage_ = msg.dump();
  return true;
}

std::string SceneState::meshFile(const std::string& name, std::size_t shape) const {
  for (const auto& [object, e] : entries_)
    if (e.described && e.name == name) return shape < e.meshes.size() ? e.meshes[shape] : std::string();
  return {};
}

std::string SceneState::buildFrame() {
  // Layout (little-endian): u32 magic "RPS1", u32 protocol, u32 scene version, u32 object count,
  // f64 time; per object: u32 index into the scene's objects, u32 frame count F, u32 value count V,
  // u32 error code, F x 16 f64 world poses (column-major 4x4), V x f64 state values.
  std::string out;
  out.reserve(1024);
  put32(out, kStateFrameMagic);
  put32(out, static_cast<std::uint32_t>(kSceneViewerProtocolVersion));
  put32(out, version_);
  const std::size_t countAt = out.size();
  put32(out, 0);
  const std::size_t timeAt = out.size();
  putDouble(out, 0);
  std::uint32_t count = 0;
  double time = 0;

  // References keep every object read here (and the mounts looked up) from being destroyed.
  std::vector<ObjectReference> published = ObjectManager().getPublishedObjects();
  std::set<const RoboticObject*> live;
  for (const ObjectReference& r : published) live.insert(r.get());
  for (const ObjectReference& r : published) {
    RoboticObject& o = *r;
    auto it = entries_.find(&o);
    if (it == entries_.end() || !it->second.described || it->second.index < 0) continue;
    Entry& e = it->second;
    StateSnapshot snap;
    const bool hasState = o.getStateSnapshot(snap);
    if (hasState) time = std::max(time, snap.time);
    std::vector<Transform> poses(e.frames.size(), Transform::unit());
    if (e.manipulator && e.data) {
      const ManipulatorModel& model = e.manipulator->getModel();
      // The poses and the values of one frame come from one servo cycle: the snapshot's joint
      // positions, not a second read (a moving arm's picture and values would be cycles apart).
      const int n = model.getNumberOfJoints();
      internal::ArmCycleState cycle;
      const JointVector q = hasState && internal::armCycleState(*e.manipulator, snap, n, cycle)
                                ? cycle.q
                                : e.manipulator->getJointPosition();
      if (q.size() == n) {
        forwardKinematics(model, *e.data, q);
        for (std::size_t f = 0; f < e.frames.size(); ++f) {
          const std::string& name = e.frames[f];
          if (name == "base") {
            poses[f] = model.getBaseTransform();
          } else if (name == "endEffector") {
            poses[f] = e.data->endEffector;
          } else if (name.rfind("link", 0) == 0) {
            int k = std::atoi(name.c_str() + 4);
            if (k >= 1 && k <= model.getNumberOfJoints()) poses[f] = e.data->linkTransforms[static_cast<std::size_t>(k - 1)];
          } else if (name.rfind("chain", 0) == 0 && e.data->chain) {
            // A link of a chain with mimic joints (those the mimic joints move included).
            int k = std::atoi(name.c_str() + 5);
            if (k >= 1 && k <= e.data->chain->n) poses[f] = e.data->chain->linkTransforms[static_cast<std::size_t>(k - 1)];
          }
        }
      }
    } else if (e.physical) {
      const Transform world = mountedPose(e.physical->getTransform(), e.physical->getConnection(),
                                          e.physical->getConnectionFrame(), live);
      for (auto& p : poses) p = world;
    }
    put32(out, static_cast<std::uint32_t>(e.index));
    put32(out, static_cast<std::uint32_t>(poses.size()));
    const int values = hasState ? std::clamp(snap.size, 0, kMaxStateValues) : 0;
    put32(out, static_cast<std::uint32_t>(values));
    put32(out, static_cast<std::uint32_t>(o.getErrorCode()));
    for (const Transform& p : poses) putTransform(out, p);
    for (int i = 0; i < values; ++i) putDouble(out, snap.values[i]);
    ++count;
  }
  // Physical objects of classes that do not publish themselves: their base frame.
  for (const PhysicalObjectView& v : unpublishedPhysicalObjects()) {
    const auto it = unpublishedIndex_.find(v.name);
    if (it == unpublishedIndex_.end()) continue;  // not in the scene yet
    put32(out, static_cast<std::uint32_t>(it->second));
    put32(out, 1);  // one frame
    put32(out, 0);  // no state values
    put32(out, 0);  // no error
    putTransform(out, mountedPose(v.transform, const_cast<PhysicalObject*>(v.mount), v.mountFrame, live));
    ++count;
  }
  for (int i = 0; i < 4; ++i) out[countAt + static_cast<std::size_t>(i)] = static_cast<char>((count >> (8 * i)) & 0xffu);
  std::string t;
  putDouble(t, time);
  out.replace(timeAt, 8, t);
  return out;
}

Transform SceneState::mountedPose(Transform world, PhysicalObject* mount, std::string frame,
                                  const std::set<const RoboticObject*>& live) {
  // World pose through the chain of connections (bounded: a cycle cannot hang us).
  for (int depth = 0; depth < 16; ++depth) {
    if (!mount || !live.count(mount)) break;  // a mount not published is not read
    auto* m = dynamic_cast<Manipulator*>(mount);
    if (m == nullptr) {
      world = mount->getTransform() * world;
      frame = mount->getConnectionFrame();
      mount = mount->getConnection();
      continue;
    }
    // A manipulator's frames are in the world already.
    Transform at = m->getModel().getBaseTransform();
    auto mi = entries_.find(mount);
    if (frame != "base" && mi != entries_.end() && mi->second.data) {
      const ManipulatorModel& model = m->getModel();
      JointVector q = m->getJointPosition();
      if (q.size() == model.getNumberOfJoints()) {
        forwardKinematics(model, *mi->second.data, q);
        if (frame == "endEffector") {
          at = mi->second.data->endEffector;
        } else if (frame.rfind("link", 0) == 0) {
          const int k = std::atoi(frame.c_str() + 4);
          if (k >= 1 && k <= model.getNumberOfJoints()) at = mi->second.data->linkTransforms[static_cast<std::size_t>(k - 1)];
        }
      }
    }
    return at * world;
  }
  return world;
}

json SceneState::describeUnpublished(const PhysicalObjectView& v, const std::map<std::string, RoboticObject*>& published) {
  json shapes = json::array();
  for (const Shape& s : v.model.shapes) shapes.push_back(shapeJson(s));
  std::string mount = v.mountName;
  for (const auto& [name, object] : published)
    if (v.mount != nullptr && object == static_cast<const RoboticObject*>(v.mount)) mount = name;
  json j = listedByName(v.name);
  j["kind"] = "physical";
  j["physical"] = true;
  j["frames"] = json::array({"base"});
  j["shapes"] = shapes;
  j["display"] = displayName(v.display);
  j["connection"] = mount.empty() ? json(nullptr) : json{{"object", mount}, {"frame", v.mountFrame}};
  return j;
}

}  // namespace rp::internal
