#pragma once
/// @file
/// The ROS 2 bridge: the process's manipulators published on DDS (Cyclone DDS) with ROS 2's wire
/// conventions, so that ROS 2 nodes (RViz, ros2 topic, MoveIt) on the same network see them
/// without a bridge node. See docs/ros2.md.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "rp/core/PhysicalObject.hpp"

namespace rp {

/// Settings of a Ros2Bridge made in code (rp.cfg has the same ones, see Ros2Bridge).
struct Ros2BridgeOptions {
  int domain = 0;          ///< DDS domain id (ROS_DOMAIN_ID), 0..230
  /// ROS namespace of every topic, e.g. `cell1` or `/lab/cell1` (empty: none); letters, digits,
  /// `_` and `/`, each part starting with a letter or `_`.
  std::string nameSpace;
  /// joint_states and tf samples per second [Hz], 1..1000, or kServoRate: every servo cycle of
  /// each arm, published as that cycle ends (rp.cfg `rate servo`)
  double rate = 50;
  static constexpr double kServoRate = 0;  ///< `rate`: every servo cycle, as it ends
  /// Network interfaces DDS may use (Linux names such as `eth0`, or IPv4 addresses); `{"lo"}`
  /// (the default) keeps DDS on this machine; `{"any"}` lets Cyclone DDS choose.
  std::vector<std::string> interfaces{"lo"};
  /// Whether the arms take trajectories from `<object>/joint_trajectory` (default false: every
  /// trajectory is refused with a message on `<object>/state`); see Ros2Bridge::setCommandsEnabled().
  bool commands = false;
  /// SCHED_FIFO priority of the publishing thread, 1..98, or 0 for normal scheduling. The default,
  /// 26, is one below the control loops' default (27): the thread never delays a servo cycle of
  /// the default priority, and no thread of normal scheduling delays its wake-up (measured with
  /// bench/dds_bench: about 10 us of the latency from a servo cycle to a remote reader). Used when
  /// the process may; otherwise one warning on stderr and normal scheduling.
  int priority = 26;
  /// How long an arm driven by effort commands (`<object>/effort_commands`) goes on with the last
  /// one [s], 0.002..1: when none came for this long, the arm holds where it is then.
  double effortTimeout = 0.02;
};

/// Counters of a running bridge (samples written since it started), for tests and diagnostics.
struct Ros2BridgeStatistics {
  std::uint64_t cycles = 0;         ///< publishing cycles run
  std::uint64_t jointStates = 0;    ///< sensor_msgs/JointState samples written (one per arm and cycle)
  std::uint64_t tf = 0;             ///< tf2_msgs/TFMessage samples written on `tf`
  std::uint64_t descriptions = 0;   ///< std_msgs/String samples written on the robot_description topics
  std::uint64_t states = 0;         ///< std_msgs/String samples written on the `<object>/state` topics
  std::uint64_t writeFailures = 0;  ///< dds_write calls that failed
  std::size_t manipulators = 0;     ///< manipulators published in the last cycle
  std::uint64_t trajectories = 0;        ///< trajectory_msgs/JointTrajectory samples accepted (handed to an arm)
  std::uint64_t trajectoriesRefused = 0; ///< trajectory_msgs/JointTrajectory samples refused
  std::uint64_t efforts = 0;             ///< std_msgs/Float64MultiArray effort commands accepted
  std::uint64_t effortsRefused = 0;      ///< std_msgs/Float64MultiArray effort commands refused
};

/// Publishes every manipulator of the process on DDS as ROS 2 does (rmw_cyclonedds conventions:
/// topic names `rt/` + namespace + topic, type names `pkg::msg::dds_::Type_`, XCDR1, ROS 2's
/// default QoS: reliable, volatile, keep-last 10; transient-local for robot_description and
/// tf_static). Topics, relative to the namespace:
/// | topic | type | what |
/// |---|---|---|
/// | `joint_states` | sensor_msgs/msg/JointState | one sample per arm and cycle: names `<object>_<joint>` (`puma_joint1`, ...), position, velocity, effort (the torque commanded) |
/// | `tf` | tf2_msgs/msg/TFMessage | world to each link frame of every arm (`<object>_link1`, ..., `<object>_tool`, the end-effector), the frames of the arm's robot_description |
/// | `tf_static` | tf2_msgs/msg/TFMessage | world to each arm's `<object>_base_link` (transient-local) |
/// | `robot_description` | std_msgs/msg/String | one URDF holding every arm (transient-local) |
/// | `<object>/robot_description` | std_msgs/msg/String | the arm's URDF (transient-local) |
/// | `<object>/state` | std_msgs/msg/String | JSON: arm power, error, system shutdown, the last trajectory accepted or refused, effort commands driving the arm or refused; when it changes and once a second |
///
/// It subscribes, per arm, to `<object>/joint_trajectory` (trajectory_msgs/msg/JointTrajectory,
/// the topic of ros2_control's joint_trajectory_controller), only obeyed when commands are on
/// (`commands on`, setCommandsEnabled()). A trajectory is checked in the bridge's thread (joint
/// names, sizes, finite values, times, joint position and velocity limits) and executed by a
/// TimedTrajectoryGenerator the bridge connects to the arm, replacing the motion under way
/// continuously; a refused one leaves the arm as it was and names the field on `<object>/state`.
///
/// It also subscribes, per arm, to `<object>/effort_commands` (std_msgs/msg/Float64MultiArray:
/// one torque per joint [N m], as ros2_control's effort forward command controller sends), obeyed
/// when commands are on: this is how a manipulator of another process drives the arm by torque
/// (rp.cfg `remote` in that arm's section, Ros2IoBoard). A command is checked as it arrives (the
/// number of joints, finite values) and drives the arm from its next servo cycle: its torque is
/// then exactly the command (saturated at the torque limits, with the position and velocity limits
/// checked as always). The first command connects the bridge's effort control to the arm (within a
/// publishing cycle); when commands stop for `effortTimeout`, the arm holds where it is then, and
/// a trajectory taken gives it back to its default control. An empty command lets go at once. One
/// writer drives an arm at a time (another's commands, and trajectories, are refused while its
/// commands are fresh); an arm its program takes back (its own servo control, zero-gravity mode)
/// refuses the commands from then on. A refused command leaves the arm as it was and names the
/// field on `<object>/state` (`effort`, `effortsRefused`).
///
/// The bridge's own thread samples the arms `rate` times a second from the snapshots their servo
/// threads publish (as the Scene Viewer does): a servo loop never waits for the bridge or the
/// network. With `rate servo` (Ros2BridgeOptions::kServoRate) the thread wakes whenever a servo
/// cycle ends (an executor's cycle, through a futex the loop only signals) and publishes each arm
/// whose snapshot holds new joints: every servo cycle of every arm, as soon as it ends, but for a
/// cycle that read a hardware server's sample again (not published again); the state topics and
/// the trajectories taken are then looked at 50 times a second. Stamps are the wall-clock time the
/// joints hold for (StateSnapshot::readTime: when the cycle read them, or the server sampled them;
/// on a simulated clock, the time of publication). Arms created after the bridge are published
/// from the next cycle on.
///
/// rp.cfg (`[ros]` + `class Ros2Bridge`):
/// | setting | meaning |
/// |---|---|
/// | `domain D` | DDS domain id 0..230 (default 0) |
/// | `namespace NS` | ROS namespace of the topics (default none) |
/// | `rate HZ\|servo` | joint_states and tf rate 1..1000 Hz, or every servo cycle (default 50) |
/// | `interfaces IF...` | network interfaces for DDS (default `lo`: this machine only; `any`: Cyclone's choice) |
/// | `commands on\|off` | take trajectories from `<object>/joint_trajectory` (default off) |
/// | `priority P` | SCHED_FIFO priority of the publishing thread, 0 (normal scheduling) .. 98 (default 26) |
/// | `effortTimeout S` | how long effort commands drive an arm after the last one, 0.002 .. 1 s (default 0.02) |
class Ros2Bridge : public FunctionalObject {
 public:
  /// Creates the bridge from its rp.cfg section (defaults without one) and starts publishing.
  /// @param[in] name  object name (rp.cfg section); empty for an automatic name
  /// @throws ConfigError naming the file and line of a bad setting, or of `interfaces` when DDS
  ///         cannot start on them
  /// Real-time safe: no.
  explicit Ros2Bridge(const std::string& name = "");
  /// Creates the bridge with settings from code (rp.cfg is not read) and starts publishing.
  /// @param[in] name     object name; empty for an automatic name
  /// @param[in] options  domain, namespace, rate, interfaces
  /// @throws std::invalid_argument for a setting out of range, std::runtime_error when DDS
  ///         cannot start
  /// Real-time safe: no.
  Ros2Bridge(const std::string& name, const Ros2BridgeOptions& options);
  /// Stops publishing and leaves the DDS domain. Real-time safe: no.
  ~Ros2Bridge() override;

  /// Declares `domain`, `namespace`, `rate`, `interfaces`, `commands`, `priority` and `effortTimeout`.
  /// @param[out] schema  schema to add to
  static void declareSettings(SettingSchema& schema);

  /// The settings in use.
  const Ros2BridgeOptions& getOptions() const noexcept;
  /// Counters since the bridge started. Real-time safe: yes.
  Ros2BridgeStatistics getStatistics() const noexcept;
  /// Lets the arms take trajectories from `<object>/joint_trajectory` (on), or refuses them (off,
  /// the default). Switching off does not stop a trajectory under way. Real-time safe: yes.
  /// @param[in] on  whether to take them
  void setCommandsEnabled(bool on) noexcept;
  /// Whether the arms take trajectories from the network. Real-time safe: yes.
  bool areCommandsEnabled() const noexcept;
  /// The bridge's message about the last trajectory for arm `object` (accepted or refused, as on
  /// `<object>/state`), "" if none came. Real-time safe: no.
  /// @param[in] object  the arm's object name
  std::string getLastCommandMessage(const std::string& object) const;

  /// The DDS topic name of ROS topic `topic` in namespace `nameSpace`: `rt/NS/TOPIC`.
  /// @param[in] nameSpace  ROS namespace (leading and trailing `/` ignored; empty: none)
  /// @param[in] topic      topic relative to the namespace, e.g. `joint_states`
  static std::string ddsTopicName(const std::string& nameSpace, const std::string& topic);
  /// The Cyclone DDS configuration (XML) that restricts a domain to `interfaces` (see
  /// Ros2BridgeOptions::interfaces).
  /// @param[in] interfaces  interface names or IPv4 addresses; `{"any"}` for no restriction
  static std::string cycloneConfig(const std::vector<std::string>& interfaces);
  /// Why `options` cannot be used ("" if they can): the first setting out of range.
  /// @param[in] options  settings to check
  static std::string checkOptions(const Ros2BridgeOptions& options);
  /// The arm's URDF as the bridge publishes it: toUrdf() with every link and joint name but the
  /// root `world` prefixed with `<object>_`.
  /// @param[in] object  the arm's object name
  /// @param[in] urdf    toUrdf() of its model
  static std::string prefixUrdf(const std::string& object, const std::string& urdf);

 private:
  void start();
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rp
