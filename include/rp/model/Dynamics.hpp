#pragma once
/// @file
/// Rigid-body dynamics over a model and a data object: inverse dynamics (recursive
/// Newton-Euler), gravity, mass matrix, Coriolis/centrifugal torques and forward dynamics.

#include "rp/model/ManipulatorData.hpp"

namespace rp {

/// Which effects the dynamics algorithms include.
struct DynamicsOptions {
  bool gravity = true;        ///< gravity of the model
  bool motorInertia = false;  ///< reflected motor inertia \f$G^2 J_m \ddot q\f$
  bool friction = false;      ///< viscous \f$B G^2 \dot q\f$ and Coulomb \f$|G| T_c\f$ friction (joint side)
  /// A wrench (force [N], moment [N m]) that the end-effector's last link exerts on its
  /// environment, in the last link frame; zero for none.
  Vector<6> tipWrench;
};

/// Inverse dynamics by the recursive Newton-Euler algorithm:
/// \f$\tau = M(q)\ddot q + C(q,\dot q)\dot q + g(q) [+ G^2 J_m \ddot q] [+ \tau_f(\dot q)]\f$.
/// @param[in]  model    the manipulator
/// @param[out] data     receives `tau`
/// @param[in]  q        joint angles (n x 1) [rad]
/// @param[in]  qd       joint velocities (n x 1) [rad/s]
/// @param[in]  qdd      joint accelerations (n x 1) [rad/s^2]
/// @param[in]  options  effects to include
/// @return `data.tau` [N m]
/// Real-time safe: yes.
const JointVector& inverseDynamics(const ManipulatorModel& model, ManipulatorData& data, const JointVector& q,
                                   const JointVector& qd, const JointVector& qdd,
                                   const DynamicsOptions& options = DynamicsOptions());

/// The gravity torque \f$g(q)\f$ that holds the arm at rest in `q`, from forward kinematics and
/// sums of link mass moments: \f$g_i = -z_i \cdot ((H_i - M_i o_i) \times g)\f$ for a revolute
/// joint about the line through \f$o_i\f$ along \f$z_i\f$, \f$g_i = -M_i z_i \cdot g\f$ for a
/// prismatic one, with \f$M_i\f$ and \f$H_i\f$ the summed masses and mass moments
/// \f$m_k c_k\f$ of links i..n (the gradient of the potential energy; no Newton-Euler pass).
/// @param[in]  model  the manipulator
/// @param[out] data   receives the forward kinematics of `q` (`linkTransforms`, `endEffector`)
/// @param[in]  q      joint angles (n x 1) [rad]
/// @param[out] tau    gravity torques (n x 1) [N m]
/// Real-time safe: yes.
void gravityTorque(const ManipulatorModel& model, ManipulatorData& data, const JointVector& q, JointVector& tau);

/// The joint friction torque \f$\tau_f = B G^2 \dot q + |G| T_c(\mathrm{sign}\,\dot q)\f$ that the
/// motors must overcome (zero Coulomb part at \f$\dot q = 0\f$).
/// @param[in]  model  the manipulator
/// @param[in]  qd     joint velocities (n x 1) [rad/s]
/// @param[out] tau    friction torques (n x 1) [N m]
/// Real-time safe: yes.
void frictionTorque(const ManipulatorModel& model, const JointVector& qd, JointVector& tau);

/// The Coriolis and centrifugal torques \f$C(q,\dot q)\dot q\f$.
/// @param[in]  model  the manipulator
/// @param[out] data   scratch
/// @param[in]  q      joint angles (n x 1) [rad]
/// @param[in]  qd     joint velocities (n x 1) [rad/s]
/// @param[out] tau    torques (n x 1) [N m]
/// Real-time safe: yes.
void coriolisTorque(const ManipulatorModel& model, ManipulatorData& data, const JointVector& q, const JointVector& qd,
                    JointVector& tau);

/// The joint-space mass matrix \f$M(q)\f$ (symmetric, positive definite), optionally with the
/// reflected motor inertia on its diagonal, by the composite-rigid-body algorithm with spatial
/// vectors in world coordinates: \f$M_{ij} = S_i^T I^c_j S_j\f$ (\f$i \le j\f$) with \f$S\f$ the
/// joints' motion subspaces and \f$I^c_j\f$ the summed inertia of links j..n (an algorithm
/// independent of the Newton-Euler one, which the tests compare it with).
/// @param[in]  model         the manipulator
/// @param[out] data          receives `massMatrix` (n x n) [kg m^2] and the forward kinematics of `q`
/// @param[in]  q             joint angles (n x 1) [rad]
/// @param[in]  motorInertia  add \f$G^2 J_m\f$ to the diagonal
/// @return `data.massMatrix`
/// Real-time safe: yes.
const JointMatrix& massMatrix(const ManipulatorModel& model, ManipulatorData& data, const JointVector& q,
                              bool motorInertia = false);

/// The two parts of the equations of motion \f$M(q)\ddot q + h(q, \dot q) = \tau\f$ that
/// forwardDynamics() solves, without solving them: the mass matrix \f$M\f$ (with motorInertia,
/// including \f$G^2 J_m\f$) and the bias torque \f$h = g(q) + C(q, \dot q)\dot q\f$ plus the
/// other effects in `options` (as forwardDynamics() computes them, so that \f$\tau - h\f$ is the
/// right-hand side it solves, to the last bit). For an integrator that solves its own system with
/// \f$M\f$ (e.g. an Euler step \f$\Delta t\f$ with implicit damping \f$D\f$:
/// \f$(M + \Delta t\,D)\,\dot q^+ = M\dot q + \Delta t\,(\tau - h)\f$) or a controller that
/// needs \f$M\f$ and \f$h\f$ together (computed torque, operational-space control): one
/// forward kinematics for both.
/// @param[in]  model    the manipulator
/// @param[out] data     receives `massMatrix` (n x n) [kg m^2], `bias` (n x 1) [N m or N] and the
///                      forward kinematics of `q`
/// @param[in]  q        joint positions (n x 1) [rad or m]
/// @param[in]  qd       joint velocities (n x 1) [rad/s or m/s]
/// @param[in]  options  effects to include (`gravity`, `motorInertia`, `friction`, `tipWrench`)
/// @return `data.bias` [N m or N]
/// Real-time safe: yes.
const JointVector& massMatrixAndBias(const ManipulatorModel& model, ManipulatorData& data, const JointVector& q,
                                     const JointVector& qd, const DynamicsOptions& options = DynamicsOptions());

/// Forward dynamics: the accelerations \f$\ddot q = M^{-1}(\tau - h(q, \dot q))\f$ that the
/// torques `tau` produce, with \f$h = g(q) + C(q, \dot q)\dot q\f$ plus the effects in `options`
/// (with motorInertia, \f$M\f$ includes \f$G^2 J_m\f$). All in world coordinates after one
/// forward kinematics: \f$g\f$ by the same routine as gravityTorque(), \f$C \dot q\f$ by a
/// Newton-Euler pass on spatial vectors, \f$M\f$ by the composite-rigid-body algorithm as in
/// massMatrix() (massMatrixAndBias() gives these two), and an unpivoted LDL^T solve (\f$M\f$ is
/// positive definite). At an equilibrium (`tau` equal to gravityTorque() of `q`,
/// \f$\dot q = 0\f$) the accelerations are exactly zero, since the same numbers are subtracted;
/// simulations with discontinuous Coulomb friction rely on that. forwardDynamicsArticulatedBody()
/// computes \f$g\f$ differently and leaves rounding residues there.
/// @param[in]  model    the manipulator
/// @param[out] data     receives `qdd`, `massMatrix`, `bias` and the forward kinematics of `q`
/// @param[in]  q        joint positions (n x 1) [rad or m]
/// @param[in]  qd       joint velocities (n x 1) [rad/s or m/s]
/// @param[in]  tau      applied joint torques (n x 1) [N m or N]
/// @param[in]  options  effects to include
/// @return `data.qdd` [rad/s^2 or m/s^2]
/// Real-time safe: yes.
const JointVector& forwardDynamics(const ManipulatorModel& model, ManipulatorData& data, const JointVector& q,
                                   const JointVector& qd, const JointVector& tau,
                                   const DynamicsOptions& options = DynamicsOptions());

/// The same forward dynamics by Featherstone's articulated-body algorithm: O(n), three passes over
/// the links with spatial vectors in world coordinates, no mass matrix (`data.massMatrix` is not
/// touched). Agrees with forwardDynamics() to rounding.
/// @param[in]  model    the manipulator
/// @param[out] data     receives `qdd`
/// @param[in]  q        joint positions (n x 1) [rad or m]
/// @param[in]  qd       joint velocities (n x 1) [rad/s or m/s]
/// @param[in]  tau      applied joint torques (n x 1) [N m or N]
/// @param[in]  options  effects to include
/// @return `data.qdd` [rad/s^2 or m/s^2]
/// Real-time safe: yes.
const JointVector& forwardDynamicsArticulatedBody(const ManipulatorModel& model, ManipulatorData& data,
                                                  const JointVector& q, const JointVector& qd, const JointVector& tau,
                                                  const DynamicsOptions& options = DynamicsOptions());

}  // namespace rp
