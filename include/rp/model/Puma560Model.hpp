#pragma once
/// @file
/// The Puma 560 model with the parameters of Peter Corke's Robotics Toolbox.

#include "rp/model/ManipulatorModel.hpp"

namespace rp {

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
};

}  // namespace rp
