#pragma once
/// @file
/// The dynamic simulation of a manipulator's arm: what a manipulator in simulation mode drives.

#include <array>

#include "rp/model/Dynamics.hpp"
#include "rp/model/Kinematics.hpp"

namespace rp {

/// Integrates a manipulator model's forward dynamics under applied joint torques.
///
/// Each step() integrates the rigid-body dynamics with motor inertia and viscous friction by the
/// semi-implicit (symplectic) Euler method; Coulomb friction is applied as a velocity impulse that
/// never reverses the motion, so a joint sticks when the torque is below its Coulomb friction;
/// torques are saturated at the model's torque limits; joints meet their limits as stiff
/// spring-damper stops, with sub-steps while a stop is engaged; and brakes hold every joint while
/// the brakes are on (with a finite braking torque). An external wrench at the end-effector adds \f$J^T F\f$; a wrench at a
/// point on link \f$k\f$ adds \f$J_k(p)^T F\f$, with \f$J_k(p)\f$ the geometric Jacobian of that
/// point (columns of joints beyond \f$k\f$ zero).
///
/// Deterministic: the same inputs give bit-identical states. Nothing allocates after construction.
class ManipulatorSimulation {
 public:
  /// Creates a simulation at rest in `model`'s home position.
  /// @param[in] model  the manipulator model (must outlive the simulation)
  explicit ManipulatorSimulation(const ManipulatorModel& model);

  /// Advances the simulation by `dt` under the joint torques `tau`.
  /// @param[in] tau  motor torques at the joints (n x 1) [N m]
  /// @param[in] dt   time step [s] (> 0)
  /// Real-time safe: yes.
  void step(const JointVector& tau, double dt);

  /// Joint positions (n x 1) [rad]. Real-time safe: yes.
  const JointVector& getPosition() const { return q_; }
  /// Joint velocities (n x 1) [rad/s]. Real-time safe: yes.
  const JointVector& getVelocity() const { return qd_; }
  /// Joint accelerations of the last step (n x 1) [rad/s^2]. Real-time safe: yes.
  const JointVector& getAcceleration() const { return qdd_; }
  /// Puts the arm at rest in `q` [rad]. Real-time safe: yes.
  void setState(const JointVector& q, const JointVector& qd);

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

  /// Stiffness of the joint stops [N m/rad] (default 2e4).
  /// @param[in] stiffness  > 0
  void setStopStiffness(double stiffness) { stopStiffness_ = stiffness; }
  /// Number of sub-steps used in the last step() (1 unless a joint stop was engaged).
  int getLastSubsteps() const { return lastSubsteps_; }

 private:
  void integrate(const JointVector& tau, double h);
  void externalTorque();

  const ManipulatorModel& model_;
  ManipulatorData data_;
  JointVector q_, qd_, qdd_, tauTotal_, tauExt_, coulombPos_, coulombNeg_, brakeTorque_;
  Vector<6> wrench_;
  std::array<Vector<3>, kMaxJoints> linkPoint_{};
  std::array<Vector<6>, kMaxJoints> linkWrench_{};
  int linkWrenches_ = 0;  // number of links with a non-zero wrench
  bool brakes_ = false;
  double stopStiffness_ = 2e4;
  int lastSubsteps_ = 1;
  DynamicsOptions options_;
};

}  // namespace rp
