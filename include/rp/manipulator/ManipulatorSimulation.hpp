#pragma once
/// @file
/// The dynamic simulation of a manipulator's arm: what a manipulator in simulation mode drives.

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>

#include "rp/model/Dynamics.hpp"
#include "rp/model/Kinematics.hpp"

namespace rp {

class ConfigSection;
class SettingSchema;

/// How ManipulatorSimulation integrates the smooth part of the dynamics over a step.
enum class SimulationIntegrator {
  /// Semi-implicit (symplectic) Euler: one forward dynamics per step, first order.
  Euler,
  /// The classical fourth-order Runge-Kutta method on the same dynamics: four forward dynamics per
  /// step; Coulomb friction, brakes and joint stops are then applied as in the Euler step.
  RK4,
};

/// How a simulated plant differs from the model the controller has (rp.cfg's `sim...` settings;
/// see makeSimulation()). The defaults give the nominal plant.
struct PlantDeviations {
  JointVector massScale;     ///< factor on each link's mass (n x 1; empty: all 1)
  JointVector inertiaScale;  ///< factor on each link's inertia tensor about its centre of mass (n x 1; empty: all 1)
  JointVector frictionScale; ///< factor on each joint's viscous and Coulomb friction (n x 1; empty: all 1)
  double payload = 0;        ///< point mass at the tool frame's origin, carried by the last link [kg]
  bool friction = true;      ///< false: no joint friction at all
  bool motorInertia = true;  ///< false: no reflected motor inertia
};

/// Integrates a manipulator model's forward dynamics under applied joint torques: the simulated
/// plant a manipulator in simulation mode drives.
///
/// Each step() integrates the rigid-body dynamics with motor inertia and viscous friction, either
/// by the semi-implicit Euler method or by RK4 (setIntegrator(); RK4 by default). Coulomb friction
/// and engaged brakes act through the full mass matrix, as a constraint: the velocity \f$v^+\f$ at
/// the end of a step minimises \f$\frac12 (v^+ - v^*)^T A (v^+ - v^*) + h \sum_i f_i(v^+_i)\f$,
/// where \f$v^*\f$ is the velocity without them, \f$A\f$ the mass matrix (plus the implicit terms
/// below) and \f$f_i(v) = F^+_i v\f$ for \f$v > 0\f$, \f$-F^-_i v\f$ for \f$v < 0\f$ the friction's
/// dissipation (\f$F^\pm_i\f$ the joint's Coulomb friction, plus its braking torque while the
/// brakes are on). Its optimality conditions are stick and slip exactly: a sliding joint feels
/// \f$F^\pm_i\f$ against its motion, a joint at rest stays there while the torque holding it
/// (which reaches the other joints through \f$M\f$) is within \f$[-F^+_i, F^-_i]\f$. It is solved
/// by exact coordinate descent (a convex problem; bounded iterations, no allocation), each sweep
/// followed by the exact solution of the contact mode it reached (which joints stick, which way the
/// others slide: a linear system) when that mode is new after the first sweep or unchanged by a
/// later one; the first such solution that satisfies the optimality conditions ends the sweeps
/// (usually after one).
///
/// Torques are saturated at the model's torque limits. Joints meet their limits as stiff
/// spring-damper stops (setStopStiffness()), critically damped for the inertia of the joint at the
/// stop, with the spring, the damper and viscous friction implicit in the velocity (backward Euler:
/// stable and dissipative for any inertia); while a stop is engaged a step is taken by the Euler
/// method in sub-steps sized from the stop's frequency on that joint. Brakes hold every joint while
/// the brakes are on (with a finite braking torque). An external wrench at the end-effector adds
/// \f$J^T F\f$; a wrench at a point on link \f$k\f$ adds \f$J_k(p)^T F\f$, with \f$J_k(p)\f$ the
/// geometric Jacobian of that point (columns of joints beyond \f$k\f$ zero).
///
/// The plant may differ from the model the controller has (PlantDeviations; the simulation then
/// owns its own model), and its joints are read through simulated sensors: getPosition() and
/// getVelocity() give the readings (quantised to the encoder resolution, delayed by a number of
/// steps, see setSensor()), getTruePosition() and getTrueVelocity() the plant's state.
///
/// A payload changed at run time (setPayload(): a gripper grasping or releasing a work piece) is
/// a point mass on the last link, in addition to PlantDeviations::payload. The dynamics are linear
/// in the links' inertial parameters, so its part is its mass times that of a unit point mass at
/// its centre: the simulation adds \f$m M_u(q)\f$ to the mass matrix and \f$m h_u(q, \dot q)\f$
/// (gravity, Coriolis and centrifugal) to the bias torques, both from a model of the same chain
/// with massless links and 1 kg at the centre (built by setPayload(), in the caller's thread).
/// The result is the plant a PlantDeviations payload at that point gives, to rounding.
///
/// Deterministic: the same inputs give bit-identical states. Nothing allocates after construction
/// (except setPayload() with a centre not used before, in its caller's thread).
class ManipulatorSimulation {
 public:
  /// Largest sensor delay [steps].
  static constexpr int kMaxSensorDelay = 16;
  /// Largest number of different payload centres setPayload() accepts over the simulation's life.
  static constexpr int kMaxPayloadCentres = 16;

  /// Creates a simulation at rest in `model`'s home position, of the nominal plant.
  /// @param[in] model  the manipulator model (must outlive the simulation)
  explicit ManipulatorSimulation(const ManipulatorModel& model);
  /// Creates a simulation at rest in `nominal`'s home position of a plant that differs from it:
  /// the simulation builds and owns the plant's model; `nominal` is not changed.
  /// @param[in] nominal     the model the controller has (read only during construction)
  /// @param[in] deviations  how the plant differs
  /// @throws std::invalid_argument on a deviation vector that has neither 0 nor n entries, or a
  ///         factor that is not positive and finite (friction: not negative), or a negative payload
  ManipulatorSimulation(const ManipulatorModel& nominal, const PlantDeviations& deviations);
  ~ManipulatorSimulation();
  ManipulatorSimulation(const ManipulatorSimulation&) = delete;             ///< not copyable
  ManipulatorSimulation& operator=(const ManipulatorSimulation&) = delete;  ///< not copyable

  /// Declares the rp.cfg settings makeSimulation() reads (a manipulator's declareSettings()
  /// calls it).
  /// @param[in,out] schema  the class's schema
  static void declareSettings(SettingSchema& schema);

  /// Advances the simulation by `dt` under the joint torques `tau`, and takes one sensor reading.
  /// @param[in] tau  motor torques at the joints (n x 1) [N m]
  /// @param[in] dt   time step [s] (> 0)
  /// Real-time safe: yes.
  void step(const JointVector& tau, double dt);
  /// Longest step advance() takes over skipped deadlines, in periods.
  static constexpr int kCatchUpStepPeriods = 4;
  /// Longest time advance() integrates, in periods (a longer gap, such as a stop in a debugger,
  /// integrates this much of it).
  static constexpr int kMaxCatchUpPeriods = 1000;
  /// Advances the simulation by the time `elapsed` that passed since the last step of a servo loop
  /// of period `period`, under the joint torques `tau` (that loop's last output): one step of
  /// exactly `period` when `elapsed` is under 1.5 periods, as in a cycle on time; otherwise (a
  /// cycle that skipped deadlines: the arm moved on under the last torque meanwhile) the fewest
  /// equal steps of at most kCatchUpStepPeriods periods that cover `elapsed` (at most
  /// kMaxCatchUpPeriods periods of it). A late cycle then costs a step, not one step per skipped
  /// deadline: a servo loop loaded near its period recovers from an overrun instead of overrunning
  /// again to catch up. The sensors still take one reading per period (a step of several periods
  /// gives the ones within it interpolated between its start and its end), so that a sensor delay
  /// (setSensor()) stays that many periods.
  /// @param[in] tau      motor torques at the joints (n x 1) [N m]
  /// @param[in] elapsed  time since the last step [s]
  /// @param[in] period   the servo period [s] (> 0 and finite)
  /// @return the number of steps taken
  /// @throws std::invalid_argument for a period that is not positive and finite
  /// Real-time safe: yes.
  int advance(const JointVector& tau, double elapsed, double period);

  /// Joint positions as the simulated encoders read them (n x 1) [rad]: the plant's, quantised to
  /// the encoder resolution and as old as the sensor delay (see setSensor()); the true positions
  /// without them. Real-time safe: yes.
  const JointVector& getPosition() const { return readings_[readIndex()].position; }
  /// Joint velocities as read (n x 1) [rad/s]: the plant's, as old as the sensor delay (not
  /// quantised). Real-time safe: yes.
  const JointVector& getVelocity() const { return readings_[readIndex()].velocity; }
  /// The plant's joint positions (n x 1) [rad]. Real-time safe: yes.
  const JointVector& getTruePosition() const { return q_; }
  /// The plant's joint velocities (n x 1) [rad/s]. Real-time safe: yes.
  const JointVector& getTrueVelocity() const { return qd_; }
  /// Joint accelerations at the start of the last step (or sub-step) (n x 1) [rad/s^2]: the
  /// forward dynamics under the applied and external torques, gravity, viscous friction and the
  /// stops' springs, before Coulomb friction and brakes. The Euler step does not need them: they
  /// are solved for on the first call after it, in the thread that steps the arm. Real-time safe:
  /// yes (from the stepping thread).
  const JointVector& getAcceleration() const;
  /// Puts the arm in `q` [rad] with velocities `qd` [rad/s]; the sensors read that state
  /// (their delay line is filled with it). Real-time safe: yes.
  void setState(const JointVector& q, const JointVector& qd);

  /// Sets the simulated sensors. Real-time safe: no.
  /// @param[in] countsPerRadian  encoder resolution per joint [counts/rad] (n x 1, each > 0, or
  ///                             infinite for exact readings); empty: exact readings
  /// @param[in] delay            readings between the plant's state and its reading
  ///                             (0..kMaxSensorDelay): one reading per step(), one per period in
  ///                             advance()
  /// @throws std::invalid_argument on a wrong size, a resolution that is not positive, or a delay
  ///         out of range
  void setSensor(const JointVector& countsPerRadian, int delay);
  /// The sensor delay [steps].
  int getSensorDelay() const { return delay_; }
  /// Sets each joint's encoder offset: the reading is the plant's position plus the offset (then
  /// quantised), as with an encoder zeroed away from the model's zero. setState() and
  /// getTruePosition() keep the plant's positions. Real-time safe: no.
  /// @param[in] offset  per joint (n x 1) [rad or m], finite
  /// @throws std::invalid_argument on a wrong size or a value that is not finite
  void setEncoderOffset(const JointVector& offset);
  /// Each joint's encoder offset [rad or m] (zero by default).
  const JointVector& getEncoderOffset() const { return encoderOffset_; }

  /// Selects the integrator (takes effect at the next step). Real-time safe: yes.
  /// @param[in] integrator  Euler or RK4
  void setIntegrator(SimulationIntegrator integrator) { integrator_ = integrator; }
  /// The integrator.
  SimulationIntegrator getIntegrator() const { return integrator_; }

  /// The plant's model: the one given to the constructor, or the simulation's own with deviations.
  const ManipulatorModel& getModel() const { return model_; }

  /// Engages (true) or releases (false) the brakes. Engaged brakes act as real ones do: the
  /// motors are off (the applied torques are ignored) and each joint's brake opposes its motion
  /// with at most its braking torque (see setBrakeTorque()), so a moving arm stops over a finite
  /// time and distance and an arm at rest is held while the load on each joint (gravity, external
  /// wrenches) stays below its braking torque. Real-time safe: yes.
  void setBrakes(bool on) { brakes_ = on; }
  /// Whether the brakes are engaged.
  bool getBrakes() const { return brakes_; }
  /// Sets each joint's braking torque [N m] (n x 1, each > 0). Default: the joint's torque limit.
  /// @throws std::invalid_argument on a wrong size or a value that is not positive and finite
  void setBrakeTorque(const JointVector& torque);
  /// Each joint's braking torque [N m].
  const JointVector& getBrakeTorque() const { return brakeTorque_; }

  /// Sets the wrench the environment applies to the end-effector, in world coordinates: force
  /// [N] then moment [N m] about the end-effector's origin; zero for none. Real-time safe: yes.
  void setExternalWrench(const Vector<6>& wrench) { wrench_ = wrench; }
  /// The external wrench. Real-time safe: yes.
  const Vector<6>& getExternalWrench() const { return wrench_; }
  /// Sets the wrench the environment applies at a point on link `link` until changed: force [N]
  /// then moment [N m], in world coordinates, the force acting at `point`; zero for none. It adds
  /// \f$J_k(p)^T F\f$ to the joint torques, where \f$J_k(p)\f$ is the geometric Jacobian of the
  /// point (so joints beyond the link feel nothing of it). One wrench per link.
  /// @param[in] link    link number, 1..n (link k moves with joints 1..k)
  /// @param[in] point   point of application in link k's frame (the frame whose pose is
  ///                    `linkTransforms[k-1]` of ManipulatorData; it moves with the link) [m]
  /// @param[in] wrench  force [N] and moment [N m] (6 x 1), world coordinates
  /// @throws std::out_of_range if `link` is not in 1..n
  /// Real-time safe: yes.
  void setExternalLinkWrench(int link, const Vector<3>& point, const Vector<6>& wrench);
  /// Removes the wrenches on all links (not the end-effector's). Real-time safe: yes.
  void clearExternalLinkWrenches();
  /// Joint torques [N m] (n x 1) that the external wrenches produced in the last step (taken at
  /// the positions the step started from). Real-time safe: yes.
  const JointVector& getExternalTorque() const { return tauExt_; }

  /// Sets the payload the arm carries from the next step() on: a point mass at `centre` in the
  /// end-effector (tool) frame, carried by the last link (in addition to PlantDeviations::payload).
  /// May be called from any thread while another one steps the simulation: the stepping thread
  /// takes the new payload at the start of a step, without a lock or an allocation (see the class
  /// comment). Calls are serialised among themselves.
  /// @param[in] mass    payload mass [kg] (0: none)
  /// @param[in] centre  centre of mass in the end-effector frame [m]
  /// @throws std::invalid_argument for a negative or non-finite mass or a non-finite centre
  /// @throws std::length_error for a centre beyond the kMaxPayloadCentres different ones kept
  /// Real-time safe: no (a centre not used before builds a model).
  void setPayload(double mass, const Vector<3>& centre = Vector<3>::Zero());
  /// The payload mass the last step() used [kg] (0 before the first step). Real-time safe: yes.
  double getPayloadMass() const { return stepMass_; }

  /// Stiffness of the joint stops [N m/rad] (default 2e4).
  /// @param[in] stiffness  > 0
  void setStopStiffness(double stiffness) { stopStiffness_ = stiffness; }
  /// Number of sub-steps used in the last step() (1 unless a joint stop was engaged).
  int getLastSubsteps() const { return lastSubsteps_; }

 private:
  void init();
  void eulerStep(double h);
  void rk4Step(double h);
  void solveFriction(double h);
  void integrate(const JointVector& tau, double dt);  // step() without its sensor reading
  void pushReading(const JointVector& q, const JointVector& qd);  // the ring's next reading
  // The oldest reading of the ring (slots 0..delay_), the one the sensor delay gives.
  std::size_t readIndex() const { return static_cast<std::size_t>(head_ == delay_ ? 0 : head_ + 1); }
  void externalTorque();
  void takePayload() noexcept;  // the payload of setPayload(), at the start of a step
  // The plant's dynamics at (q, qd) under tau, with the payload, in the stepping thread's
  // workspace: its massMatrix, and in its qdd the accelerations (solve) or the right-hand side
  // tau - h that gives them.
  void dynamics(const JointVector& q, const JointVector& qd, const JointVector& tau, bool solve);
  const JointMatrix& plantMassMatrix();   // the mass matrix at q_ with motor inertia and the payload

  // What every step reads and writes comes first, and what only some steps use (a payload, link
  // wrenches, a sensor delay) last: with hundreds of arms in one servo cycle, the pages and cache
  // lines an arm's step touches are the cost (docs/realtime.md). The steps' scratch (the
  // integrators', the friction problem's, the payload's) is not here but the stepping thread's
  // (ManipulatorSimulation.cpp): it stays in that thread's caches from one arm to the next.
  std::unique_ptr<const ManipulatorModel> own_;  // the plant's model when it deviates (before model_)
  const ManipulatorModel& model_;
  JointVector q_, qd_, tauExt_, tauApplied_, coulombPos_, coulombNeg_, brakeTorque_, viscous_;
  // The last Euler step's start (q, qd, torque: columns of n rows, contiguous), from which
  // getAcceleration() solves for the accelerations when accelerationPending_.
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::ColMajor, kMaxJoints, 3> stepStart_;
  bool accelerationPending_ = false;
  std::array<bool, kMaxJoints> engaged_{};  // joints whose stop acts in the current Euler step
  Vector<6> wrench_;
  int linkWrenches_ = 0;  // number of links with a non-zero wrench
  bool brakes_ = false;
  bool hasCoulomb_ = false;
  double stopStiffness_ = 2e4;
  int lastSubsteps_ = 1;
  SimulationIntegrator integrator_ = SimulationIntegrator::RK4;
  DynamicsOptions options_;
  double stepMass_ = 0;      // the payload of the current step [kg]
  int stepCentre_ = -1;      // its unit model (index into Payload's), -1: none
  // setPayload() calls published, and how many of them the steps have taken: a step looks at the
  // hand-over (a cache line of its own, behind a pointer) only when the two differ.
  std::atomic<std::uint64_t> payloadsSet_{0};
  std::uint64_t payloadsTaken_ = 0;
  // Sensors: a ring of the last delay_ + 1 readings (slots 0..delay_); head_ is the newest. Without
  // a delay every step writes and reads slot 0.
  JointVector countsPerRadian_, encoderOffset_;
  int delay_ = 0;
  int head_ = 0;
  struct Reading {
    JointVector position, velocity;
  };
  std::array<Reading, kMaxSensorDelay + 1> readings_{};
  ManipulatorData data_;  // its per-link arrays are used from the start (links 1..n)

  struct Payload;  // the unit point-mass models by centre and the hand-over
  std::unique_ptr<Payload> payload_;
  JointVector zero_;  // zero accelerations (the payload's bias torques)
  JointVector qdd_;  // the accelerations getAcceleration() returns
  std::array<Vector<3>, kMaxJoints> linkPoint_{};
  std::array<Vector<6>, kMaxJoints> linkWrench_{};
};

/// Creates the simulated plant of a manipulator from its rp.cfg section (which may be null): the
/// nominal `model`, or a plant that deviates from it as the section's `sim...` settings say, with
/// the section's `integrator`, sensors and initial state. The controller keeps `nominal`.
/// @param[in] nominal  the controller's model (must outlive the simulation when it has no deviations)
/// @param[in] section  the manipulator's rp.cfg section, or nullptr
/// @return the simulation
/// @throws ConfigError naming the file and line of a setting with the wrong number of values
///         for the arm's joints, or a value the plant cannot take
std::unique_ptr<ManipulatorSimulation> makeSimulation(const ManipulatorModel& nominal, const ConfigSection* section);

}  // namespace rp
