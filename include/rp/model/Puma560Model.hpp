#pragma once
/// @file
/// The Puma 560 model with the parameters of Peter Corke's Robotics Toolbox.

#include <array>

#include "rp/model/InverseKinematics.hpp"
#include "rp/model/ManipulatorModel.hpp"

namespace rp {

/// One closed-form inverse kinematics solution of the Puma 560 and its branch.
struct Puma560IkSolution {
  JointVector q;              ///< joint angles (6 x 1) [rad], q1..q3 and q4, q6 in (-pi, pi]
  bool rightShoulder = true;  ///< shoulder right: the wrist centre lies ahead of the shoulder along the arm plane's x axis (X >= 0)
  bool elbowUp = true;        ///< elbow up: the first of the two elbow angles (q3 + atan2(d4, a3) = +acos(...))
  bool wristFlipped = false;  ///< wrist flipped: q4 + pi, -q5, q6 + pi of the unflipped wrist
  bool withinLimits = false;  ///< every joint inside its limits
  /// The branch as a word: `right|left`, `up|down`, `noflip|flip`, e.g. `right-up-noflip`.
  /// Real-time safe: yes (a string literal).
  const char* branchName() const;
};

/// The Unimation Puma 560: standard DH kinematics and dynamics as published in Peter Corke's
/// Robotics Toolbox (Python `models/DH/Puma560.py`, MATLAB `mdl_puma560.m`), which take them from
/// Corke & Armstrong-Helouvry, "A search for consensus among model parameters reported for the
/// PUMA 560 robot", ICRA 1994. Joint limits as in the Python toolbox (Wang & Chen 1991).
///
/// The pedestal height d1 is 0.67183 m (26.45 in) by default, as in the Python toolbox; the
/// MATLAB toolbox uses 0. Motor inertia, gear ratios and friction are the toolbox's (motor side).
/// Velocity and torque limits are not part of the toolbox model: the values here are assumed,
/// documented in docs/models.md, and are settable by deriving.
/// Home position: the toolbox's `qr` ready pose (0, 90°, -90°, 0, 0, 0).
class Puma560Model : public ManipulatorModel {
 public:
  /// Creates the model.
  /// @param[in] pedestalHeight  d1 [m] (0.67183 as in the Python toolbox, 0 as in MATLAB's)
  /// @param[in] base            pose of the base in the world [m]
  /// @param[in] tool            pose of the end-effector in link frame 6 [m]
  explicit Puma560Model(double pedestalHeight = 0.67183, const Transform& base = Transform::unit(),
                        const Transform& tool = Transform::unit());

  /// All eight closed-form inverse kinematics solutions of `pose` (paper section 3.3's Cartesian
  /// motion needs them): shoulder right/left, elbow up/down, wrist not flipped/flipped, each
  /// flagged whether it is within the joint limits. The arm is solved geometrically (the wrist
  /// centre fixes q1 from the shoulder offset d3, then q3 and q2 from the planar two-link arm) and
  /// the spherical wrist as ZYZ Euler angles $R_{36} = R_z(q_4) R_y(-q_5) R_z(q_6)$.
  /// At the wrist singularity (q5 = 0) q4 is set to 0.
  /// @param[in]  pose       end-effector pose in the world [m]
  /// @param[out] solutions  the eight solutions (valid only when Solved)
  /// @return Solved, or Unreachable when the wrist centre is out of reach (no NaNs are produced)
  /// Real-time safe: yes.
  IkStatus inverseKinematicsAll(const Transform& pose, std::array<Puma560IkSolution, 8>& solutions) const;

  /// The closed-form solution nearest to `current` (smallest sum of squared joint differences,
  /// angles compared modulo 2 pi), among those within the joint limits.
  /// @param[in]  pose     end-effector pose in the world [m]
  /// @param[in]  current  the configuration to stay close to (6 x 1) [rad]
  /// @param[out] q        the solution (6 x 1) [rad]
  /// @return Solved, Unreachable, or NotConverged when no branch is within the limits
  /// Real-time safe: yes.
  IkStatus inverseKinematicsClosest(const Transform& pose, const JointVector& current, JointVector& q) const;

  /// The branch a configuration lies on, labelled as inverseKinematicsAll() labels its solutions:
  /// for every solution `s` of a pose, `branchOf(s.q)` has the same `rightShoulder`, `elbowUp`
  /// and `wristFlipped` (and so the same branchName()). Shoulder right: the wrist centre's
  /// coordinate along the arm plane's x axis, \f$X = u\cos q_2 - v\sin q_2\f$ with
  /// \f$u = a_2 + a_3\cos q_3 - d_4\sin q_3\f$, \f$v = a_3\sin q_3 + d_4\cos q_3\f$, is >= 0; elbow up:
  /// \f$\sin(q_3 + \mathrm{atan2}(d_4, a_3)) \ge 0\f$; wrist flipped: \f$q_5\f$ (wrapped to
  /// \f$(-\pi, \pi]\f$) > 0. On a boundary (X = 0, the elbow stretched, q5 = 0 or pi) both labels
  /// describe the configuration and the one given is the first of the two.
  /// @param[in] q  joint angles (6 x 1) [rad]
  /// @return `q`, its labels, and whether it is within the joint limits
  /// Real-time safe: yes.
  Puma560IkSolution branchOf(const JointVector& q) const;
};

}  // namespace rp
