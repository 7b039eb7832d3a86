#pragma once
/// @file
/// The default servo control: PID on joint position with friction compensation.

#include "rp/control/ServoControl.hpp"
#include "rp/model/ManipulatorModel.hpp"

namespace rp {

/// PID position control with friction compensation (paper section 3.3), the servo control every
/// built-in manipulator creates for the programmer's convenience.
///
/// Per joint \f$i\f$, with \f$e = q_d - q\f$:
/// \f[ \tau_i = K_{p,i} e_i + K_{d,i} (\dot q_{d,i} - \dot q_i) + K_{i,i} \int e_i\,dt
///      + B_i \dot q_{d,i} + F_{c,i} \tanh(\dot q_{d,i} / \epsilon) \f]
/// where \f$B_i\f$ and \f$F_{c,i}\f$ are the model's viscous and Coulomb friction at the joint and
/// \f$\epsilon\f$ = 0.01 rad/s smooths the Coulomb term around zero velocity. The output is
/// limited to the model's torque limits and the integral is clamped so that its term stays within
/// 20 % of them (anti-windup). The manipulator adds the gravity torque when gravity compensation
/// is on (the default for built-in arms).
///
/// Default gains: a critically damped response at \f$\omega_n\f$ = 25 rad/s for each joint's
/// inertia \f$m_i\f$ (the diagonal of the mass matrix with motor inertia at the model's home
/// position): \f$K_p = m_i \omega_n^2\f$, \f$K_d = 2 m_i \omega_n\f$, \f$K_i = K_p \omega_n / 10\f$.
/// The gains are tunable parameters of the manipulator's control program (`kp`, `kd`, `ki`).
class DefaultPositionControl : public ServoControl {
 public:
  /// Creates the control; gains are set when it is attached to a manipulator.
  /// @param[in] name  object name; empty for an automatic name
  explicit DefaultPositionControl(const std::string& name = "");
  /// Stops the manipulator from using this control first.
  ~DefaultPositionControl() override { releaseFromManipulator(); }

  /// Attaches to `manipulator` and sets the default gains for its model (unless set before).
  /// @param[in] manipulator  the manipulator to drive
  void attach(Manipulator& manipulator) override;
  /// Resets the integral (bumpless start). Real-time safe: yes.
  void activate() override;
  /// PID with friction compensation. Real-time safe: yes.
  void calculate() override;

  /// Sets the gains (n x 1 each) [N m/rad], [N m s/rad], [N m/(rad s)].
  /// @param[in] kp  proportional gains
  /// @param[in] kd  derivative gains
  /// @param[in] ki  integral gains
  /// @throws std::invalid_argument on a size mismatch with the attached manipulator or negative gains
  void setGains(const JointVector& kp, const JointVector& kd, const JointVector& ki);
  /// Proportional gains (storage the manipulator registers as tunable parameter `kp`).
  JointVector& getKp() { return kp_; }
  /// Derivative gains (tunable parameter `kd`).
  JointVector& getKd() { return kd_; }
  /// Integral gains (tunable parameter `ki`).
  JointVector& getKi() { return ki_; }
  /// The servo period the integral term integrates over [s]: the manipulator's, taken when the
  /// control is attached and again each time it is activated (so a rate set after attach(), e.g.
  /// by a qmotorConfig file, is the one used).
  double getPeriod() const { return period_; }

  /// Natural frequency of the default gains [rad/s].
  static constexpr double kDefaultBandwidth = 25.0;

 private:
  JointVector kp_, kd_, ki_, integral_, tau_, viscous_, coulombPos_, coulombNeg_, limit_;
  double period_ = 0.001;
  bool gainsSet_ = false;
};

}  // namespace rp
