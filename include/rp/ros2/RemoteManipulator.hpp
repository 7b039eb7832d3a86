#pragma once
/// @file
/// A manipulator whose arm runs in another process (or on another machine), reached over DDS
/// through that process's Ros2Bridge. See docs/ros2.md, "A remote arm".

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "rp/manipulator/Manipulator.hpp"
#include "rp/rt/ControlProgram.hpp"
#include "rp/trajectory/Setpoint.hpp"

namespace rp {

/// Settings of a RemoteManipulator made in code (rp.cfg has the same ones, see RemoteManipulator).
struct RemoteManipulatorOptions {
  /// The remote arm: `NS/OBJECT` (the namespace of the remote Ros2Bridge, then the arm's object
  /// name), or `OBJECT` when that bridge has no namespace; e.g. `cell1/puma`.
  std::string remote;
  int domain = 0;  ///< DDS domain id (ROS_DOMAIN_ID) of the remote bridge, 0..230
  /// Network interfaces DDS may use, as Ros2BridgeOptions::interfaces (default `lo`).
  std::vector<std::string> interfaces{"lo"};
  double rate = 100;           ///< setpoints streamed per second [Hz], 10..500
  double timeout = 0.5;        ///< silence of the remote arm's joint_states that is a fault [s], 0.05..60
  double connectTimeout = 10;  ///< longest wait at construction for the remote description and state [s], 0.1..600
};

/// Counters and figures of a RemoteManipulator's link to its arm, since construction.
struct RemoteManipulatorStatistics {
  std::uint64_t samples = 0;       ///< joint_states samples of the remote arm received
  std::uint64_t gaps = 0;          ///< intervals between received samples longer than 1.5 publishing periods
  std::uint64_t missing = 0;       ///< samples estimated lost in those gaps (interval / period - 1, rounded)
  double period = 0;               ///< the remote bridge's publishing period, estimated (the shortest interval seen) [s]
  double latencyMedian = 0;        ///< receipt time minus the sample's header.stamp, median of the last 4096 [s]
  double latencyP99 = 0;           ///< the same, 99th percentile [s]
  double latencyMax = 0;           ///< the same, largest of the last 4096 [s]
  std::uint64_t trajectoriesSent = 0;     ///< trajectory_msgs/JointTrajectory samples written
  std::uint64_t writeFailures = 0;        ///< dds_write calls that failed
  std::uint64_t remoteRefusals = 0;       ///< trajectories the remote bridge reported refused since construction
};

/// A Manipulator whose arm runs in another process, on this machine or another: it reads the
/// arm's `joint_states` and `<object>/state` and streams the attached trajectory generator's
/// setpoints to `<object>/joint_trajectory`, the topics of the remote process's Ros2Bridge (which
/// must have `commands on`). The paper's programs run against it unchanged: `[leader] class
/// RemoteManipulator` and `remote NS/OBJECT` in rp.cfg instead of `class Puma560`.
///
/// - Model: loadUrdf() of the remote `<object>/robot_description` (transient-local), waited for
///   at construction up to `connectTimeout`; its joint names carry the `<object>_` prefix.
/// - State: joint positions, velocities and efforts from the arm's entries of `joint_states`;
///   the end-effector pose by the model's forward kinematics of those positions; the power, the
///   remote errors and shutdowns from `<object>/state`.
/// - Motion: its own control program (`rate` Hz, default 100, in a thread of its own) evaluates
///   the attached TrajectoryGenerator every cycle, as a DefaultManipulator's servo loop does (the
///   first call of a generator gets the last measured position as the setpoint it starts from),
///   and writes a JointTrajectory of two points: the setpoint (position, velocity) 50 ms ahead
///   and, 200 ms after it, the stop at constant deceleration from there (velocity 0). Each
///   replaces the one before on the remote side, continuously; if the stream ends (this program
///   ends or dies), the arm stops within 250 ms of the last sample. The remote arm follows the
///   generator about 50 ms plus the network latency behind. Nothing is written while no
///   generator is set or the power is off here: the remote arm holds where it is.
/// - Its loop makes no DDS call and takes no lock: a reader thread waits for the arm's samples
///   (joint_states, `<object>/state`, parsed as JSON) and hands the joints over through a
///   TripleBuffer; a writer thread writes each cycle's trajectory after the cycle ends. The cycle
///   does not allocate. The remote arm's servo loop runs in the remote process.
/// - Faults: no joint_states from the arm for `timeout` seconds (default 0.5), a remote error or
///   shutdown, or a trajectory refused by the remote bridge sets this object's error status
///   (naming the remote arm) and requests a system shutdown, so every wait of a generator
///   returns instead of hanging, and a program started with RoboticPlatform::init() ends with
///   status 3.
/// - The remote servo control, gravity compensation and simulation are the remote process's:
///   setServoControl(), the gravity and zero-gravity switches, setControlOutput() and
///   applyExternalWrench() throw std::logic_error. enableArmPower() does not switch the remote
///   arm on (it throws if it is off); disableArmPower() stops the stream here.
///
/// rp.cfg (`[leader]` + `class RemoteManipulator`):
/// | setting | meaning |
/// |---|---|
/// | `remote NS/OBJECT` | the remote arm (required) |
/// | `domain D` | DDS domain id 0..230 (default 0) |
/// | `interfaces IF...` | network interfaces for DDS (default `lo`) |
/// | `rate HZ` | setpoints per second 10..500 (default 100) |
/// | `timeout S` | silence that is a fault, 0.05..60 s (default 0.5) |
/// | `connectTimeout S` | wait for the remote arm at construction, 0.1..600 s (default 10) |
class RemoteManipulator : public Manipulator, public ControlProgram {
 public:
  /// Connects to the arm its rp.cfg section names.
  /// @param[in] name  object name (rp.cfg section)
  /// @throws ConfigError naming the file and line of a missing or bad setting, or of `remote`
  ///         when the arm does not answer within `connectTimeout` (naming the topic)
  /// Real-time safe: no.
  explicit RemoteManipulator(const std::string& name = "");
  /// Connects to the arm `options.remote` with settings from code (rp.cfg is not read).
  /// @param[in] name     object name; empty for an automatic name
  /// @param[in] options  the remote arm, domain, interfaces, rate and time-outs
  /// @throws std::invalid_argument for a bad setting; std::runtime_error when DDS cannot start or
  ///         the arm does not answer within `connectTimeout` (naming the topic)
  /// Real-time safe: no.
  RemoteManipulator(const std::string& name, const RemoteManipulatorOptions& options);
  /// Stops the stream (the remote arm stops as described above), prints the link's statistics on
  /// stderr if samples were lost, and leaves the DDS domain. Real-time safe: no.
  ~RemoteManipulator() override;

  /// Declares `remote`, `domain`, `interfaces`, `rate`, `timeout` and `connectTimeout`.
  /// @param[out] schema  schema to add to
  static void declareSettings(SettingSchema& schema);
  /// Why `options` cannot be used ("" if they can): the first setting out of range.
  /// @param[in] options  settings to check
  static std::string checkOptions(const RemoteManipulatorOptions& options);

  /// The settings in use.
  const RemoteManipulatorOptions& getOptions() const noexcept;
  /// The link's counters, latency and loss so far. Real-time safe: no.
  RemoteManipulatorStatistics getStatistics() const;
  /// The last `<object>/state` JSON text received ("" if none). Real-time safe: no.
  std::string getRemoteState() const;

  /// The model loaded from the remote robot_description.
  const ManipulatorModel& getModel() const override;
  /// The period of the streaming program [s] (1 / rate).
  double getServoPeriod() const override;
  /// The last joint positions received [rad or m]. Real-time safe: no (a short lock).
  JointVector getJointPosition() const override;
  /// The last joint velocities received. Real-time safe: no (a short lock).
  JointVector getJointVelocity() const override;
  /// The last setpoint streamed (the generator's, or the hold while none drives the arm); read it
  /// from the streaming thread only (e.g. from a generator).
  const Setpoint& getSetpoint() const override;
  JointVector getDesiredJointPosition() const override;
  /// The last joint efforts received (the remote arm's commanded torques). Real-time safe: no.
  JointVector getControlOutput() const override;
  /// Not possible on a remote arm. @throws std::logic_error
  /// @param[in] torque  ignored
  void setControlOutput(const Eigen::Ref<const Eigen::VectorXd>& torque) override;
  /// Resumes the stream; the remote arm's power must be on (switched on remotely).
  /// @throws std::runtime_error if the remote arm reports its power off or the link is faulted
  void enableArmPower() override;
  /// Stops the stream (the remote arm stops and holds); does not switch the remote power off.
  void disableArmPower() override;
  /// Whether the stream is on and the remote arm reports its power on.
  bool isArmPowerOn() const override;
  /// The end-effector pose of the last positions received, by the model's forward kinematics.
  Transform getEndEffectorTransform() const override;
  /// Joint torques of an end-effector wrench at `q`, by the model.
  /// @param[in]  q       joint positions
  /// @param[in]  force   wrench (3 or 6 values) in the base frame
  /// @param[out] torque  joint torques
  void endEffectorForceToJointTorque(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& force,
                                     Eigen::Ref<Eigen::VectorXd> torque) const override;
  /// Attaches `generator`: from the next cycle its setpoints are streamed to the remote arm.
  /// @param[in] generator  the generator to follow
  void setTrajectoryGenerator(TrajectoryGenerator& generator) override;
  /// Detaches the generator: the stream ends, the remote arm stops as described above.
  void clearTrajectoryGenerator() override;
  /// The attached generator, nullptr if none.
  TrajectoryGenerator* getTrajectoryGenerator() const override;
  /// Detaches `generator` if it is the one attached, and disconnects it.
  /// @param[in] generator  the generator going away
  void releaseTrajectoryGenerator(TrajectoryGenerator& generator) override;
  /// The servo control runs on the remote side. @throws std::logic_error
  /// @param[in] control  ignored
  void setServoControl(ServoControl& control) override;
  /// The servo control runs on the remote side. @throws std::logic_error
  ServoControl& getServoControl() const override;
  /// Does nothing (no servo control of this object's can be set).
  /// @param[in] control  ignored
  void releaseServoControl(ServoControl& control) override;
  /// The remote side's. @throws std::logic_error
  void setGravityCompensationOn() override;
  /// The remote side's. @throws std::logic_error
  void setGravityCompensationOff() override;
  /// true: the remote arm's servo loop compensates gravity (the platform's default).
  bool isGravityCompensationOn() const override;
  /// The remote side's. @throws std::logic_error
  void setZeroGravityModeOn() override;
  /// Does nothing (never on).
  void setZeroGravityModeOff() override;
  /// false.
  bool isZeroGravityModeOn() const override;
  /// Not possible on a remote arm. @throws std::logic_error
  /// @param[in] wrench  ignored
  void applyExternalWrench(const Vector<6>& wrench) override;
  /// Not possible on a remote arm. @throws std::logic_error
  /// @param[in] link    ignored
  /// @param[in] point   ignored
  /// @param[in] wrench  ignored
  void applyExternalWrench(int link, const Vector<3>& point, const Vector<6>& wrench) override;
  /// This object's streaming program.
  ControlProgram* getControlProgram() override { return this; }

 protected:
  /// One cycle: take the samples received, check the link, evaluate the generator, write.
  void control() override;

 private:
  void connect();
  // A fault (the link, the remote arm, the generator): the error status and a system shutdown, once.
  void raiseFault(const std::string& fault);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rp
