#pragma once
/// @file
/// The default implementation of open-architecture manipulators: the servo loop (paper section
/// 3.3, Figure 11) and simulation mode.

#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "rp/control/DefaultPositionControl.hpp"
#include "rp/io/IoBoard.hpp"
#include "rp/math/Differentiator.hpp"
#include "rp/manipulator/Manipulator.hpp"
#include "rp/manipulator/ManipulatorSimulation.hpp"
#include "rp/rt/ControlProgram.hpp"
#include "rp/rt/TripleBuffer.hpp"
#include "rp/trajectory/Setpoint.hpp"

namespace rp {

class SimulatedClock;

/// A manipulator whose servo loop is a ControlProgram, started when the object is created (paper
/// Figure 11) and stepped by the executor thread of its rate with every other arm of that rate
/// (or in a thread of its own: rp.cfg `thread own`; docs/realtime.md, Executors). Every cycle:
/// 1. read the joints (from the arm, or from the dynamic simulation in simulation mode, which first
///    integrates the time since the last cycle under its torques: ManipulatorSimulation::advance()
///    on the real clock): the read phase, readInputs(), before any program of the executor computes;
/// 2. get the setpoint from the trajectory generator (hold the current position when there is
///    none; see the hand-overs below);
/// 3. run the servo control (a DefaultPositionControl unless switched), plus the gravity torque
///    when gravity compensation is on (only the gravity torque in zero-gravity mode);
/// 4. saturate the command (servo control plus gravity) at each joint's torque limit (counted, and
///    logged in the column `saturated`), then check the limits: a joint outside its position
///    limits or faster than its velocity limit sets the error status (naming the joint, the value
///    and the limit) and requests a system shutdown. So does a torque or setpoint that is not a
///    number, or an exception thrown by the servo control or the trajectory generator (its
///    message in the error status); a joint reading that is not a number switches the power off
///    at once;
///    (steps 2 to 4 are the control phase, control());
/// 5. output the torques (to the amplifiers, or to the simulation, which integrates them at the next
///    cycle's read over the time that really passed): the write phase, writeOutputs(), after every
///    program of the executor has computed;
/// 6. publish the state for other threads and sample the log variables `q`, `qd`, `qdes`,
///    `qddes`, `qdddes`, `tau`, `saturated` and `missed` (deadlines skipped so far).
///
/// Shutdown (system shutdown, a fault, or the object's destruction while the arm is powered): a
/// damped hold (velocity damping plus gravity compensation, within the torque limits) until the
/// arm has been at rest for 50 ms (at most 3 s), then power off (brakes on). However the servo
/// loop ends, its last act switches the amplifiers off and writes 0 V to every joint.
///
/// The arm power is on when the loop starts, holding the position the arm is in. In simulation
/// mode the arm starts at rest at the model's home position (or where rp.cfg's
/// `simInitialPosition` puts it).
///
/// Hand-overs are bumpless: each holds the arm where it is in the cycle the change is taken (the
/// joints read in that cycle), never at a pose from before. They are: the loop's first cycle (a
/// program's start, wherever the arm is), the power coming on, a servo control set or released
/// (the control in use is activated, e.g. a DefaultPositionControl's integral is reset), a
/// trajectory generator set, replaced, cleared or released (a new generator's first call gets
/// that hold as the setpoint it starts from), zero-gravity mode switched on (from that cycle only
/// the gravity torque goes out: neither the servo control nor the generator runs; the arm goes on
/// under its own momentum) or off (the servo control in use starts afresh, holding there). A
/// generator still set when zero-gravity mode ends drives the arm again from that cycle, with the
/// setpoint it gives for that time: clear it first (clearTrajectoryGenerator()) to keep the arm
/// where it was pushed to.
///
/// Pose, mount and simulation mode: setTransform(), setConnection(), clearConnection(),
/// setSimulationModeOn() and setSimulationModeOff() rebuild the model (its base is the mount
/// frame's world pose, evaluated when called, times the object's pose) and switch between the
/// simulated arm and the hardware, while the loop runs: the change takes effect at the next cycle
/// boundary, before the call returns, and the arm holds where it is (a simulation taking over
/// starts from the joint state the arm had; the hardware taking over holds where its encoders
/// say). Allowed while nothing drives the arm: before a trajectory generator is set and while
/// the DefaultPositionControl is in use (as the paper's Figure 23 does it: right after the
/// declaration); otherwise, and during or after a shutdown, the call throws std::logic_error and
/// changes nothing. Leaving the hardware switches its amplifiers off and writes 0 V first.
/// Switching to the hardware without a configured hardware server throws std::runtime_error. A
/// mount that moves later (an arm on another arm) is not followed: the base is where the mount
/// was when the call was made. References from getModel() stay valid (models replaced are kept
/// until the manipulator is destroyed) but describe the pose they were taken at.
///
/// Hardware (simulation mode off): the arm is reached through a hardware server named by rp.cfg's
/// `hwserver NAME` (see rp-hwserver): joint j's angle is encoder j's count divided by
/// `countsPerRadian` (default 20000), its velocity a filtered backward difference, its torque goes
/// out as analog output j in volts (torque / gain, gain = torque limit / 10 V), and digital output 0
/// enables the amplifiers (power). A failed read or write sets the error status and requests a
/// system shutdown.
class DefaultManipulator : public Manipulator, public ControlProgram {
 public:
  /// Makes the model once the object's pose (rp.cfg `position`/`orientation`) is known.
  using ModelFactory = std::function<std::unique_ptr<ManipulatorModel>(const Transform& base)>;
  /// Tag of the protected constructors of the arm classes (Puma560, WAM) for classes derived
  /// from them: those constructors do not start the servo loop, the derived class's constructor
  /// calls startControlLoop() last (and its destructor stopControlLoop() first), so the loop
  /// never runs on a half-built object.
  struct DerivedClass {};

  /// Creates the manipulator. Derived classes call startControlLoop() at the end of their
  /// constructor.
  /// @param[in] name          object name; empty for an automatic name
  /// @param[in] modelFactory  makes the model for the given base pose
  /// If simulation mode is off and no hardware is configured for the object, the arm stays
  /// unpowered until the program switches it to simulation (setSimulationModeOn() right after the
  /// declaration, as the paper's Figure 23 does); enableArmPower() before that throws, and half a
  /// second without it is a fault (error status and system shutdown, naming the object).
  /// @throws IoException if the configured hardware server cannot be reached
  DefaultManipulator(const std::string& name, const ModelFactory& modelFactory);
  /// Stops the servo loop.
  ~DefaultManipulator() override;

  /// Declares `hwserver` and `countsPerRadian`.
  /// @param[out] schema  schema to add to
  static void declareSettings(SettingSchema& schema);
  /// Whether the arm is reached through a hardware server (simulation mode off).
  /// Real-time safe: yes.
  bool usesHardware() const { return usesHardware_.load(std::memory_order_acquire); }

  /// The model for the current base pose (see the class comment on pose changes).
  /// Real-time safe: yes.
  const ManipulatorModel& getModel() const override { return *modelView_.load(std::memory_order_acquire); }
  double getServoPeriod() const override { return getPeriod(); }
  ControlProgram* getControlProgram() override { return this; }

  JointVector getJointPosition() const override;
  JointVector getJointVelocity() const override;
  const Setpoint& getSetpoint() const override;
  JointVector getDesiredJointPosition() const override;
  JointVector getControlOutput() const override;
  void setControlOutput(const Eigen::Ref<const Eigen::VectorXd>& torque) override;

  /// @throws std::runtime_error if simulation mode is off and no hardware is configured
  /// @throws std::logic_error during a shutdown
  void enableArmPower() override;
  void disableArmPower() override;
  bool isArmPowerOn() const override;

  Transform getEndEffectorTransform() const override;
  void endEffectorForceToJointTorque(const Eigen::Ref<const Eigen::VectorXd>& q,
                                     const Eigen::Ref<const Eigen::VectorXd>& force,
                                     Eigen::Ref<Eigen::VectorXd> torque) const override;

  void setTrajectoryGenerator(TrajectoryGenerator& generator) override;
  void clearTrajectoryGenerator() override;
  TrajectoryGenerator* getTrajectoryGenerator() const override;
  /// Uses `control` from the next cycle (a bumpless hand-over) and offers it to the operator (see
  /// addServoControl()).
  void setServoControl(ServoControl& control) override;
  ServoControl& getServoControl() const override;
  /// Offers `control` to the operator without using it: the control panel's servo-control switch
  /// and the pop-up menu list it (command "Servo Control: NAME", which calls setServoControl()),
  /// next to the DefaultPositionControl and every control set with setServoControl(). The offer
  /// ends when the control is released or destroyed (releaseServoControl()).
  /// @param[in] control  a servo control for this manipulator (attached now)
  /// Real-time safe: no.
  void addServoControl(ServoControl& control);
  /// The names of the offered servo controls, in the order they were offered (the
  /// DefaultPositionControl first). Real-time safe: no.
  std::vector<std::string> getServoControlNames() const;
  /// The name of the servo control in use. Real-time safe: no.
  std::string getServoControlName() const;
  /// The DefaultPositionControl the manipulator created.
  DefaultPositionControl& getDefaultPositionControl() { return *defaultControl_; }
  void setGravityCompensationOn() override { gravityCompensation_.store(true); }
  void setGravityCompensationOff() override { gravityCompensation_.store(false); }
  bool isGravityCompensationOn() const override { return gravityCompensation_.load(); }
  void setZeroGravityModeOn() override { zeroGravity_.store(true); }
  void setZeroGravityModeOff() override;
  bool isZeroGravityModeOn() const override { return zeroGravity_.load(); }

  void applyExternalWrench(const Vector<6>& wrench) override;
  void applyExternalWrench(int link, const Vector<3>& point, const Vector<6>& wrench) override;

  /// Sets the payload the arm carries (a gripper sets it when it grasps and releases a work
  /// piece): a point mass at `centre` in the end-effector frame. From the next servo cycle both
  /// the gravity compensation (and the damped hold of a shutdown) and, in simulation mode, the
  /// simulated plant carry it: the gravity torque gains \f$-J_p(q)^T m\,g\f$, with \f$J_p\f$
  /// the translational Jacobian of the centre and \f$g\f$ the model's gravity, and the plant's
  /// dynamics the point mass (see ManipulatorSimulation::setPayload(); it adds to rp.cfg's
  /// `simPayload`). The servo thread takes the payload between two cycles without a lock or an
  /// allocation; a change of pose or simulation mode keeps it. The servo control itself (a
  /// DefaultPositionControl) has no model and is not changed.
  /// @param[in] mass    payload mass [kg] (0: none)
  /// @param[in] centre  centre of mass in the end-effector frame [m]
  /// @throws std::invalid_argument for a negative or non-finite mass or a non-finite centre
  /// @throws std::length_error from ManipulatorSimulation::setPayload() (too many centres)
  /// Real-time safe: no.
  void setPayload(double mass, const Vector<3>& centre = Vector<3>::Zero());
  /// The payload mass last set [kg]. Real-time safe: no.
  double getPayloadMass() const;
  /// The payload's centre of mass last set, in the end-effector frame [m]. Real-time safe: no.
  Vector<3> getPayloadCentre() const;

  void releaseServoControl(ServoControl& control) override;
  void releaseTrajectoryGenerator(TrajectoryGenerator& generator) override;

  /// Holds a powered arm until it is at rest and switches the power off (as in a shutdown),
  /// before the loop stops: so destroying a manipulator (its destructor calls stopControlLoop())
  /// never cuts the power of a moving arm. Bounded: at most about 5 s.
  void beforeControlLoopStops() override { holdUntilSafe(); }

  /// QMotor's Stop: a powered arm is held (damped, with gravity compensation) until it is at rest,
  /// then the power goes off and the brakes on where it came to rest; then the loop stops. Unlike
  /// a shutdown, the program can be started again (startControlProgram()).
  /// @return what was done, with the joints where the arm was braked [deg]
  /// @throws std::logic_error if the loop is not running
  std::string stopControlProgram() override;
  /// QMotor's Start: the loop starts holding the arm where it is (a bumpless hand-over: the servo
  /// control starts afresh at the joints read in the first cycle), with the power on if it was on
  /// at the stop; with a trajectory generator set the arm stays braked (its program powers it, as
  /// for the Power On command).
  /// @return what was done
  /// @throws std::logic_error saying why not (see RoboticObject::startControlProgram())
  std::string startControlProgram() override;

  /// Starts the damped hold (velocity damping plus gravity compensation, within the torque
  /// limits) until the arm is at rest, then switches the power off and engages the brakes. The
  /// servo loop goes on running (holding the outputs off) until the system shutdown stops it.
  void startShutdown() override;
  bool isShutdownComplete() const override;

  /// Number of powered cycles in which the command (servo control plus gravity) was saturated at
  /// a joint's torque limit. The log column `saturated` has the number of saturated joints of
  /// each cycle. Real-time safe: yes.
  std::uint64_t getSaturatedCycleCount() const noexcept { return saturatedCycles_.load(std::memory_order_relaxed); }

  Model3D get3DModel() const override;
  ControlPanel getControlPanel() const override;
  bool getStateSnapshot(StateSnapshot& snapshot) const override;

  /// Waits until the servo loop has run `cycles` more cycles (tests, programs on a simulated clock).
  /// @param[in] cycles  number of cycles
  /// @param[in] timeoutSeconds  longest wait in real time [s]
  /// @return false on time-out or if the loop is not running
  bool waitForCycles(std::uint64_t cycles, double timeoutSeconds = 60) const;
  /// Runs exactly `cycles` more servo cycles: on a SimulatedClock it resumes the clock (pause it
  /// first to start from a known cycle) and pauses it right after the last of them (call its
  /// resume() to go on); on the real clock this waits for them.
  /// @param[in] cycles          number of cycles
  /// @param[in] timeoutSeconds  longest wait in real time [s]
  /// @return false on time-out or if the loop is not running
  bool runCycles(std::uint64_t cycles, double timeoutSeconds = 60);

 protected:
  void enterControl() override;
  /// The read phase of the servo cycle: commands from other threads (power, a new setup), then
  /// the joints (encoders, or the simulation) and the external wrenches. After it, every program
  /// of the executor that calls getJointPosition() from the executor's thread gets this cycle's
  /// reading, without a lock.
  void readInputs() override;
  /// The compute phase: the setpoint, the servo control, gravity, saturation, the limits and the
  /// shutdown's hold.
  void control() override;
  /// The write phase: the torques to the amplifiers (a simulation integrates them at the next
  /// read), then the state for other threads.
  void writeOutputs() override;
  void exitControl() override;
  /// Rebuilds the model and switches simulation and hardware after a change of pose, mount or
  /// simulation mode (see the class comment).
  /// @throws std::logic_error while a trajectory generator or another servo control drives the
  ///         arm, or during or after a shutdown
  /// @throws std::runtime_error switching to the hardware when none is configured, or if the
  ///         servo loop does not take the change within 5 s
  /// @throws IoException if the configured hardware server cannot be reached
  void physicalSetupChanged() override;

 private:
  struct PublishedState {
    double time = 0;
    double readTime = 0;  // the time the cycle's joints hold for
    std::uint64_t cycle = 0;  // the program's cycle count when the cycle published it
    int n = 0;
    bool power = false;
    double missed = 0, saturated = 0;  // servo cycles missed and saturated so far
    double q[kMaxJoints] = {}, qd[kMaxJoints] = {}, tau[kMaxJoints] = {}, qdes[kMaxJoints] = {};
  };
  struct WrenchBox;
  struct PayloadBox;
  struct Setup;  // what is built from the pose and the simulation mode

  enum class SetupResult { kApplied, kShutdown, kDriven, kMoving, kHardwareFailed };
  std::unique_ptr<Setup> makeSetup(bool simulation, const Transform& base) const;
  SetupResult checkSetup(const Setup& setup) const noexcept;  // in the servo thread, before applySetup()
  void install(Setup& setup) noexcept;     // swaps the setup's parts with the manipulator's
  void applySetup(Setup& setup) noexcept;  // in the servo thread between cycles: install and carry the state over
  void applyWrenches(int n);               // the last external wrenches to the simulation
  void addOperatorCommands();              // Power On/Off, Gravity Compensation, Zero Gravity, Hold Here
  void offerLocked(ServoControl& control);  // with offersMutex_ held: offers_ and its command

  bool inServoThread() const;
  void waitUntilNotExecuting(const void* object) const;
  void checkLimits();
  void violation(const char* what, int joint, double value, double limit, const char* unit);
  // Records a fault (printf-style message after the object's name), starts the damped hold and
  // requests the system shutdown; the first fault wins. Real-time safe.
  void fault(const char* format, ...) noexcept __attribute__((format(printf, 2, 3)));
  void holdTorque();
  void gravityWithPayload();  // gravity_ at q_, with the payload's weight
  void saturate() noexcept;  // tau_ within the torque limits; saturatedJoints_ counts the joints
  void powerOffNow() noexcept;
  void finishCycle(double t);
  void holdUntilSafe();
  void publish();
  bool readHardware(double elapsed);
  void writeHardware();
  void writeOutputsOff() noexcept;
  void ioFailure(const char* what, int line);
  std::string noHardwareMessage() const;

  ModelFactory modelFactory_;
  std::unique_ptr<ManipulatorModel> model_;  // servo thread's; other threads use getModel()
  std::atomic<const ManipulatorModel*> modelView_{nullptr};
  std::vector<std::unique_ptr<ManipulatorModel>> retiredModels_;  // kept for references taken earlier
  mutable std::mutex setupMutex_;                                 // one pose, mode or payload change at a time
  std::atomic<Setup*> pendingSetup_{nullptr};                     // for the servo thread to take
  std::atomic<Setup*> appliedSetup_{nullptr};                     // the servo thread took this one
  std::atomic<int> setupResult_{0};                               // and what became of it (SetupResult)
  bool builtForSimulation_ = true;                                // the mode and base the parts were built for
  Transform builtBase_ = Transform::unit();
  std::atomic<bool> usesHardware_{false};
  std::unique_ptr<ManipulatorData> data_;  // servo thread's
  std::unique_ptr<ManipulatorSimulation> sim_;
  // (Before defaultControl_: its destructor releases it, which takes them.)
  mutable std::mutex offersMutex_;     // offers_; held while an offered control is set or released
  std::vector<ServoControl*> offers_;  // the servo controls the operator can switch to
  std::unique_ptr<DefaultPositionControl> defaultControl_;
  std::unique_ptr<WrenchBox> wrench_;
  std::unique_ptr<PayloadBox> payload_;
  std::unique_ptr<IoBoard> board_;  // hardware server client, when simulation mode is off
  double countsPerRadian_ = 20000;
  std::unique_ptr<Differentiator<JointVector>> velocity_;

  std::atomic<ServoControl*> servoControl_{nullptr};
  ServoControl* activeControl_ = nullptr;  // servo thread's: the control last activated (nullptr: activate again)
  std::atomic<TrajectoryGenerator*> generator_{nullptr};
  const TrajectoryGenerator* activeGenerator_ = nullptr;  // servo thread's: the generator of the last cycle
  std::atomic<const void*> executing_{nullptr};  // the control or generator a cycle is running
  std::atomic<bool> powerRequested_{true};
  std::atomic<bool> gravityCompensation_{true};
  std::atomic<bool> zeroGravity_{false};
  std::atomic<bool> holdHere_{false};
  std::atomic<bool> noHardware_{false};  // simulation off, no hardware: unpowered until simulation is on
  std::atomic<bool> loopEnded_{false};   // exitControl() ran: no cycle will complete a hold
  double noHardwareSince_ = -1;          // steady-clock time the no-hardware wait began [s]
  std::atomic<int> shutdownPhase_{0};  // 0 running, 1 damped hold, 2 complete
  std::atomic<std::thread::id> servoThread_{};
  std::atomic<std::uint64_t> pauseAtCycle_{0};
  SimulatedClock* simulatedClock_ = nullptr;  // the loop's clock if simulated (set in enterControl)

  // Servo-thread state.
  JointVector q_, qd_, tau_, gravity_, hold_;
  double payloadMass_ = 0;  // the payload the servo thread took last [kg]
  Vector<3> payloadCentre_ = Vector<3>::Zero();  // its centre in the end-effector frame [m]
  // Writes published to the wrench and payload boxes (each behind a pointer: a cache miss a
  // cycle to look at with hundreds of arms) and how many of them the servo thread has taken: the
  // cycle reads a box only when its two counts differ.
  std::atomic<std::uint64_t> wrenchesSet_{0}, payloadsSet_{0};
  std::uint64_t wrenchesTaken_ = 0, payloadsTaken_ = 0;
  Setpoint setpoint_;
  bool power_ = false;
  double restTime_ = 0, shutdownStart_ = 0;
  double lastCycleTime_ = -1;   // time of the previous cycle (-1 before the first)
  double readTime_ = 0;         // servo thread: the time this cycle's joints hold for
  bool poweredOn_ = false;      // loop: the power came on in this cycle's read phase
  bool readFailed_ = false;     // loop: this cycle's reading is not a number (control() skipped)
  std::int64_t lastSampleTime_ = 0;  // the board's time of the joints last read [ns] (0: none, or not known)
  double saturatedJoints_ = 0;  // log column `saturated`: joints at their torque limit this cycle
  double missedCycles_ = 0;     // log column `missed`: deadlines skipped so far
  std::atomic<std::uint64_t> saturatedCycles_{0};
  char nameBuffer_[64] = {};
  char errorBuffer_[256] = {};

  TripleBuffer<PublishedState> published_;
  PublishedState initial_;
};

}  // namespace rp
