#pragma once
/// @file
/// The generic manipulator interface (paper sections 3.3 and 3.6, Figure 10).

#include <Eigen/Core>

#include <string>

#include "rp/core/PhysicalObject.hpp"
#include "rp/model/ManipulatorModel.hpp"

namespace rp {

class ServoControl;
class TrajectoryGenerator;
struct Setpoint;

/// A manipulator with any number of joints: the interface that generic programs use (paper
/// section 3.6), whatever the arm (Puma560, WAM, UrdfManipulator, ...).
///
/// A manipulator is only the interface to the arm: its servo control (a ServoControl) and its
/// trajectory generator (a TrajectoryGenerator) are separate objects connected to it and
/// switchable at any time (paper Figure 8).
///
/// Threads: the methods marked "servo thread" are for ServoControl::calculate(); called from any
/// other thread, the state getters return the latest state the servo loop published.
class Manipulator : public PhysicalObject {
 public:
  /// Creates the manipulator.
  /// @param[in] name  object name; empty for an automatic name
  explicit Manipulator(const std::string& name = "") : PhysicalObject(name) {}
  /// Disconnects the trajectory generator and the servo controls that refer to this manipulator.
  ~Manipulator() override;

  /// The kinematic and dynamic model. Real-time safe: yes.
  virtual const ManipulatorModel& getModel() const = 0;
  /// Number of joints. Real-time safe: yes.
  int getNumberOfJoints() const { return getModel().getNumberOfJoints(); }
  /// Period of the servo loop [s]. Real-time safe: yes.
  virtual double getServoPeriod() const = 0;

  /// @name Joint state
  /// @{

  /// Joint positions (n x 1) [rad]. Real-time safe: yes.
  virtual JointVector getJointPosition() const = 0;
  /// Joint velocities (n x 1) [rad/s]. Real-time safe: yes.
  virtual JointVector getJointVelocity() const = 0;
  /// The setpoint of the current cycle (n x 1 each): a reference to the servo thread's own, for
  /// that thread (a ServoControl's calculate()); another thread that reads it races with the
  /// cycle that writes it. Real-time safe: yes.
  virtual const Setpoint& getSetpoint() const = 0;
  /// The setpoint's position (n x 1) [rad] for any thread: in the servo thread this cycle's, in
  /// another the one the last servo cycle published (a consistent copy). Real-time safe: yes.
  virtual JointVector getDesiredJointPosition() const = 0;
  /// The control output (joint torques) last written (n x 1) [N m]. Real-time safe: yes.
  virtual JointVector getControlOutput() const = 0;
  /// Sets this cycle's control output: joint torques [N m] (servo thread).
  /// @param[in] torque  one value per joint
  /// @throws MathException if the size is not the number of joints
  /// Real-time safe: yes.
  virtual void setControlOutput(const Eigen::Ref<const Eigen::VectorXd>& torque) = 0;
  /// @}

  /// @name Arm power
  /// @{

  /// Switches the arm power on (motors enabled, brakes released); the arm holds its position.
  virtual void enableArmPower() = 0;
  /// Switches the arm power off (brakes engaged, no torque).
  virtual void disableArmPower() = 0;
  /// Whether the arm power is on. Real-time safe: yes.
  virtual bool isArmPowerOn() const = 0;
  /// @}

  /// @name Kinematics
  /// @{

  /// Pose of the end-effector in the world for the current joint positions [m].
  /// Real-time safe: yes in the servo thread.
  virtual Transform getEndEffectorTransform() const = 0;
  /// The same as getEndEffectorTransform() (the paper's Figure 22 spells it this way).
  Transform getEndEffectorPosition() const { return getEndEffectorTransform(); }
  /// World pose of one of the arm's frames at the current joint positions [m]: `base` (the
  /// model's base frame), `link1` to `linkN` (the frame of each link) or `endEffector`; other
  /// objects are mounted on these (setConnection()).
  /// @param[in] frame  frame name
  /// @throws std::invalid_argument if the arm has no such frame
  /// Real-time safe: no.
  Transform getFrameTransform(const std::string& frame) const override;
  /// Joint torques that make the end-effector exert `force` (3: force [N]; 6: force and moment
  /// [N m]), in world coordinates, at the joint positions `q`: \f$\tau = J(q)^T F\f$.
  /// @param[in]  q       joint positions (n x 1) [rad]
  /// @param[in]  force   force (3 x 1) or wrench (6 x 1)
  /// @param[out] torque  joint torques (n x 1) [N m]
  /// @throws MathException on wrong sizes
  /// Real-time safe: yes in the servo thread.
  virtual void endEffectorForceToJointTorque(const Eigen::Ref<const Eigen::VectorXd>& q,
                                             const Eigen::Ref<const Eigen::VectorXd>& force,
                                             Eigen::Ref<Eigen::VectorXd> torque) const = 0;
  /// @}

  /// @name Servo control and trajectory generation
  /// @{

  /// Connects a trajectory generator; the manipulator follows its setpoints from the next cycle.
  /// Bumpless: that cycle holds the arm where it is, and the generator's first call gets this
  /// hold (not an older one) as the setpoint it starts from.
  /// @param[in] generator  the generator (must outlive the connection)
  virtual void setTrajectoryGenerator(TrajectoryGenerator& generator) = 0;
  /// Disconnects the trajectory generator; the manipulator holds its current setpoint.
  virtual void clearTrajectoryGenerator() = 0;
  /// The connected trajectory generator, or nullptr.
  virtual TrajectoryGenerator* getTrajectoryGenerator() const = 0;
  /// Switches to another servo control between two cycles.
  /// @param[in] control  the servo control (must outlive its use)
  virtual void setServoControl(ServoControl& control) = 0;
  /// The servo control in use.
  virtual ServoControl& getServoControl() const = 0;
  /// Adds the model's gravity torque to the servo control's output.
  virtual void setGravityCompensationOn() = 0;
  /// Stops adding the gravity torque.
  virtual void setGravityCompensationOff() = 0;
  /// Whether gravity compensation is on. Real-time safe: yes.
  virtual bool isGravityCompensationOn() const = 0;
  /// Zero-gravity mode: output only the gravity torque (the servo control and the trajectory
  /// generator are bypassed from the next cycle), so the arm floats and can be pushed around (the
  /// Teachpendant uses it); an arm in motion goes on under its own momentum, without a jump.
  virtual void setZeroGravityModeOn() = 0;
  /// Leaves zero-gravity mode; the servo control takes over at the current position, starting
  /// afresh. A trajectory generator still set drives the arm again with its setpoint for that
  /// time: clear it before to keep the arm where it was pushed to.
  virtual void setZeroGravityModeOff() = 0;
  /// Whether zero-gravity mode is on. Real-time safe: yes.
  virtual bool isZeroGravityModeOn() const = 0;
  /// Stops using `control` (its destructor calls this): switches to the default servo control if
  /// `control` is in use and returns once no servo cycle runs it. Real-time safe: no.
  /// @param[in] control  a servo control about to be destroyed
  virtual void releaseServoControl(ServoControl& control) = 0;
  /// Stops using `generator` (its destructor calls this): holds the current position and returns
  /// once no servo cycle runs it. Real-time safe: no.
  /// @param[in] generator  a trajectory generator about to be destroyed
  virtual void releaseTrajectoryGenerator(TrajectoryGenerator& generator) = 0;
  /// @}

  /// @name Simulation
  /// @{

  /// In simulation mode: sets the wrench the environment applies to the end-effector, in world
  /// coordinates (force [N], moment [N m] about the end-effector origin), until changed.
  /// @param[in] wrench  (6 x 1); zero for none
  virtual void applyExternalWrench(const Vector<6>& wrench) = 0;
  /// Removes the external wrench at the end-effector.
  void clearExternalWrench() { applyExternalWrench(Vector<6>()); }
  /// In simulation mode: sets the wrench the environment applies at a point on link `link`, in
  /// world coordinates (the force acts at `point`; the moment is a pure couple), until changed.
  /// The simulation adds \f$J_k(p)^T F\f$ to the joint torques, with \f$J_k(p)\f$ the geometric
  /// Jacobian of the point, so joints beyond link k feel nothing of it directly. One wrench per
  /// link; it adds to the end-effector's wrench. Callable from any thread; takes effect in the next
  /// servo cycle (the servo thread never waits for it).
  /// @param[in] link    link number, 1..n (link k moves with joints 1..k; link n carries the tool)
  /// @param[in] point   point of application in link k's frame (DH frame k, which moves with the
  ///                    link; its pose is `linkTransforms[k-1]` of ManipulatorData) [m]
  /// @param[in] wrench  force [N] then moment [N m] (6 x 1), world coordinates; zero for none
  /// @throws std::out_of_range if `link` is not in 1..n
  virtual void applyExternalWrench(int link, const Vector<3>& point, const Vector<6>& wrench) = 0;
  /// Removes the external wrench on link `link` (1..n).
  /// @param[in] link  link number
  /// @throws std::out_of_range if `link` is not in 1..n
  void clearExternalWrench(int link) { applyExternalWrench(link, Vector<3>(), Vector<6>()); }
  /// @}

 protected:
  /// Records that this manipulator calls `generator` (derived classes call it when connecting).
  /// @param[in] generator  the generator
  void connectGenerator(TrajectoryGenerator& generator);
  /// Records that this manipulator no longer calls `generator`.
  /// @param[in] generator  the generator
  void disconnectGenerator(TrajectoryGenerator& generator);
};

}  // namespace rp
