#include "rp/effector/Gripper.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <mutex>
#include <sstream>
#include <string>

#include "rp/core/ObjectManager.hpp"
#include "rp/core/TypeDatabase.hpp"
#include "rp/effector/WorkPiece.hpp"
#include "rp/manipulator/DefaultManipulator.hpp"
#include "rp/math/Transform.hpp"

namespace rp {

namespace {
Vector<3> point(double x, double y, double z) {
  Vector<3> v;
  v << x, y, z;
  return v;
}

// A length setting of the gripper: checked, then set under the gripper's lock.
void setLength(std::mutex& mutex, double& field, double meters, bool zeroAllowed, const std::string& what) {
  if (!std::isfinite(meters) || meters < 0 || (!zeroAllowed && meters == 0))
    throw std::invalid_argument(what + (zeroAllowed ? " must be finite and not negative" : " must be positive and finite"));
  std::lock_guard lock(mutex);
  field = meters;
}
}  // namespace

struct Gripper::Impl {
  mutable std::mutex mutex;
  double graspRange = 0.05;                 // [m]
  Vector<3> toolPoint = point(0, 0, 0.1);  // [m]
  double opening = 0.08;                    // [m]
  double graspTolerance = 0.01;             // [m]
  std::vector<std::string> graspableNames;  // from rp.cfg, resolved when closing
  std::vector<PhysicalObject*> graspable;   // added in code
  std::vector<PhysicalObject*> grasped;
};

Gripper::Gripper(const std::string& name) : PhysicalObject(name), impl_(std::make_unique<Impl>()) {
  if (const ConfigSection* section = configSection()) {
    if (const ConfigSetting* s = section->find("graspRange")) {
      const double mm = section->getNumbers("graspRange").at(0);
      if (mm < 0) throw section->errorAt(*s, "setting 'graspRange' must not be negative");
      impl_->graspRange = mm / 1000.0;
    }
    if (const ConfigSetting* s = section->find("graspable")) impl_->graspableNames = s->values;
    if (section->has("toolPoint")) {
      const std::vector<double> mm = section->getNumbers("toolPoint");
      impl_->toolPoint = point(mm.at(0), mm.at(1), mm.at(2)) / 1000.0;
    }
    if (const ConfigSetting* s = section->find("opening")) {
      const double mm = section->getNumbers("opening").at(0);
      if (!(mm > 0)) throw section->errorAt(*s, "setting 'opening' must be positive");
      impl_->opening = mm / 1000.0;
    }
    if (const ConfigSetting* s = section->find("graspTolerance")) {
      const double mm = section->getNumbers("graspTolerance").at(0);
      if (mm < 0) throw section->errorAt(*s, "setting 'graspTolerance' must not be negative");
      impl_->graspTolerance = mm / 1000.0;
    }
  }
  // A command the device did not carry out says why (the error status its driver set).
  addCommandWithResult("Open", [this] { return commandResult(open(), "open"); }, "open the gripper");
  addCommandWithResult("Close", [this] { return commandResult(close(), "closed"); }, "close the gripper");
  addCommandWithResult("Relax", [this] { return commandResult(relax(), "relaxed"); }, "relax the gripper (no force)");
}

Gripper::~Gripper() = default;

void Gripper::declareSettings(SettingSchema& schema) {
  PhysicalObject::declareSettings(schema);
  schema.addNumbers("graspRange", 1, "mm", "how close a graspable object must be (simulation)", 0,
                    std::numeric_limits<double>::max());
  schema.addWords("graspable", 1, 64, "names of the objects the simulated gripper can pick up");
  schema.addNumbers("toolPoint", 3, "mm", "the point midway between the fingertips, in the gripper's frame");
  schema.addNumbers("opening", 1, "mm", "distance between the open fingers (the widest work piece held)", 0,
                    std::numeric_limits<double>::max());
  schema.addNumbers("graspTolerance", 1, "mm", "how far a work piece's centre may be from the tool point (simulation)",
                    0, std::numeric_limits<double>::max());
  schema.setDefault("graspRange", "50");
  schema.setDefault("graspable", "(none: only objects added in code; work pieces are always)");
  schema.setDefault("toolPoint", "0 0 100");
  schema.setDefault("opening", "80");
  schema.setDefault("graspTolerance", "10");
}

const char* Gripper::stateName(State state) noexcept {
  switch (state) {
    case State::Unknown: return "unknown";
    case State::Open: return "open";
    case State::Closed: return "closed";
    case State::Relaxed: return "relaxed";
  }
  return "unknown";
}

bool Gripper::open() {
  if (!isSimulationModeOn() && !hardwareOpen()) return false;
  if (isSimulationModeOn()) releaseInSimulation();
  state_.store(State::Open);
  clearError();
  return true;
}

bool Gripper::close() {
  if (!isSimulationModeOn() && !hardwareClose()) return false;
  if (isSimulationModeOn()) graspInSimulation();
  state_.store(State::Closed);
  clearError();
  return true;
}

bool Gripper::relax() {
  if (!isSimulationModeOn() && !hardwareRelax()) return false;
  if (isSimulationModeOn()) releaseInSimulation();
  state_.store(State::Relaxed);
  clearError();
  return true;
}

Transform Gripper::worldTransform(const PhysicalObject& object) { return object.getWorldTransform(); }

void Gripper::setToolPoint(const Vector<3>& point) {
  if (!point.allFinite()) throw std::invalid_argument(getName() + ": the tool point must be finite");
  std::lock_guard lock(impl_->mutex);
  impl_->toolPoint = point;
}

Vector<3> Gripper::getToolPoint() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->toolPoint;
}

Transform Gripper::getToolTransform() const { return Transform(getWorldTransform() * translation(getToolPoint())); }

void Gripper::setOpening(double meters) {
  setLength(impl_->mutex, impl_->opening, meters, false, getName() + ": the opening");
}

double Gripper::getOpening() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->opening;
}

void Gripper::setGraspTolerance(double meters) {
  setLength(impl_->mutex, impl_->graspTolerance, meters, true, getName() + ": the grasp tolerance");
}

double Gripper::getGraspTolerance() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->graspTolerance;
}

bool Gripper::fingersAround(const WorkPiece& piece) const {
  const Transform tool = getToolTransform();
  const Transform world = piece.getWorldTransform();
  const Vector<3> size = piece.getSize();
  // The piece's extent along the gripper's closing axis (x): its box projected onto that axis.
  const Eigen::Vector3d across = tool.topLeftCorner<3, 3>().col(0);
  double width = 0;
  for (int i = 0; i < 3; ++i) width += std::abs(across.dot(world.topLeftCorner<3, 3>().col(i))) * size(i);
  const double offset = (getPosition(world) - getPosition(tool)).norm();
  std::lock_guard lock(impl_->mutex);
  return offset <= impl_->graspTolerance && width <= impl_->opening;
}

void Gripper::addGraspable(PhysicalObject& object) {
  std::lock_guard lock(impl_->mutex);
  if (std::find(impl_->graspable.begin(), impl_->graspable.end(), &object) == impl_->graspable.end())
    impl_->graspable.push_back(&object);
}

void Gripper::removeGraspable(PhysicalObject& object) {
  std::lock_guard lock(impl_->mutex);
  std::erase(impl_->graspable, &object);
  if (std::find(impl_->grasped.begin(), impl_->grasped.end(), &object) != impl_->grasped.end()) {
    const Transform world = object.getWorldTransform();
    object.clearConnection();
    object.setTransform(world);
    std::erase(impl_->grasped, &object);
  }
}

void Gripper::setGraspRange(double meters) {
  std::lock_guard lock(impl_->mutex);
  impl_->graspRange = std::max(0.0, meters);
}

std::vector<PhysicalObject*> Gripper::getGraspedObjects() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->grasped;
}

void Gripper::graspInSimulation() {
  std::vector<PhysicalObject*> candidates;
  double range = 0;
  {
    std::lock_guard lock(impl_->mutex);
    candidates = impl_->graspable;
    range = impl_->graspRange;
  }
  ObjectManager om;
  for (const std::string& n : impl_->graspableNames)
    if (auto* o = om.findObject<PhysicalObject>(n)) candidates.push_back(o);
  for (WorkPiece* piece : om.getDerivedObjects<WorkPiece>()) candidates.push_back(piece);
  const Transform self = getWorldTransform();
  std::vector<PhysicalObject*> held;
  for (PhysicalObject* o : candidates) {
    if (o == this || std::find(held.begin(), held.end(), o) != held.end()) continue;
    {
      std::lock_guard lock(impl_->mutex);
      if (std::find(impl_->grasped.begin(), impl_->grasped.end(), o) != impl_->grasped.end()) continue;
    }
    if (auto* piece = dynamic_cast<WorkPiece*>(o)) {
      if (!fingersAround(*piece)) continue;
      piece->attachTo(*this);
    } else {
      const Transform world = o->getWorldTransform();
      if ((getPosition(world) - getPosition(self)).norm() > range) continue;
      o->setConnection(*this, "base");
      o->setTransform(rigidInverse(self) * world);  // stays where it is, now moving with the gripper
    }
    held.push_back(o);
  }
  {
    std::lock_guard lock(impl_->mutex);
    impl_->grasped.insert(impl_->grasped.end(), held.begin(), held.end());
  }
  updatePayload();
}

void Gripper::releaseInSimulation() {
  std::vector<PhysicalObject*> held;
  {
    std::lock_guard lock(impl_->mutex);
    held.swap(impl_->grasped);
  }
  for (PhysicalObject* o : held) {
    if (auto* piece = dynamic_cast<WorkPiece*>(o)) {
      piece->release();  // falls to its table
      continue;
    }
    const Transform world = o->getWorldTransform();
    o->clearConnection();
    o->setTransform(world);  // dropped where it is
  }
  updatePayload();
}

void Gripper::updatePayload() {
  // The arm the gripper is mounted on at its end-effector, directly or through other objects.
  DefaultManipulator* arm = nullptr;
  const PhysicalObject* child = this;
  PhysicalObject* mount = getConnection();
  for (int depth = 0; mount != nullptr && depth < 64; ++depth) {  // bounded: a cycle cannot hang us
    arm = dynamic_cast<DefaultManipulator*>(mount);
    if (arm != nullptr) {
      if (child->getConnectionFrame() != "endEffector") arm = nullptr;
      break;
    }
    child = mount;
    mount = mount->getConnection();
  }
  if (arm == nullptr) return;
  // The held pieces' total mass at their common centre of mass, in the end-effector frame.
  double mass = 0;
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  for (PhysicalObject* o : getGraspedObjects()) {
    if (auto* piece = dynamic_cast<WorkPiece*>(o)) {
      mass += piece->getMass();
      moment += piece->getMass() * Eigen::Vector3d(getPosition(piece->getWorldTransform()));
    }
  }
  Vector<3> centre = Vector<3>::Zero();
  if (mass > 0) centre = transformPoint(rigidInverse(arm->getFrameTransform("endEffector")), Vector<3>(moment / mass));
  arm->setPayload(mass, centre);
}

Model3D Gripper::get3DModel() const {
  const Vector<3> tool = getToolPoint();
  const double opening = getOpening();
  const double reach = std::max(tool(2), 0.04);  // the fingers' length, from the base to the tool point
  Model3D m;
  Shape palm;
  palm.size = point(opening + 0.04, 0.04, 0.03);
  palm.pose = translation(tool(0), tool(1), 0.015);
  palm.color = Color{0.35, 0.35, 0.4, 1.0};
  m.shapes.push_back(palm);
  for (const double side : {-1.0, 1.0}) {
    Shape finger;
    finger.size = point(0.01, 0.02, reach - 0.02);
    finger.pose = translation(tool(0) + side * (opening / 2 + 0.005), tool(1), 0.02 + (reach - 0.02) / 2);
    finger.color = palm.color;
    m.shapes.push_back(finger);
  }
  return m;
}

ControlPanel Gripper::getControlPanel() const {
  ControlPanel panel = PhysicalObject::getControlPanel();
  ControlPanelField state;
  state.name = "state";
  state.label = "State";
  state.kind = FieldKind::Choice;
  state.choices = {"unknown", "open", "closed", "relaxed"};
  state.stateIndex = 0;
  panel.fields.push_back(state);
  ControlPanelField grasped;
  grasped.name = "grasped";
  grasped.label = "Objects held";
  grasped.kind = FieldKind::Number;
  grasped.stateIndex = 1;
  panel.fields.push_back(grasped);
  return panel;
}

bool Gripper::getStateSnapshot(StateSnapshot& snapshot) const {
  snapshot.size = 2;
  snapshot.values[0] = static_cast<double>(static_cast<int>(getState()));
  snapshot.values[1] = static_cast<double>(getGraspedObjects().size());
  return true;
}

bool Gripper::handleMessage(const std::string& type, const std::string& payload, std::string& reply) {
  if (type != "read") return PhysicalObject::handleMessage(type, payload, reply);
  std::ostringstream out;
  out << "{\"state\": \"" << stateName(getState()) << "\", \"simulation\": "
      << (isSimulationModeOn() ? "true" : "false") << ", \"grasped\": [";
  const auto held = getGraspedObjects();
  for (std::size_t i = 0; i < held.size(); ++i) out << (i ? ", " : "") << '"' << held[i]->getName() << '"';
  out << "]}";
  reply = out.str();
  return true;
}

}  // namespace rp
