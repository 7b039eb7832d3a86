#pragma once
/// @file
/// Speed limits of straight-line Cartesian motion.

namespace rp {

/// Limits of the end-effector's straight-line motion (DefaultTrajectoryGenerator::moveTo()).
///
/// The translation is limited along the line, the rotation about its (fixed) shortest-arc axis.
/// Joint velocity, acceleration and jerk limits apply on top of these: a motion is slowed down
/// until every joint stays within its limits too.
struct CartesianLimits {
  double linearVelocity = 0.5;       ///< [m/s]
  double linearAcceleration = 2.0;   ///< [m/s^2]
  double linearJerk = 20.0;          ///< [m/s^3]
  double angularVelocity = 1.5;      ///< [rad/s]
  double angularAcceleration = 6.0;  ///< [rad/s^2]
  double angularJerk = 60.0;         ///< [rad/s^3]
};

}  // namespace rp
