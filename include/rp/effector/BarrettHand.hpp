#pragma once
/// @file
/// The BarrettHand three-finger gripper over its serial command protocol (paper section 3.4).

#include <array>
#include <memory>
#include <string>

#include "rp/effector/Gripper.hpp"
#include "rp/io/BarrettHandSerial.hpp"

namespace rp {

/// The BarrettHand (paper section 3.4, reference [16]) on a serial port: 9600 baud 8N1, the
/// supervisory command protocol of `BarrettHandSerial`. In hardware mode the hand is initialised
/// with `HI` (a calibration move of every finger) before its first motion command, never for a
/// reading; `open()` sends `GO`, `close()` `GC`, `relax()` the hand's own
/// terminate command `T` (motors off). Every command waits for the `=> ` prompt within a bounded
/// time and turns an `ERR` reply into the object's error status.
///
/// Also registers the command `Initialize` (sends `HI` again). The message `read` answers
/// `{"state": ..., "positions": [f1, f2, f3, spread]}` (encoder counts; hardware only); it opens
/// the port if needed but does not initialise the hand.
///
/// rp.cfg settings (besides Gripper's): `port DEVICE` (serial port, e.g. `/dev/ttyS0`; required),
/// `baud N` (default 9600), `timeout MS` (prompt wait, default 1000), `motionTimeout MS`
/// (for HI, GO, GC; default 10000).
class BarrettHand : public Gripper {
 public:
  /// Creates the hand (the port is opened on first use, in hardware mode).
  /// @param[in] name  object name (rp.cfg section); empty for an automatic name
  /// @throws ConfigError if a setting is invalid or `port` is missing from its rp.cfg section
  /// Real-time safe: no.
  explicit BarrettHand(const std::string& name = "");
  ~BarrettHand() override;

  /// Declares `port`, `baud`, `timeout` and `motionTimeout`.
  /// @param[out] schema  schema to add to
  static void declareSettings(SettingSchema& schema);

  /// Opens the port (if needed) and initialises the hand with `HI`.
  /// @return true on success; false on failure (see getErrorStatus())
  /// Real-time safe: no.
  bool initialize();
  /// Reads the finger and spread positions (`FGET P`); opens the port if needed, never sends `HI`.
  /// @param[out] counts  encoder counts of fingers 1, 2, 3 and the spread
  /// @return true on success; false on failure or in simulation
  /// Real-time safe: no.
  bool readPositions(std::array<int, 4>& counts);

  /// Answers `read` with the state (and positions on hardware) as JSON. Real-time safe: no.
  bool handleMessage(const std::string& type, const std::string& payload, std::string& reply) override;

 protected:
  bool hardwareOpen() override;
  bool hardwareClose() override;
  bool hardwareRelax() override;

 private:
  bool ready();
  bool opened();
  bool check(IoStatus status);

  BarrettHandSerial::Config config_;
  std::unique_ptr<BarrettHandSerial> driver_;
  bool initialized_ = false;
};

}  // namespace rp
