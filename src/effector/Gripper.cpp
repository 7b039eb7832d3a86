#include "rp/effector/Gripper.hpp"

#include <algorithm>
#include <limits>
#include <mutex>
#include <sstream>
#include <string>

#include "rp/core/ObjectManager.hpp"
#include "rp/core/TypeDatabase.hpp"
#include "rp/math/Transform.hpp"

namespace rp {

struct Gripper::Impl {
  mutable std::mutex mutex;
  double graspRange = 0.05;                 // [m]
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
  SettingSpec graspable;
  graspable.name = "graspable";
  graspable.kind = SettingKind::Word;
  graspable.minValues = 1;
  graspable.maxValues = 64;
  graspable.description = "names of the objects the simulated gripper can pick up";
  schema.add(graspable);
  schema.setDefault("graspRange", "50");
  schema.setDefault("graspable", "(none: only objects added in code)");
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

Transform Gripper::worldTransform(const PhysicalObject& object) {
  Transform t = object.getTransform();
  const PhysicalObject* mount = object.getConnection();
  for (int depth = 0; mount != nullptr && depth < 64; ++depth) {  // bounded: a cycle cannot hang us
    t = mount->getTransform() * t;
    mount = mount->getConnection();
  }
  return t;
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
    const Transform world = worldTransform(object);
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
  {
    std::lock_guard lock(impl_->mutex);
    candidates = impl_->graspable;
  }
  ObjectManager om;
  for (const std::string& n : impl_->graspableNames)
    if (auto* o = om.findObject<PhysicalObject>(n)) candidates.push_back(o);
  const Transform self = worldTransform(*this);
  std::lock_guard lock(impl_->mutex);
  for (PhysicalObject* o : candidates) {
    if (o == this || std::find(impl_->grasped.begin(), impl_->grasped.end(), o) != impl_->grasped.end()) continue;
    const Transform world = worldTransform(*o);
    if ((getPosition(world) - getPosition(self)).norm() > impl_->graspRange) continue;
    o->setConnection(*this, "base");
    o->setTransform(rigidInverse(self) * world);  // stays where it is, now moving with the gripper
    impl_->grasped.push_back(o);
  }
}

void Gripper::releaseInSimulation() {
  std::lock_guard lock(impl_->mutex);
  for (PhysicalObject* o : impl_->grasped) {
    const Transform world = worldTransform(*o);
    o->clearConnection();
    o->setTransform(world);  // dropped where it is
  }
  impl_->grasped.clear();
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
