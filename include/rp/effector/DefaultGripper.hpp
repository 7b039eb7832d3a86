#pragma once
/// @file
/// A gripper worked by two digital outputs (paper section 3.4).

#include <memory>
#include <string>

#include "rp/effector/Gripper.hpp"
#include "rp/io/IoBoard.hpp"

namespace rp {

/// The default gripper (paper section 3.4): two digital output lines, one that opens the gripper
/// and one that closes it. `open()` sets the open line and clears the close line, `close()` the
/// reverse, `relax()` clears both.
///
/// rp.cfg settings (besides Gripper's), the same for DefaultToolChanger with `lockLine` and
/// `unlockLine`:
/// | setting | meaning |
/// |---|---|
/// | `board simulated\|modbus\|hwserver` | which I/O board drives the lines |
/// | `openLine N`, `closeLine N` | the two output lines (for `modbus`: coil addresses) |
/// | `address A`, `port P`, `unitId U`, `timeout MS` | Modbus TCP server (default 127.0.0.1, 502, 1, 200) |
/// | `server NAME` | the hardware server (`rp-hwserver -name NAME`) for `hwserver` |
///
/// Example: `[gripper]` `class DefaultGripper` `board modbus` `port 1502` `openLine 0` `closeLine 1`.
class DefaultGripper : public Gripper {
 public:
  /// Creates the gripper; with a `board` setting, sets up that board (connection problems are
  /// reported as the object's error status, not thrown).
  /// @param[in] name  object name (rp.cfg section); empty for an automatic name
  /// @throws ConfigError if a setting is invalid or a line is missing
  /// Real-time safe: no.
  explicit DefaultGripper(const std::string& name = "");
  ~DefaultGripper() override;

  /// Declares the board and line settings.
  /// @param[out] schema  schema to add to
  static void declareSettings(SettingSchema& schema);

  /// Uses `board` (not owned; must outlive the gripper) with the given output lines.
  /// @param[in] board  the I/O board
  /// @param[in] openLine  digital output that opens the gripper
  /// @param[in] closeLine  digital output that closes the gripper
  /// Real-time safe: no.
  void setIoBoard(IoBoard& board, int openLine, int closeLine);
  /// The board in use, or nullptr (simulation only). Real-time safe: yes.
  IoBoard* getIoBoard() const noexcept { return board_; }

 protected:
  bool hardwareOpen() override;
  bool hardwareClose() override;
  bool hardwareRelax() override;

 private:
  bool drive(bool openOn, bool closeOn);

  std::unique_ptr<IoBoard> ownedBoard_;
  IoBoard* board_ = nullptr;
  int openLine_ = 0, closeLine_ = 1;
};

}  // namespace rp
