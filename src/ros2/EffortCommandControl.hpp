#pragma once
// Internal to src/ros2: the servo control through which a Ros2Bridge drives an arm by the effort
// commands (std_msgs/Float64MultiArray, N m) of `<object>/effort_commands`. Not installed.

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include "rp/control/ServoControl.hpp"
#include "rp/model/ManipulatorData.hpp"
#include "rp/model/ManipulatorModel.hpp"

namespace rp::ros2detail {

// Outputs the last effort command while it is fresh (received within `timeout`): the arm's torque
// is then exactly the command (the gravity torque the manipulator adds with compensation on is
// taken off first). Once the commands stop, it holds the arm where it is at that moment with the
// PD gains of the arm's default position control (and the manipulator's gravity compensation).
// Commands arrive from Cyclone DDS's receive thread (command()) through a sequence lock;
// calculate() and activate() do not allocate, lock or block.
class EffortCommandControl : public ServoControl {
 public:
  EffortCommandControl(const std::string& name, double timeout);
  ~EffortCommandControl() override;
  // Sizes the buffers and copies the hold gains of `manipulator`'s servo control, which must be a
  // DefaultPositionControl (std::logic_error otherwise).
  void attach(Manipulator& manipulator) override;
  void activate() override;
  void calculate() override;
  // A checked command of n torques [N m], received now. Real-time safe: yes (one writer).
  void command(const double* torques, int n) noexcept;
  // The driver let go (an empty command): the arm holds from the next cycle. Real-time safe: yes.
  void release() noexcept;
  // Whether the last cycle output a command (false: holding). Real-time safe: yes.
  bool isDriving() const noexcept { return driving_.load(std::memory_order_relaxed); }

 private:
  bool latest(double* torques, int n, std::int64_t& received) const noexcept;

  const double timeout_;
  std::atomic<std::uint64_t> sequence_{0};  // odd while a command is being stored
  std::array<std::atomic<double>, kMaxJoints> torques_{};
  std::atomic<std::int64_t> received_{0};  // steady clock [ns]; 0: none yet
  std::atomic<bool> driving_{false};
  // The servo thread's own.
  std::unique_ptr<ManipulatorData> data_;
  JointVector kp_, kd_, hold_, out_, gravity_;
  bool holding_ = false;
  double lastTorques_[kMaxJoints] = {};  // the last command read whole, for a cycle whose read collides with a store
  std::int64_t lastReceived_ = 0;
};

}  // namespace rp::ros2detail
