#pragma once
/// @file
/// A tool changer worked by two digital outputs (paper section 3.4).

#include <memory>
#include <string>

#include "rp/effector/ToolChanger.hpp"
#include "rp/io/IoBoard.hpp"

namespace rp {

/// The default tool changer (paper section 3.4): one digital output locks, one unlocks;
/// `relax()` clears both. rp.cfg settings as DefaultGripper's, with `lockLine` and `unlockLine`
/// instead of `openLine` and `closeLine`.
class DefaultToolChanger : public ToolChanger {
 public:
  /// Creates the tool changer; with a `board` setting, sets up that board.
  /// @param[in] name  object name (rp.cfg section); empty for an automatic name
  /// @throws ConfigError if a setting is invalid or a line is missing
  /// Real-time safe: no.
  explicit DefaultToolChanger(const std::string& name = "");
  ~DefaultToolChanger() override;

  /// Declares the board and line settings.
  /// @param[out] schema  schema to add to
  static void declareSettings(SettingSchema& schema);

  /// Uses `board` (not owned; must outlive the tool changer) with the given output lines.
  /// @param[in] board  the I/O board
  /// @param[in] lockLine  digital output that locks
  /// @param[in] unlockLine  digital output that unlocks
  /// Real-time safe: no.
  void setIoBoard(IoBoard& board, int lockLine, int unlockLine);
  /// The board in use, or nullptr. Real-time safe: yes.
  IoBoard* getIoBoard() const noexcept { return board_; }

 protected:
  bool hardwareLock() override;
  bool hardwareUnlock() override;
  bool hardwareRelax() override;

 private:
  bool drive(bool lockOn, bool unlockOn);

  std::unique_ptr<IoBoard> ownedBoard_;
  IoBoard* board_ = nullptr;
  int lockLine_ = 0, unlockLine_ = 1;
};

}  // namespace rp
