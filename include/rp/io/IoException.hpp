#pragma once
/// @file
/// The exception thrown when an I/O board or device driver is set up with invalid settings.

#include <stdexcept>
#include <string>

namespace rp {

/// Error in the set-up (not the cyclic use) of an I/O board or device driver: an invalid
/// line mapping, an impossible setting, a shared-memory segment that does not exist, and so on.
/// The message names the setting that was wrong. Cyclic operations never throw; they return
/// an `IoStatus`.
class IoException : public std::runtime_error {
 public:
  /// Creates the exception with a message that says what was wrong.
  /// @param[in] what  human-readable description of the error
  explicit IoException(const std::string& what) : std::runtime_error(what) {}
};

}  // namespace rp
