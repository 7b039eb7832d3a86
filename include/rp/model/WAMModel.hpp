#pragma once
/// @file
/// The Barrett WAM models (7-DOF with wrist, and 4-DOF) with Barrett's published parameters.

#include "rp/model/ManipulatorModel.hpp"

namespace rp {

/// The Barrett Whole Arm Manipulator with the 7-DOF wrist: standard DH kinematics, link masses,
/// centres of mass and inertias of libbarrett's `config/wam7w.conf` ("From inertial
/// specifications Sept 2008"), joint stops of `autotension.conf` / the WAM User's Manual (Table 6),
/// gear ratios of btclient's WAM7.conf and torque limits from libbarrett's control_signal_limit.
/// libbarrett publishes no motor inertia or friction, so both are zero here; velocity limits are
/// assumed (2 rad/s). Home position (0, -1.95, 0, 3.05, 0, 0, 0) rad: zerocal.conf's home
/// (0, -2, 0, 3.13, ...) lies on the joint stops, so the model's is 0.05 rad inside them.
class WAM7Model : public ManipulatorModel {
 public:
  /// Creates the model.
  /// @param[in] base  pose of the base in the world [m]
  /// @param[in] tool  pose of the end-effector in link frame 7 [m]
  explicit WAM7Model(const Transform& base = Transform::unit(), const Transform& tool = Transform::unit());
};

/// The 4-DOF Barrett WAM: the first four joints of the WAM with libbarrett's `wam4.conf` link-4
/// parameters and its tool plate 0.36 m along z of frame 4. Other sources as WAM7Model.
class WAM4Model : public ManipulatorModel {
 public:
  /// Creates the model.
  /// @param[in] base  pose of the base in the world [m]
  /// @param[in] tool  pose of the end-effector in link frame 4 [m] (default: the 0.36 m tool plate)
  explicit WAM4Model(const Transform& base = Transform::unit(), const Transform& tool = translation(0, 0, 0.36));
};

}  // namespace rp
