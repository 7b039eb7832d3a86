#pragma once
/// @file
/// A joint trajectory given as timed points (ROS's trajectory_msgs/JointTrajectory), interpolated
/// as ros2_control's joint_trajectory_controller interpolates them.

#include <array>
#include <vector>

#include "rp/model/ManipulatorModel.hpp"
#include "rp/trajectory/Setpoint.hpp"

namespace rp {

/// One point of a TimedJointTrajectory: where the joints are to be at a time.
struct TimedJointPoint {
  double time = 0;           ///< time from the start of the trajectory [s], >= 0
  JointVector position;      ///< joint positions (n x 1) [rad, m]
  JointVector velocity;      ///< joint velocities (n x 1) [rad/s, m/s], or empty (0 values): estimated
  JointVector acceleration;  ///< joint accelerations (n x 1) [rad/s^2, m/s^2], or empty
};

/// Where a trajectory leaves the joint limits (TimedJointTrajectory::findLimitViolation()).
struct TrajectoryLimitViolation {
  bool found = false;     ///< false: the trajectory keeps every limit
  int point = -1;         ///< the point that ends the piece where it happens (0: the piece from the start)
  int joint = -1;         ///< the joint, 0 .. n-1
  bool velocity = false;  ///< true: a velocity limit; false: a position limit
  double time = 0;        ///< when, from the start of the trajectory [s]
  double value = 0;       ///< the position [rad, m] or velocity [rad/s, m/s] there
  double limit = 0;       ///< the limit it passes
};

/// A joint trajectory through timed points, continuous with the motion it starts from.
///
/// The pieces between the points are polynomials in time per joint, as ros2_control's
/// joint_trajectory_controller uses (its "spline" interpolation):
/// - points with positions, velocities and accelerations: quintic Hermite pieces (position,
///   velocity and acceleration continuous);
/// - points with positions and velocities: cubic Hermite pieces (position and velocity continuous);
/// - points with positions only: cubic Hermite pieces through velocities estimated at the points
///   (joint_trajectory_controller draws straight lines here, with jumps in velocity): at an inner
///   point the weighted harmonic mean of the two neighbouring slopes, or 0 where the joint turns
///   (Fritsch and Butland's monotone estimate: a joint never overshoots the points on either
///   side), 0 at the last point.
///
/// The first piece runs from the state the trajectory starts from (start(): the position, velocity
/// and acceleration of the motion it replaces, at time 0) to the first point; after the last
/// point the trajectory holds it (velocity and acceleration 0).
///
/// The points are checked and the pieces between them computed by the constructor (in any
/// thread); start() and evaluate() allocate nothing and take no lock, for the servo thread.
class TimedJointTrajectory {
 public:
  /// How the pieces are interpolated (see the class description).
  enum class Interpolation {
    Cubic,         ///< positions only: cubic through estimated velocities
    CubicHermite,  ///< positions and velocities: cubic Hermite
    QuinticHermite ///< positions, velocities and accelerations: quintic Hermite
  };

  /// The most points a trajectory may have.
  static constexpr int kMaxPoints = 10000;

  /// Checks the points and computes the pieces between them; start() must be called before
  /// evaluate().
  /// @param[in] points  at least one, at most kMaxPoints; times >= 0 and strictly increasing;
  ///                    every point with the same number of positions (1 .. kMaxJoints), and
  ///                    either no velocities or as many, likewise accelerations (which need
  ///                    velocities); every value finite; the last point's velocities and
  ///                    accelerations (if given) 0
  /// @throws std::invalid_argument naming the first point (from 0) and field that breaks a rule
  /// Real-time safe: no.
  explicit TimedJointTrajectory(std::vector<TimedJointPoint> points);

  /// Number of joints.
  int getNumberOfJoints() const noexcept { return joints_; }
  /// The points, as given (the velocities estimated for Interpolation::Cubic are not in them).
  const std::vector<TimedJointPoint>& getPoints() const noexcept { return points_; }
  /// How the pieces are interpolated.
  Interpolation getInterpolation() const noexcept { return interpolation_; }
  /// Time of the last point [s]: the trajectory's duration.
  double getDuration() const noexcept { return points_.back().time; }

  /// Sets the state the trajectory starts from at time 0 and computes the first piece (and, for
  /// Interpolation::Cubic, the velocity estimated at the first point and the piece after it).
  /// @param[in] state  position, velocity and acceleration (n x 1 each) at time 0
  /// Real-time safe: yes.
  void start(const Setpoint& state) noexcept;
  /// The setpoint at time `t` from the start (before 0: the start; after the last point: the last
  /// point at rest).
  /// @param[in]  t    time since the start [s]
  /// @param[out] out  position, velocity and acceleration (each resized to n, within kMaxJoints)
  /// Real-time safe: yes.
  void evaluate(double t, Setpoint& out) const noexcept;

  /// The first place where the trajectory, started with start(), leaves the position limits
  /// [`min`, `max`] or the velocity limits (|v| <= `vmax`): each piece is checked at its ends and
  /// at `samples` instants between.
  /// @param[in] min      joint position lower limits (n x 1)
  /// @param[in] max      joint position upper limits (n x 1)
  /// @param[in] vmax     joint velocity limits (n x 1), > 0
  /// @param[in] samples  instants checked inside each piece
  /// @return the first violation in time (`found` false if none)
  /// Real-time safe: no (a trajectory of many points takes a while).
  TrajectoryLimitViolation findLimitViolation(const JointVector& min, const JointVector& max, const JointVector& vmax,
                                              int samples = 32) const;

 private:
  using Coefficients = std::array<double, 6>;
  void computePiece(int piece, const JointVector& p0, const JointVector& v0, const JointVector& a0);
  void piecePolynomial(int piece, int joint, double duration, double p0, double v0, double a0, double p1, double v1,
                       double a1) noexcept;
  double pieceStart(int piece) const noexcept { return piece == 0 ? 0.0 : points_[static_cast<std::size_t>(piece) - 1].time; }

  std::vector<TimedJointPoint> points_;
  std::vector<double> times_;                // points_[k].time, for the search
  std::vector<JointVector> velocities_;      // the velocities at the points, given or estimated
  std::vector<Coefficients> coefficients_;   // piece k (ending at point k), joint i at k * n + i
  Setpoint start_;
  Interpolation interpolation_ = Interpolation::Cubic;
  int joints_ = 0;
};

}  // namespace rp
