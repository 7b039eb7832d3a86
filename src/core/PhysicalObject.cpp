// PhysicalObject: pose, connection, simulation and display modes, default 3D model.
#include "rp/core/PhysicalObject.hpp"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <vector>
#include <stdexcept>

#include "PhysicalObjectViews.hpp"
#include "rp/core/RoboticPlatform.hpp"

namespace rp {

namespace {
constexpr int kMaxMountDepth = 64;  // longest chain of connections followed

// The PhysicalObjects whose PhysicalObject part is complete (internal::unpublishedPhysicalObjects()).
struct Constructed {
  std::mutex mutex;
  std::vector<const PhysicalObject*> objects;
};
Constructed& constructed() {
  static auto* c = new Constructed;  // never destroyed: objects may outlive static destruction
  return *c;
}
}  // namespace

namespace internal {
std::vector<PhysicalObjectView> unpublishedPhysicalObjects() {
  Constructed& c = constructed();
  std::lock_guard<std::mutex> lock(c.mutex);
  std::vector<PhysicalObjectView> views;
  for (const PhysicalObject* o : c.objects) {
    if (o->isObjectPublished()) continue;
    PhysicalObjectView v;
    v.name = o->getName();
    v.transform = o->getTransform();
    v.mount = o->getConnection();
    v.mountFrame = o->getConnectionFrame();
    v.display = o->getDisplayMode();
    v.model = o->PhysicalObject::get3DModel();
    // A mount in this list is alive while the lock is held (others are looked up by the caller).
    if (v.mount != nullptr && std::find(c.objects.begin(), c.objects.end(), v.mount) != c.objects.end())
      v.mountName = v.mount->getName();
    views.push_back(std::move(v));
  }
  return views;
}
}  // namespace internal

struct PhysicalObject::Impl {
  mutable std::mutex mutex;
  Transform transform = Transform::unit();
  PhysicalObject* connection = nullptr;
  std::string connectionFrame = "base";
  // -1: follow the platform; 0: off; 1: on.
  std::atomic<int> simulation{-1};
  std::atomic<int> display{static_cast<int>(DisplayMode::Solid)};
};

template <typename Undo>
void PhysicalObject::changed(const Undo& undo) {
  try {
    physicalSetupChanged();
  } catch (...) {
    undo();
    throw;
  }
}

PhysicalObject::PhysicalObject(const std::string& name) : RoboticObject(name), pimpl_(std::make_unique<Impl>()) {
  [&] {  // rp.cfg's settings
    const ConfigSection* section = configSection();
    if (!section) return;
    // rp.cfg units: position in millimetres, orientation (roll, pitch, yaw) in degrees.
    Vector<3> p;
    Vector<3> rpy;
    if (section->has("position")) {
      auto v = section->getNumbers("position");
      if (v.size() != 3) throw section->errorAt(*section->find("position"), "setting 'position' needs 3 values");
      p = v[0] / 1000.0, v[1] / 1000.0, v[2] / 1000.0;
    }
    if (section->has("orientation")) {
      auto v = section->getNumbers("orientation");
      if (v.size() != 3) throw section->errorAt(*section->find("orientation"), "setting 'orientation' needs 3 values");
      rpy = v[0] * M_PI / 180.0, v[1] * M_PI / 180.0, v[2] * M_PI / 180.0;
    }
    pimpl_->transform = translation(p) * rpyToTransform(rpy(0), rpy(1), rpy(2));
    if (section->has("simulationMode")) pimpl_->simulation = section->getWord("simulationMode") == "on" ? 1 : 0;
    if (section->has("display")) {
      std::string d = section->getWord("display");
      pimpl_->display = static_cast<int>(d == "off" ? DisplayMode::Off : d == "wireframe" ? DisplayMode::Wireframe
                                                                                            : DisplayMode::Solid);
    }
  }();
  // Complete as a PhysicalObject: the Scene Viewer may draw it from here, published or not.
  Constructed& c = constructed();
  std::lock_guard<std::mutex> lock(c.mutex);
  c.objects.push_back(this);
}

PhysicalObject::~PhysicalObject() {
  {
    Constructed& c = constructed();
    std::lock_guard<std::mutex> lock(c.mutex);
    c.objects.erase(std::remove(c.objects.begin(), c.objects.end(), this), c.objects.end());
  }
  withdrawObject();  // first thing for a plain PhysicalObject
}

void PhysicalObject::declareSettings(SettingSchema& schema) {
  RoboticObject::declareSettings(schema);
  // Within 1 km of the world origin; angles within one turn either way.
  schema.addNumbers("position", 3, "mm", "x y z", -1e6, 1e6);
  schema.addNumbers("orientation", 3, "deg", "roll pitch yaw", -360, 360);
  schema.addChoice("simulationMode", {"on", "off"}, "simulate instead of using the hardware");
  schema.addChoice("display", {"off", "solid", "wireframe"}, "how the Scene Viewer shows the object");
  schema.setDefault("position", "0 0 0");
  schema.setDefault("orientation", "0 0 0");
  schema.setDefault("simulationMode", "the -sim/-nosim switch");
  schema.setDefault("display", "solid");
}

Model3D PhysicalObject::get3DModel() const {
  Model3D model;
  Shape cube;
  cube.kind = ShapeKind::Box;
  cube.size = Vector<3>::Constant(0.1);
  model.shapes.push_back(cube);
  return model;
}

void PhysicalObject::setConnection(PhysicalObject& mount, const std::string& frame) {
  // No cycles: the mount must not be this object nor carried by it.
  const PhysicalObject* m = &mount;
  for (int depth = 0; m != nullptr && depth < kMaxMountDepth; ++depth, m = m->getConnection()) {
    if (m == this) {
      throw std::invalid_argument("'" + getName() + "' cannot be mounted on '" + mount.getName() +
                                  "': the connection would make a cycle");
    }
  }
  PhysicalObject* oldMount = nullptr;
  std::string oldFrame;
  {
    std::lock_guard<std::mutex> lock(pimpl_->mutex);
    oldMount = pimpl_->connection;
    oldFrame = pimpl_->connectionFrame;
    pimpl_->connection = &mount;
    pimpl_->connectionFrame = frame;
  }
  changed([&] {
    std::lock_guard<std::mutex> lock(pimpl_->mutex);
    pimpl_->connection = oldMount;
    pimpl_->connectionFrame = oldFrame;
  });
}

void PhysicalObject::clearConnection() {
  PhysicalObject* oldMount = nullptr;
  std::string oldFrame;
  {
    std::lock_guard<std::mutex> lock(pimpl_->mutex);
    oldMount = pimpl_->connection;
    oldFrame = pimpl_->connectionFrame;
    pimpl_->connection = nullptr;
    pimpl_->connectionFrame = "base";
  }
  if (oldMount == nullptr) return;
  changed([&] {
    std::lock_guard<std::mutex> lock(pimpl_->mutex);
    pimpl_->connection = oldMount;
    pimpl_->connectionFrame = oldFrame;
  });
}

PhysicalObject* PhysicalObject::getConnection() const {
  std::lock_guard<std::mutex> lock(pimpl_->mutex);
  return pimpl_->connection;
}

std::string PhysicalObject::getConnectionFrame() const {
  std::lock_guard<std::mutex> lock(pimpl_->mutex);
  return pimpl_->connectionFrame;
}

void PhysicalObject::setTransform(const Transform& t) {
  if (const std::string problem = rigidTransformError(t); !problem.empty())
    throw std::invalid_argument("setTransform of '" + getName() + "': the pose " + problem);
  Transform old;
  {
    std::lock_guard<std::mutex> lock(pimpl_->mutex);
    old = pimpl_->transform;
    pimpl_->transform = t;
  }
  changed([&] {
    std::lock_guard<std::mutex> lock(pimpl_->mutex);
    pimpl_->transform = old;
  });
}

Transform PhysicalObject::getTransform() const {
  std::lock_guard<std::mutex> lock(pimpl_->mutex);
  return pimpl_->transform;
}

Transform PhysicalObject::getWorldTransform() const {
  PhysicalObject* mount = nullptr;
  std::string frame;
  Transform own;
  {
    std::lock_guard<std::mutex> lock(pimpl_->mutex);
    mount = pimpl_->connection;
    frame = pimpl_->connectionFrame;
    own = pimpl_->transform;
  }
  if (mount == nullptr) return own;
  return Transform(mount->getFrameTransform(frame) * own);
}

Transform PhysicalObject::getFrameTransform(const std::string& frame) const {
  if (frame != "base") throw std::invalid_argument("'" + getName() + "' has no frame '" + frame + "'");
  return getWorldTransform();
}

void PhysicalObject::setSimulationModeOn() {
  const int old = pimpl_->simulation.exchange(1);
  changed([&] { pimpl_->simulation = old; });
}

void PhysicalObject::setSimulationModeOff() {
  const int old = pimpl_->simulation.exchange(0);
  changed([&] { pimpl_->simulation = old; });
}


bool PhysicalObject::isSimulationModeOn() const {
  if (RoboticPlatform::isSimulationModeForced()) return true;
  const int own = pimpl_->simulation.load();
  return own < 0 ? RoboticPlatform::isSimulationModeOn() : own == 1;
}

void PhysicalObject::setDisplayMode(DisplayMode mode) { pimpl_->display = static_cast<int>(mode); }
DisplayMode PhysicalObject::getDisplayMode() const { return static_cast<DisplayMode>(pimpl_->display.load()); }

}  // namespace rp
