#include "rp/effector/DefaultGripper.hpp"

#include <string>

#include "BoardSettings.hpp"
#include "rp/core/TypeDatabase.hpp"

namespace rp {

DefaultGripper::DefaultGripper(const std::string& name) : Gripper(ClassSection(name, "DefaultGripper")) {
  const ConfigSection* section = configSection();
  if (section == nullptr) {
    publishObject();  // complete: other threads (the Scene Viewer) may use it
    return;
  }
  internal::TwoLineBoard b = internal::createTwoLineBoard(*section, "openLine", "closeLine");
  ownedBoard_ = std::move(b.board);
  board_ = ownedBoard_.get();
  openLine_ = b.lineA;
  closeLine_ = b.lineB;
  if (!b.deviceError.empty()) setError(1, (getName() + ": " + b.deviceError).c_str());
  publishObject();  // complete: other threads (the Scene Viewer) may use it
}

DefaultGripper::~DefaultGripper() { withdrawObject(); }  // first: other threads keep off from here on

void DefaultGripper::declareSettings(SettingSchema& schema) {
  Gripper::declareSettings(schema);
  internal::declareTwoLineBoardSettings(schema, "openLine", "closeLine");
}

void DefaultGripper::setIoBoard(IoBoard& board, int openLine, int closeLine) {
  ownedBoard_.reset();
  board_ = &board;
  openLine_ = openLine;
  closeLine_ = closeLine;
}

bool DefaultGripper::drive(bool openOn, bool closeOn) {
  if (board_ == nullptr) {
    if (getErrorCode() == 0) setError(1, (getName() + ": no I/O board configured (rp.cfg setting 'board')").c_str());
    return false;
  }
  std::string error;
  if (!internal::driveTwoLines(*board_, openLine_, openOn, closeLine_, closeOn, error)) {
    setError(1, (getName() + ": " + error).c_str());
    return false;
  }
  return true;
}

bool DefaultGripper::hardwareOpen() { return drive(true, false); }
bool DefaultGripper::hardwareClose() { return drive(false, true); }
bool DefaultGripper::hardwareRelax() { return drive(false, false); }

}  // namespace rp

RP_REGISTER_CLASS_AS(rp::DefaultGripper, "DefaultGripper");
