#include "rp/effector/ToolChanger.hpp"

#include <string>

namespace rp {

ToolChanger::ToolChanger(const std::string& name) : PhysicalObject(name) {
  // A command the device did not carry out says why (the error status its driver set).
  addCommandWithResult("Lock", [this] { return commandResult(lock(), "locked"); }, "lock the tool");
  addCommandWithResult("Unlock", [this] { return commandResult(unlock(), "unlocked"); }, "release the tool");
  addCommandWithResult("Relax", [this] { return commandResult(relax(), "relaxed"); }, "switch both actuators off");
}

ToolChanger::~ToolChanger() = default;

const char* ToolChanger::stateName(State state) noexcept {
  switch (state) {
    case State::Unknown: return "unknown";
    case State::Locked: return "locked";
    case State::Unlocked: return "unlocked";
    case State::Relaxed: return "relaxed";
  }
  return "unknown";
}

bool ToolChanger::apply(State target, bool (ToolChanger::*hardware)()) {
  if (!isSimulationModeOn() && !(this->*hardware)()) return false;
  state_.store(target);
  clearError();
  return true;
}

bool ToolChanger::lock() { return apply(State::Locked, &ToolChanger::hardwareLock); }
bool ToolChanger::unlock() { return apply(State::Unlocked, &ToolChanger::hardwareUnlock); }
bool ToolChanger::relax() { return apply(State::Relaxed, &ToolChanger::hardwareRelax); }

ControlPanel ToolChanger::getControlPanel() const {
  ControlPanel panel = PhysicalObject::getControlPanel();
  ControlPanelField state;
  state.name = "state";
  state.label = "State";
  state.kind = FieldKind::Choice;
  state.choices = {"unknown", "locked", "unlocked", "relaxed"};
  state.stateIndex = 0;
  panel.fields.push_back(state);
  return panel;
}

bool ToolChanger::getStateSnapshot(StateSnapshot& snapshot) const {
  snapshot.size = 1;
  snapshot.values[0] = static_cast<double>(static_cast<int>(getState()));
  return true;
}

bool ToolChanger::handleMessage(const std::string& type, const std::string& payload, std::string& reply) {
  if (type != "read") return PhysicalObject::handleMessage(type, payload, reply);
  reply = std::string("{\"state\": \"") + stateName(getState()) + "\", \"simulation\": " +
          (isSimulationModeOn() ? "true" : "false") + "}";
  return true;
}

}  // namespace rp
