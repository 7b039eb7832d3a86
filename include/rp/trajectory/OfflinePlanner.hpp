#pragma once
/// @file
/// Plans the default trajectory generator's motions for a model without an arm, and samples them
/// (notebooks, plots, tests, the Python module's Planner).

#include <memory>
#include <vector>

#include <Eigen/Core>

#include "rp/model/ManipulatorModel.hpp"
#include "rp/trajectory/DefaultTrajectoryGenerator.hpp"

namespace rp {

/// A DefaultTrajectoryGenerator connected to a stand-in arm that has a model and a joint position
/// but no servo loop: queue motions on generator() exactly as for a real arm (move(),
/// moveRadians(), moveTo(), blend radii, speed fraction; dwell() instead of the blocking stop()),
/// then sample() evaluates them at a fixed rate from time 0, as the servo loop would.
///
/// At most QueueTrajectoryGenerator::kCapacity - 4 motions may wait between two calls of
/// sample() (the queue would block the caller, with nothing to drain it): more throw
/// std::length_error. Not thread-safe; not real-time safe.
class OfflinePlanner {
 public:
  /// The samples of a plan: row k is the setpoint at time[k].
  struct Samples {
    std::vector<double> time;  ///< sample times [s], from 0 at 1 / rate
    Eigen::MatrixXd q;         ///< positions (samples x joints) [rad]
    Eigen::MatrixXd qd;        ///< velocities (samples x joints) [rad/s]
    Eigen::MatrixXd qdd;       ///< accelerations (samples x joints) [rad/s^2]
    double duration = 0;       ///< time of the last sample, the first after the last motion ended [s]
  };

  /// Creates the planner.
  /// @param[in] model  the arm's model (copied, keeping its class: a Puma560Model keeps its
  ///                   closed-form inverse kinematics, as the generator uses it on a real Puma)
  /// @param[in] start  joint positions the first motion starts from (dof x 1) [rad]
  /// @throws std::invalid_argument if `start` has the wrong size or is outside the limits
  OfflinePlanner(const ManipulatorModel& model, const JointVector& start);
  /// Creates the planner on a shared model.
  /// @param[in] model  the arm's model (not null)
  /// @param[in] start  joint positions the first motion starts from (dof x 1) [rad]
  /// @throws std::invalid_argument if `start` has the wrong size or is outside the limits
  OfflinePlanner(std::shared_ptr<const ManipulatorModel> model, const JointVector& start);
  /// Drains what was queued and not sampled, then disconnects.
  ~OfflinePlanner();
  OfflinePlanner(const OfflinePlanner&) = delete;             ///< not copyable
  OfflinePlanner& operator=(const OfflinePlanner&) = delete;  ///< not copyable

  /// The model planned for.
  const ManipulatorModel& getModel() const;
  /// The generator to queue motions on.
  /// @throws std::length_error if kCapacity - 4 motions already wait for sample()
  DefaultTrajectoryGenerator<>& generator();
  /// Queues a pause at the last target (the non-blocking counterpart of stop()).
  /// @param[in] seconds  length of the pause [s], >= 0
  void dwell(double seconds);
  /// Evaluates every queued motion at `rate` samples per second, from time 0 (each call starts
  /// its times at 0, continuing the plan where the previous call ended), up to and including
  /// the first sample at which the last motion has ended (at rest at its target); `duration` is
  /// that sample's time, within 1 / rate after the true end. Empty if nothing was queued.
  /// @param[in] rate         samples per second, > 0
  /// @param[in] maxDuration  longest time sampled [s]; a longer plan, or more than 10^7 samples,
  ///                         throws std::length_error
  /// @throws std::invalid_argument for a rate that is not positive
  Samples sample(double rate, double maxDuration = 3600);

 private:
  class Arm;
  class Generator;
  std::unique_ptr<Arm> arm_;
  std::unique_ptr<Generator> generator_;
  double time_ = 0;  // the generator's clock: where the next sample() starts [s]
};

}  // namespace rp
