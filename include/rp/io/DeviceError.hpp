#pragma once
/// @file
/// A fixed-size record of a device's last error: status code and message, without heap use.

#include <array>

#include "rp/io/IoStatus.hpp"

namespace rp {

/// The last error of an I/O board or device driver: a status code and a message of at most
/// 255 characters kept in a fixed buffer, so that recording an error in a servo loop does not
/// allocate.
class DeviceError {
 public:
  /// Records an error and returns its status, so a driver can write `return error_.set(...)`.
  /// @param[in] status  the status to record (`IoStatus::kOk` clears the record)
  /// @param[in] format  printf-style format of the message, then its arguments
  /// @return `status`
  /// Real-time safe: yes (formats into a fixed buffer; use only `%s`, `%d`, `%u`, `%ld`, `%g`-style conversions).
  [[gnu::format(printf, 3, 4)]] IoStatus set(IoStatus status, const char* format, ...) noexcept;

  /// Clears the record (status `kOk`, empty message).
  /// Real-time safe: yes.
  void clear() noexcept {
    status_ = IoStatus::kOk;
    message_[0] = '\0';
  }

  /// Status of the last recorded error (`IoStatus::kOk` if none).
  /// Real-time safe: yes.
  IoStatus status() const noexcept { return status_; }

  /// Message of the last recorded error (empty if none); valid until the next `set()`.
  /// Real-time safe: yes.
  const char* message() const noexcept { return message_.data(); }

 private:
  IoStatus status_ = IoStatus::kOk;
  std::array<char, 256> message_{};
};

}  // namespace rp
