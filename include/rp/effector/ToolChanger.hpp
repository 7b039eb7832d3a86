#pragma once
/// @file
/// The generic tool-changer interface (paper section 3.4): lock, unlock, relax.

#include <atomic>
#include <string>

#include "rp/core/PhysicalObject.hpp"

namespace rp {

/// Generic interface of a tool changer (paper section 3.4): `lock()`, `unlock()`, `relax()`.
///
/// Registers the interactive commands `Lock`, `Unlock` and `Relax`, describes a control panel
/// with its state and answers the message `read` with `{"state": "locked"}`. In simulation mode
/// only the state changes. A hardware failure sets the error status (code 1) and the command
/// returns false.
class ToolChanger : public PhysicalObject {
 public:
  /// What the tool changer was last told to do.
  enum class State {
    Unknown,   ///< no command yet
    Locked,    ///< tool locked
    Unlocked,  ///< tool released
    Relaxed    ///< both actuators off
  };

  /// Creates the tool changer and registers its commands.
  /// @param[in] name  object name (rp.cfg section); empty for an automatic name
  /// Real-time safe: no.
  explicit ToolChanger(const std::string& name = "");
  ~ToolChanger() override;

  /// Locks the tool. @return true on success, false on a hardware failure. Real-time safe: no.
  virtual bool lock();
  /// Unlocks the tool. @return true on success, false on a hardware failure. Real-time safe: no.
  virtual bool unlock();
  /// Switches both actuators off. @return true on success, false on a hardware failure. Real-time safe: no.
  virtual bool relax();

  /// The state after the last successful command. Real-time safe: yes.
  State getState() const noexcept { return state_.load(); }
  /// The name of a state: `unknown`, `locked`, `unlocked` or `relaxed`.
  /// @param[in] state  a state
  static const char* stateName(State state) noexcept;

  /// Adds the state to the default panel. Real-time safe: no.
  ControlPanel getControlPanel() const override;
  /// Publishes the state (index into the panel's `state` choices).
  /// @param[out] snapshot  receives the value
  /// @return true
  /// Real-time safe: no.
  bool getStateSnapshot(StateSnapshot& snapshot) const override;
  /// Answers `read` with the state as JSON. Real-time safe: no.
  bool handleMessage(const std::string& type, const std::string& payload, std::string& reply) override;

 protected:
  /// Drives the hardware to lock. @return true on success; on failure, set the error first.
  virtual bool hardwareLock() = 0;
  /// Drives the hardware to unlock. @return true on success; on failure, set the error first.
  virtual bool hardwareUnlock() = 0;
  /// Switches the hardware off. @return true on success; on failure, set the error first.
  virtual bool hardwareRelax() = 0;

 private:
  bool apply(State target, bool (ToolChanger::*hardware)());
  std::atomic<State> state_{State::Unknown};
};

}  // namespace rp
