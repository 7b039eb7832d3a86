// Trajectories planned and sampled in Python without an arm: the library's jerk-limited joint
// motion (JointLineSegment) through waypoints, and the default generator's joint, Cartesian and
// blended motions (OfflinePlanner).
#include <pybind11/pybind11.h>

#include <cmath>
#include <string>
#include <vector>

#include "Arrays.hpp"
#include "Bindings.hpp"
#include "rp/trajectory/JointLineSegment.hpp"
#include "rp/trajectory/OfflinePlanner.hpp"

namespace rp::python {

Synchronization synchronizationOf(const std::string& name) {
  if (name == "time") return Synchronization::Time;
  if (name == "phase") return Synchronization::Phase;
  if (name == "none") return Synchronization::None;
  throw py::value_error("synchronization: '" + name + "' is not one of time, phase, none");
}

void bindTrajectories(py::module_& m) {
  m.def(
      "plan_joint_motion",
      [](const py::handle& modelObject, const py::handle& waypoints, double rate, double speedFraction) {
        const ManipulatorModel& model = modelOf(modelObject);
        const int n = model.getNumberOfJoints();
        if (!(rate > 0) || !std::isfinite(rate)) throw py::value_error("rate must be a positive number of samples per second");
        if (!(speedFraction > 0 && speedFraction <= 1)) throw py::value_error("speed_fraction must be in (0, 1]");
        auto points = toMatrix(waypoints, -1, n, "waypoints");
        const py::ssize_t count = points.shape(0);
        if (count < 2) throw py::value_error("waypoints: at least two rows (the start and a target)");
        auto rowOf = [&](py::ssize_t r) {
          JointVector v(n);
          for (int i = 0; i < n; ++i) v(i) = points.data()[r * n + i];
          return v;
        };
        // Time scaling by f: velocity f, acceleration f^2, jerk f^3 of the limits.
        const JointVector vmax = model.getVelocityLimit() * speedFraction;
        const JointVector amax = model.getAccelerationLimit() * (speedFraction * speedFraction);
        const JointVector jmax = model.getJerkLimit() * (speedFraction * speedFraction * speedFraction);
        std::vector<JointLineSegment> segments;
        std::vector<double> starts{0.0};
        for (py::ssize_t r = 0; r + 1 < count; ++r) {
          segments.emplace_back(rowOf(r), rowOf(r + 1), vmax, amax, jmax);
          starts.push_back(starts.back() + segments.back().getDuration());
        }
        const double duration = starts.back();
        if (!(duration * rate <= 1e7))
          throw py::value_error("plan_joint_motion: more than 1e7 samples (" + std::to_string(duration) + " s at " +
                                std::to_string(rate) + " Hz); lower the rate");
        const auto samples = static_cast<py::ssize_t>(std::floor(duration * rate + 1e-9)) + 1;
        py::array_t<double> t(samples), q({samples, py::ssize_t{n}}), qd({samples, py::ssize_t{n}}),
            qdd({samples, py::ssize_t{n}});
        Setpoint sp;
        sp.position.resize(n);
        sp.velocity.resize(n);
        sp.acceleration.resize(n);
        std::size_t segment = 0;
        for (py::ssize_t k = 0; k < samples; ++k) {
          const double time = static_cast<double>(k) / rate;
          while (segment + 1 < segments.size() && time > starts[segment + 1]) ++segment;
          segments[segment].evaluate(time - starts[segment], sp);
          t.mutable_data()[k] = time;
          for (int i = 0; i < n; ++i) {
            q.mutable_data()[k * n + i] = sp.position(i);
            qd.mutable_data()[k * n + i] = sp.velocity(i);
            qdd.mutable_data()[k * n + i] = sp.acceleration(i);
          }
        }
        py::dict out;
        out["time"] = t;
        out["q"] = q;
        out["qd"] = qd;
        out["qdd"] = qdd;
        out["duration"] = duration;
        return out;
      },
      py::arg("model"), py::arg("waypoints"), py::arg("rate") = 1000.0, py::arg("speed_fraction") = 1.0,
      "Plans rest-to-rest jerk-limited joint motions through the rows of `waypoints` (K x dof, the first row the "
      "start) within the model's velocity, acceleration and jerk limits (scaled in time by speed_fraction), and "
      "samples them at `rate` Hz: a dict of time (N), q, qd, qdd (N x dof) and duration [s].");

  py::class_<OfflinePlanner>(m, "Planner",
                             "The default trajectory generator's motions planned for a model alone and sampled: queue "
                             "motions as on rp.TrajectoryGenerator (move, move_radians, move_to, dwell, blend radii, "
                             "speed fraction), then sample(rate).")
      .def(py::init([](const py::handle& modelObject, const py::object& start) {
             std::shared_ptr<const ManipulatorModel> model = sharedModelOf(modelObject);
             const JointVector q = start.is_none() ? model->getHomePosition()
                                                   : toVector(start, model->getNumberOfJoints(), "start");
             return std::make_unique<OfflinePlanner>(std::move(model), q);
           }),
           py::arg("model"), py::arg("start") = py::none())
      .def("move", [](OfflinePlanner& p, const py::handle& degrees) {
             auto& g = p.generator();
             g.move(toVector(degrees, p.getModel().getNumberOfJoints(), "target_degrees"));
           }, py::arg("target_degrees"), "queues a joint motion to the given joint positions [deg]")
      .def("move_radians", [](OfflinePlanner& p, const py::handle& q) {
             auto& g = p.generator();
             g.moveRadians(toVector(q, p.getModel().getNumberOfJoints(), "target"));
           }, py::arg("target"), "queues a joint motion to the given joint positions [rad or m]")
      .def("move_to", [](OfflinePlanner& p, const py::handle& pose) { p.generator().moveTo(toTransform(pose, "pose")); },
           py::arg("pose"), "queues a Cartesian straight-line motion to a 4 x 4 end-effector pose")
      .def("move_to_through_joint_space",
           [](OfflinePlanner& p, const py::handle& pose) { p.generator().moveToThroughJointSpace(toTransform(pose, "pose")); },
           py::arg("pose"), "queues a joint-interpolated motion to a 4 x 4 end-effector pose")
      .def("dwell", &OfflinePlanner::dwell, py::arg("seconds"), "holds still for the given time [s]")
      .def("set_joint_blend_radius", [](OfflinePlanner& p, double r) { p.generator().setJointBlendRadius(r); },
           py::arg("radians"), "blend radius of the joint motions that follow [rad] (0: stop at each point)")
      .def("set_cartesian_blend_radius", [](OfflinePlanner& p, double r) { p.generator().setCartesianBlendRadius(r); },
           py::arg("metres"), "blend radius of the Cartesian motions that follow [m] (0: stop at each point)")
      .def("set_speed_fraction", [](OfflinePlanner& p, double f) { p.generator().setSpeedFraction(f); },
           py::arg("fraction"), "fraction (0..1] of the joint limits the motions that follow use")
      .def("set_synchronization",
           [](OfflinePlanner& p, const std::string& mode) { p.generator().setSynchronization(synchronizationOf(mode)); },
           py::arg("mode"),
           "how the joints of the joint motions queued from now on are synchronised: 'time' (the default: all end "
           "together at the slowest joint's minimum time), 'phase' (the straight line in joint space) or 'none'")
      .def(
          "sample",
          [](OfflinePlanner& p, double rate) {
            const OfflinePlanner::Samples s = p.sample(rate);
            py::dict out;
            out["time"] = fromVector(Eigen::Map<const Eigen::VectorXd>(s.time.data(), static_cast<Eigen::Index>(s.time.size())));
            out["q"] = fromMatrix(s.q);
            out["qd"] = fromMatrix(s.qd);
            out["qdd"] = fromMatrix(s.qdd);
            out["duration"] = s.duration;
            return out;
          },
          py::arg("rate") = 1000.0,
          "the queued motions sampled at `rate` Hz: dict of time, q, qd, qdd and duration (the first sample after the end)");
}

}  // namespace rp::python
