#pragma once
/// @file
/// The identification behind rp-calibrate: the gravity regressor of a manipulator model, its base
/// (identifiable) parameters, the excitation plan, and the least-squares fits of the encoder
/// offsets, the gravity parameters and the joint friction from logged torques.
///
/// Model of a logged torque on a moving joint i (rows of joints at rest are not used: a joint that
/// sticks holds any torque within its Coulomb band):
/// \f[
///   \tau_i = [C(q,\dot q)\dot q]_i + Y_i(q - \delta)\,\theta + F_{v,i}\dot q_i + F_{c,i}\,\mathrm{sign}(\dot q_i) + a_i
/// \f]
/// with \f$q\f$ the joints as read, \f$\delta\f$ the encoder offsets (reading minus true angle),
/// \f$Y\theta\f$ the gravity torque, linear in each link's first mass moments \f$\theta_k = (m_k,
/// m_k c_{k,x}, m_k c_{k,y}, m_k c_{k,z})\f$ (centre of mass in link frame k), \f$F_v\f$ viscous and
/// \f$F_c\f$ Coulomb friction (joint side; the model's \f$B G^2\f$ and the mean of \f$|G| T_c^\pm\f$)
/// and \f$a_i\f$ half the Coulomb asymmetry \f$(|G| T_c^+ - |G| |T_c^-|) / 2\f$. Only samples at a
/// constant setpoint velocity are logged; the small inertial torque of the servo's tracking errors,
/// \f$M(q) \ddot q\f$ with the model's mass matrix (and motor inertia), is subtracted with the
/// Coriolis torque.

#include <Eigen/Dense>

#include <string>
#include <vector>

#include "rp/model/Model.hpp"

namespace rp::calibration {

/// One logged servo cycle on a constant-velocity part of the plan: the torque applied from one
/// reading of the joints to the next, with the state in the middle of that step (the mean of the
/// two readings) and the mean acceleration over it (their velocities' difference over the period).
struct Sample {
  JointVector q;    ///< joint positions as read [rad or m]
  JointVector qd;   ///< joint velocities as read [rad/s or m/s]
  JointVector qdd;  ///< joint accelerations over the servo cycle [rad/s^2 or m/s^2]
  JointVector tau;  ///< torques the servo loop applied over that cycle [N m or N]
};

/// Number of standard gravity parameters: 4 per link (m, m cx, m cy, m cz).
/// @param[in] model  the manipulator model
/// @return 4 n
int gravityParameterCount(const ManipulatorModel& model);

/// Name of standard gravity parameter `k`: `m3`, `mcx3`, `mcy3` or `mcz3` for link 3.
/// @param[in] k  0 .. gravityParameterCount() - 1
/// @return the name
std::string gravityParameterName(int k);

/// The model's standard gravity parameters: per link m, m cx, m cy, m cz [kg, kg m].
/// @param[in] model  the manipulator model (without mimic joints)
/// @return 4 n values
Eigen::VectorXd gravityParameters(const ManipulatorModel& model);

/// The gravity regressor \f$Y(q)\f$ (n x 4n): gravityTorque(model, q) = Y(q) gravityParameters(model),
/// exactly, for any masses and centres of mass. Computed analytically after one forward
/// kinematics: for a revolute joint i about the line through \f$o_i\f$ along \f$z_i\f$ and a link
/// k >= i with world pose \f$(R_k, p_k)\f$, the column of \f$m_k\f$ is
/// \f$-(p_k - o_i)\cdot(g \times z_i)\f$ and the columns of \f$m_k c_k\f$ are
/// \f$-R_k^T (g \times z_i)\f$; for a prismatic joint \f$-z_i \cdot g\f$ and 0.
/// @param[in]  model  the manipulator model (without mimic joints)
/// @param[out] data   scratch (receives the forward kinematics)
/// @param[in]  q      joint positions (n x 1)
/// @param[out] Y      the regressor (resized to n x 4n)
void gravityRegressor(const ManipulatorModel& model, ManipulatorData& data, const JointVector& q, Eigen::MatrixXd& Y);

/// Which combinations of the standard gravity parameters the gravity torque determines.
struct BaseParameters {
  std::vector<int> base;            ///< standard parameters kept as base parameters
  std::vector<int> dependent;       ///< parameters that only act through the base ones
  std::vector<int> unidentifiable;  ///< parameters that never change the gravity torque
  /// (base x dependent): base parameter b stands for \f$\theta_b + \sum_d K_{bd} \theta_d\f$.
  Eigen::MatrixXd K;
  /// The combination base parameter `b` (0 .. base.size() - 1) stands for, e.g. `mcx2 + 0.4318 m3`.
  /// @param[in] b  index into `base`
  /// @return a readable expression
  std::string expression(int b) const;
  /// The base parameters' values for standard parameters `theta`: \f$\theta_b + K \theta_d\f$.
  /// @param[in] theta  standard parameters (4n)
  /// @return base.size() values
  Eigen::VectorXd project(const Eigen::VectorXd& theta) const;
};

/// Finds the base parameters of `model`'s gravity torque: QR with column pivoting of the stacked
/// regressor at `poses` random configurations within the joint limits (fixed seed). Columns
/// whose norm is below 1e-9 of the largest are unidentifiable; of the others, those beyond the
/// numerical rank (relative tolerance 1e-8) are dependent.
/// @param[in] model  the manipulator model (without mimic joints)
/// @param[in] poses  number of random configurations (>= 1)
/// @return the partition and the combination matrix
BaseParameters findBaseParameters(const ManipulatorModel& model, int poses = 200);

/// What the plan does and how fast.
struct PlanOptions {
  int poses = 8;              ///< poses passed through slowly in both directions (gravity, offsets)
  double passAmplitude = 0.06;  ///< each pass runs from pose - a to pose + a on every joint [rad or m]
  double passSpeed = 0.1;     ///< speed of the passes [rad/s or m/s], capped at 0.5 of each joint's limit
  std::vector<double> sweepSpeeds{0.15, 0.4, 0.8};  ///< friction sweeps per joint [rad/s or m/s], capped at 0.5 of the limit
  double sweepRange = 0.5;    ///< each friction sweep covers at most the middle pose +- this [rad or m]
  unsigned seed = 1;          ///< seed of the random poses
};

/// One motion of the plan: from the previous target to `target`, synchronised in time, at most
/// `vmax` per joint; its constant-velocity part is logged when `log` is true.
struct PlanSegment {
  JointVector target;  ///< where the motion ends
  JointVector vmax;    ///< speed limit per joint for this motion
  bool log = false;    ///< log its constant-velocity samples
  std::string what;    ///< e.g. "pose 3 +" or "joint 2 sweep 0.40 rad/s -"
};

/// The excitation plan: move to each of `options.poses` random poses (kept 15 % of each joint's
/// range inside its limits) and pass through it slowly on all joints, up and down; then for each
/// joint, at the middle of the joint ranges (or else at the home position), constant-velocity
/// sweeps at each speed of `options.sweepSpeeds`, up and down (kept 10 % of the range inside the
/// limits). Every motion keeps the model's gravity torque within 60 % of each joint's torque
/// limit along its path (the first only at its end: it starts where the arm is held; poses are
/// drawn again, sweeps shortened). Transfers between the logged motions run at 0.3 of the
/// velocity limits.
/// @param[in] model    the manipulator model (limits)
/// @param[in] options  sizes and speeds
/// @return the segments in order; the first starts where the arm is
/// @throws std::invalid_argument on non-positive sizes or speeds
/// @throws std::runtime_error when no pose or sweep keeps within the torque limits
std::vector<PlanSegment> makePlan(const ManipulatorModel& model, const PlanOptions& options);

/// An identified value with its standard error and the model's (nominal) value.
struct Estimate {
  double value = 0;    ///< identified
  double stdError = 0; ///< standard error (from the residual variance and \f$(A^T A)^{-1}\f$)
  double nominal = 0;  ///< the model's value
  /// The largest error a systematic (unmodelled, not random) torque error of the fit's residual
  /// size can cause: by Cauchy-Schwarz \f$\|e\| \sqrt{[(A^T A)^{-1}]_{kk}}\f$ with
  /// \f$\|e\| = \sqrt{N}\f$ times the residual's rms, i.e. \f$\sqrt{N}\f$ standard errors.
  double resolution = 0;
};

/// Everything rp-calibrate identifies.
struct Result {
  std::vector<Estimate> offset;           ///< encoder offsets per joint (reading - true) [rad or m]
  std::vector<bool> offsetObservable;     ///< false: the gravity torque does not depend on it (left at 0)
  std::vector<bool> offsetSeparable;      ///< false: it equals a change of the base parameters (found with the model's masses)
  /// How much the gravity torque changes per radian of each offset (rms over the rows, the
  /// friction's share taken out) [N m/rad]; 0 when not observable.
  std::vector<double> offsetSensitivity;
  double offsetResidualRms = 0;           ///< torque residual of the offset fit [N m]
  BaseParameters baseParameters;          ///< the partition the gravity fit used
  std::vector<Estimate> gravity;          ///< base gravity parameters, in the order of baseParameters.base
  std::vector<Estimate> viscous;          ///< F_v per joint [N m s/rad]
  std::vector<Estimate> coulomb;          ///< F_c per joint (mean of both directions) [N m]
  std::vector<Estimate> asymmetry;        ///< a per joint: half of F_c+ minus F_c- [N m]
  std::vector<int> rowsPerJoint;          ///< moving-joint rows used per joint
  double residualRms = 0;                 ///< torque residual of the final fit [N m]
  int offsetIterations = 0;               ///< Gauss-Newton iterations of the offset fit
};

/// Fits the logged samples. Step 1 (when `fitOffsets`): Gauss-Newton on the offsets with the
/// model's gravity parameters, friction free (linear), the offsets whose gravity column is
/// (numerically) zero left at 0. Step 2: linear least squares over the base gravity parameters
/// and the friction, at the joint angles corrected by the offsets.
/// @param[in] model       the manipulator model (the controller's nominal model)
/// @param[in] samples     the logged samples
/// @param[in] base        the base parameters (findBaseParameters())
/// @param[in] fitOffsets  false: the offsets are known to be 0
/// @return the estimates
/// @throws std::runtime_error when a joint has too few rows or the fit is rank deficient
Result fit(const ManipulatorModel& model, const std::vector<Sample>& samples, const BaseParameters& base,
           bool fitOffsets);

/// The model's friction per joint, on the joint side: viscous \f$B G^2\f$, Coulomb the mean of
/// \f$|G| T_c^+\f$ and \f$|G| |T_c^-|\f$, asymmetry half their difference.
/// @param[in]  model      the manipulator model
/// @param[in]  joint      0 .. n-1
/// @param[out] viscous    F_v [N m s/rad]
/// @param[out] coulomb    F_c [N m]
/// @param[out] asymmetry  a [N m]
void modelFriction(const ManipulatorModel& model, int joint, double& viscous, double& coulomb, double& asymmetry);

}  // namespace rp::calibration
