#pragma once
/// @file
/// The desired joint state of one servo cycle.

#include "rp/model/ManipulatorModel.hpp"

namespace rp {

/// A desired joint state: what a trajectory generator gives a manipulator every servo cycle.
struct Setpoint {
  JointVector position;      ///< desired joint positions (n x 1) [rad]
  JointVector velocity;      ///< desired joint velocities (n x 1) [rad/s], for feed-forward
  JointVector acceleration;  ///< desired joint accelerations (n x 1) [rad/s^2], for feed-forward
};

}  // namespace rp
