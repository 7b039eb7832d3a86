#pragma once
/// @file
/// The status code returned by every I/O board and device-driver operation.

namespace rp {

/// Result of an I/O board or device-driver operation (returned, never thrown, so that the
/// cyclic calls of a servo loop can use it).
///
/// The object that returned a status other than `kOk` also keeps a human-readable message,
/// for example `IoBoard::lastError()`.
enum class IoStatus {
  kOk,             ///< the operation succeeded
  kInvalidLine,    ///< a line, channel or encoder number outside the board's range
  kNotConnected,   ///< the device is absent or the connection is closed (refused, no such port, peer gone)
  kTimeout,        ///< the device did not answer within the configured time
  kProtocolError,  ///< the reply was garbled, truncated or otherwise did not follow the protocol
  kDeviceError,    ///< the device answered with an error of its own (for example a BarrettHand `ERR` reply)
  kDataLoss,       ///< data arrived, but some was lost or out of order (for example UDP records)
  kNotSupported,   ///< the board or device does not offer this operation
  kInvalidValue    ///< a value the operation cannot take (for example NaN volts); nothing was written
};

/// Name of a status code, for messages and logs, for example `"timeout"`.
/// @param[in] status  the status code
/// @return a static string (never null)
/// Real-time safe: yes.
constexpr const char* toString(IoStatus status) noexcept {
  switch (status) {
    case IoStatus::kOk: return "ok";
    case IoStatus::kInvalidLine: return "invalid line";
    case IoStatus::kNotConnected: return "not connected";
    case IoStatus::kTimeout: return "timeout";
    case IoStatus::kProtocolError: return "protocol error";
    case IoStatus::kDeviceError: return "device error";
    case IoStatus::kDataLoss: return "data loss";
    case IoStatus::kNotSupported: return "not supported";
    case IoStatus::kInvalidValue: return "invalid value";
  }
  return "unknown";
}

}  // namespace rp
