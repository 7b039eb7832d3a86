#include "rp/effector/DefaultToolChanger.hpp"

#include <string>

#include "BoardSettings.hpp"
#include "rp/core/TypeDatabase.hpp"

namespace rp {

DefaultToolChanger::DefaultToolChanger(const std::string& name)
    : ToolChanger(ClassSection(name, "DefaultToolChanger")) {
  const ConfigSection* section = configSection();
  if (section == nullptr) {
    publishObject();  // complete: other threads (the Scene Viewer) may use it
    return;
  }
  internal::TwoLineBoard b = internal::createTwoLineBoard(*section, "lockLine", "unlockLine");
  ownedBoard_ = std::move(b.board);
  board_ = ownedBoard_.get();
  lockLine_ = b.lineA;
  unlockLine_ = b.lineB;
  if (!b.deviceError.empty()) setError(1, (getName() + ": " + b.deviceError).c_str());
  publishObject();  // complete: other threads (the Scene Viewer) may use it
}

DefaultToolChanger::~DefaultToolChanger() { withdrawObject(); }  // first: other threads keep off from here on

void DefaultToolChanger::declareSettings(SettingSchema& schema) {
  ToolChanger::declareSettings(schema);
  internal::declareTwoLineBoardSettings(schema, "lockLine", "unlockLine");
}

void DefaultToolChanger::setIoBoard(IoBoard& board, int lockLine, int unlockLine) {
  ownedBoard_.reset();
  board_ = &board;
  lockLine_ = lockLine;
  unlockLine_ = unlockLine;
}

bool DefaultToolChanger::drive(bool lockOn, bool unlockOn) {
  if (board_ == nullptr) {
    if (getErrorCode() == 0) setError(1, (getName() + ": no I/O board configured (rp.cfg setting 'board')").c_str());
    return false;
  }
  std::string error;
  if (!internal::driveTwoLines(*board_, lockLine_, lockOn, unlockLine_, unlockOn, error)) {
    setError(1, (getName() + ": " + error).c_str());
    return false;
  }
  return true;
}

bool DefaultToolChanger::hardwareLock() { return drive(true, false); }
bool DefaultToolChanger::hardwareUnlock() { return drive(false, true); }
bool DefaultToolChanger::hardwareRelax() { return drive(false, false); }

}  // namespace rp

RP_REGISTER_CLASS_AS(rp::DefaultToolChanger, "DefaultToolChanger");
