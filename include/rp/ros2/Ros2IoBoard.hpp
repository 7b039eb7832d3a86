#pragma once
/// @file
/// An I/O board whose encoders are a remote arm's joint_states and whose analog outputs are its
/// effort commands, over DDS with ROS 2's wire conventions: the hardware path of a manipulator
/// whose arm runs in another process (rp.cfg `remote NS/OBJECT` in the arm's section). See
/// docs/ros2.md.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "rp/io/IoBoard.hpp"

namespace rp {

/// Settings of a Ros2IoBoard (a manipulator's rp.cfg section has the same ones beside `remote`).
struct Ros2IoBoardOptions {
  /// The remote arm: the remote Ros2Bridge's namespace, `/`, the arm's object name (`cell1/puma`;
  /// `puma` alone without a namespace).
  std::string remote;
  int domain = 0;                             ///< DDS domain id of the remote bridge, 0..230
  std::vector<std::string> interfaces{"lo"};  ///< network interfaces DDS may use (`any`: Cyclone's choice)
  /// Silence of the remote arm's joint_states that fails every read [s], 0.005..60: the servo loop
  /// then shuts down naming the remote arm. The remote bridge holds the arm on its own once the
  /// effort commands stop for its `effortTimeout`.
  double timeout = 0.1;
  double connectTimeout = 10;  ///< longest wait for the remote arm's first joint_states and state [s], 0.1..600
  /// SCHED_FIFO priority of the thread that writes the effort commands, 1..98, or 0 for normal
  /// scheduling (default 26, as the bridge's publishing thread); warned once when refused.
  int priority = 26;
};

/// Counters of a Ros2IoBoard since it connected.
struct Ros2IoBoardStatistics {
  std::uint64_t samples = 0;        ///< joint_states samples of the arm received
  std::uint64_t commands = 0;       ///< std_msgs/Float64MultiArray effort commands written
  std::uint64_t writeFailures = 0;  ///< dds_write calls that failed
};

/// The I/O board of a remote arm: a manipulator in another process (another machine) published by
/// a Ros2Bridge there with `rate servo` and `commands on`, driven here by torque as a local arm is
/// driven through its amplifiers. So a program that declares `Puma560 puma;` (the paper's
/// Figure 21) runs its own servo loop, trajectory generator, gripper and work cell against an arm
/// in another process, with only rp.cfg changed (`simulationMode off`, `remote cell1/puma`).
///
/// | board | ROS 2 topic (relative to the remote namespace) |
/// |---|---|
/// | encoder k (counts, kCountsPerRadian a radian) | `joint_states` (sensor_msgs/msg/JointState): position of `<object>_<joint k>` |
/// | analog output k (volts, times the channel's N m per volt) | `<object>/effort_commands` (std_msgs/msg/Float64MultiArray, N m in joint order, as ros2_control's effort forward command controller sends) |
/// | digital output 0 (amplifiers on) | effort commands are written while it is on and the last sample is at most 10 ms old; when it goes off, or the samples go stale (and when the board goes while on), one empty command lets go of the arm, which the remote bridge then holds, and none is written after it until both hold again |
///
/// Samples arrive in Cyclone DDS's receive thread (a listener) and reach the servo loop through a
/// sequence lock: inputSampleTime() steps by the remote servo cycles' stamps, so the manipulator
/// differentiates positions over the remote arm's own cycle times (a stamp repeated: no new sample,
/// and not fresh: no torque is sent on it, and a remote that only repeats one falls silent). The
/// outputs of a cycle are written by a thread of the board's own, woken as the cycle ends: the servo thread makes no DDS
/// call and does not allocate.
///
/// Faults: a read fails (and the manipulator shuts down, naming the board's message) when no
/// joint_states came for `timeout`, when the remote arm reports an error or a system shutdown,
/// when the remote bridge refused an effort command, or when ten commands in a row could not be
/// written; switching the amplifiers on fails while the remote arm's power is off.
class Ros2IoBoard : public IoBoard {
 public:
  /// Encoder counts per joint radian: positions are exact to 1e-9 rad.
  static constexpr double kCountsPerRadian = 1e9;
  /// Joins the domain and waits for the remote arm's first joint_states and state.
  /// @param[in] options  the remote arm and how to reach it
  /// @param[in] jointNames  the arm's joint names in the model (`joint1`, ...); joint_states names
  ///            them `<object>_<joint>`
  /// @param[in] newtonMetresPerVolt  per analog output: the torque of one volt [N m/V]
  /// @throws std::invalid_argument for bad options, IoException when DDS cannot start or the remote
  ///         arm does not answer within `connectTimeout` (naming the topic), or lacks a joint
  /// Real-time safe: no.
  Ros2IoBoard(const Ros2IoBoardOptions& options, const std::vector<std::string>& jointNames,
              const std::vector<double>& newtonMetresPerVolt);
  /// Stops the writer thread and leaves the domain (no effort command is written after it).
  ~Ros2IoBoard() override;
  Ros2IoBoard(const Ros2IoBoard&) = delete;
  Ros2IoBoard& operator=(const Ros2IoBoard&) = delete;

  /// Why `options` cannot be used ("" if they can): the first setting out of range.
  /// @param[in] options  settings to check
  static std::string checkOptions(const Ros2IoBoardOptions& options);
  /// The settings in use.
  const Ros2IoBoardOptions& getOptions() const noexcept;
  /// Counters since the board connected. Real-time safe: yes.
  Ros2IoBoardStatistics getStatistics() const noexcept;

  /// None. Real-time safe: yes.
  int numDigitalInputs() const noexcept override { return 0; }
  /// One: line 0 switches the remote arm's effort commands on and off. Real-time safe: yes.
  int numDigitalOutputs() const noexcept override { return 1; }
  /// None. Real-time safe: yes.
  int numAnalogInputs() const noexcept override { return 0; }
  /// One per joint. Real-time safe: yes.
  int numAnalogOutputs() const noexcept override;
  /// One per joint. Real-time safe: yes.
  int numEncoders() const noexcept override;
  /// No digital inputs: `kInvalidLine`. Real-time safe: yes.
  IoStatus readDigitalInput(int line, bool& value) noexcept override;
  /// Line 0: on writes this cycle's effort commands (and those of the cycles that follow) while
  /// the last sample is at most 10 ms old, off writes none (one empty command on the way off).
  /// Hands the cycle's outputs to the writer thread. Fails while the remote arm's power is off.
  /// Real-time safe: yes.
  IoStatus writeDigitalOutput(int line, bool value) noexcept override;
  /// Line 0 as last written. Real-time safe: yes.
  IoStatus readDigitalOutput(int line, bool& value) noexcept override;
  /// No analog inputs: `kInvalidLine`. Real-time safe: yes.
  IoStatus readAnalogInput(int channel, double& volts) noexcept override;
  /// Sets joint `channel`'s torque to `volts` (clamped to +-10 V) times its N m per volt; written
  /// with the next digital output 0. NaN is refused. Real-time safe: yes.
  IoStatus writeAnalogOutput(int channel, double volts) noexcept override;
  /// Joint `encoder`'s position in the last joint_states sample [counts]; fails as the class
  /// comment says. Real-time safe: yes.
  IoStatus readEncoder(int encoder, std::int64_t& counts) noexcept override;
  /// When the sample the reads return was taken, on CLOCK_MONOTONIC [ns]: its stamp (the remote
  /// cycle's) plus an offset that follows the least delayed receipts, slewed by at most 1 us a
  /// sample (steps are the stamps' to that); -1 while one is stored. Real-time safe: yes.
  std::int64_t inputSampleTime() const noexcept override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rp
