// QMotor's requests from the page (docs/gui.md, "QMotor"): start, stop and restart an object's
// control program, save and load its control-program files, and QMotor's log (variables,
// decimation, trigger, CSV). The Scene Viewer checks each message with parseQMotorRequest() on
// its server thread (after the token, Host and Origin checks of the WebSocket) and runs it with
// runQMotorRequest() in its worker thread.
#pragma once

#include <nlohmann/json.hpp>

#include <cstddef>
#include <filesystem>
#include <string>

#include "rp/rt/ControlProgram.hpp"

namespace rp {

class RoboticObject;

namespace internal {

/// A checked QMotor request.
struct QMotorRequest {
  std::string action;       ///< status, start, stop, restart, save, load, capture, clearCapture, csv
  std::string file;         ///< save (optional) and load: a file name in the object's control-program folder
  LogCaptureSettings capture;  ///< capture
};

/// Longest file name a page may give.
constexpr std::size_t kMaxQMotorFileName = 128;
/// Most variables a page may choose for QMotor's log.
constexpr std::size_t kMaxQMotorLogVariables = 64;
/// Most control-program files listed in the status.
constexpr std::size_t kMaxQMotorFilesListed = 200;

/// Checks every field of a `qmotor` message (`action` and what the action needs) without touching
/// any object.
/// @param[in] msg  the message
/// @return the checked request
/// @throws std::invalid_argument naming the field that is missing, of the wrong type or out of range
QMotorRequest parseQMotorRequest(const nlohmann::json& msg);

/// Runs a checked request on `object`.
/// @param[in,out] object   a published object (held by the caller)
/// @param[in] request      from parseQMotorRequest()
/// @return the reply for the page (JSON text: `message` and the program's `status`, or `csv`)
/// @throws std::exception saying why it was refused (a file error names FILE:LINE)
std::string runQMotorRequest(RoboticObject& object, const QMotorRequest& request);

/// The file `name` in `folder`, where QMotor may save and load control-program files: `name` is
/// a plain file name ending in `.cfg` (letters, digits, `.`, `_`, `-`; not starting with `.`), so
/// no other folder is reachable, and an existing file of that name must be a regular file (not a
/// link).
/// @param[in] folder  the object's control-program folder (RoboticObject::getQMotorConfigFolder())
/// @param[in] name    the name the page gave
/// @return the path
/// @throws std::invalid_argument naming the field `file` otherwise
std::filesystem::path qmotorFileIn(const std::string& folder, const std::string& name);

}  // namespace internal
}  // namespace rp
