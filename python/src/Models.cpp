// The models and their algorithms in Python: Puma560Model, WAMModel, UrdfModel; FK, Jacobian,
// RNEA, gravity, CRBA, ABA, inverse kinematics; batched forms that run with the GIL released.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <string>
#include <vector>

#include "Arrays.hpp"
#include "Bindings.hpp"
#include "rp/model/Dynamics.hpp"
#include "rp/model/InverseKinematics.hpp"
#include "rp/model/Kinematics.hpp"
#include "rp/model/Puma560Model.hpp"
#include "rp/model/UrdfModel.hpp"
#include "rp/model/WAMModel.hpp"

namespace rp::python {

namespace {

// A model with the scratch space of single calls (guarded by the GIL); batched calls make their own.
struct PyModel {
  explicit PyModel(std::shared_ptr<ManipulatorModel> m) : model(std::move(m)), data(*model) {}
  virtual ~PyModel() = default;
  int dof() const { return model->getNumberOfJoints(); }
  JointVector q(const py::handle& v, const char* what) const { return toVector(v, dof(), what); }
  std::shared_ptr<ManipulatorModel> model;
  ManipulatorData data;
};

struct PyPuma : PyModel {
  PyPuma(double pedestal, const py::object& base, const py::object& tool)
      : PyModel(std::make_shared<Puma560Model>(pedestal, base.is_none() ? Transform::unit() : toTransform(base, "base"),
                                               tool.is_none() ? Transform::unit() : toTransform(tool, "tool"))) {}
  const Puma560Model& puma() const { return static_cast<const Puma560Model&>(*model); }
};

std::shared_ptr<ManipulatorModel> makeWam(int dof, const Transform& base, const Transform& tool) {
  if (dof == 7) return std::make_shared<WAM7Model>(base, tool);
  if (dof == 4) return std::make_shared<WAM4Model>(base, tool);
  throw py::value_error("WAMModel: dof must be 4 or 7, got " + std::to_string(dof));
}

// A URDF given as a path, or as the XML text itself (error messages then call it "<string>").
std::shared_ptr<ManipulatorModel> makeUrdf(const std::string& source, const std::string& tip, bool requireDynamics) {
  UrdfOptions options;
  options.tip = tip;
  options.requireDynamics = requireDynamics;
  if (source.find('<') == std::string::npos) return std::shared_ptr<ManipulatorModel>(loadUrdf(source, options));
  return std::shared_ptr<ManipulatorModel>(loadUrdfString(source, options));
}

const char* statusName(IkStatus s) {
  switch (s) {
    case IkStatus::Solved: return "solved";
    case IkStatus::NotConverged: return "not_converged";
    case IkStatus::Unreachable: return "unreachable";
  }
  return "unknown";
}

ReferenceFrame frameOf(const std::string& frame) {
  if (frame == "base" || frame == "world") return ReferenceFrame::Base;
  if (frame == "end_effector" || frame == "tool") return ReferenceFrame::EndEffector;
  throw py::value_error("frame must be 'base' or 'end_effector', got '" + frame + "'");
}

DynamicsOptions options(bool gravity, bool motorInertia, bool friction) {
  DynamicsOptions o;
  o.gravity = gravity;
  o.motorInertia = motorInertia;
  o.friction = friction;
  return o;
}

py::dict linkDict(const LinkParameters& l) {
  py::dict d;
  d["type"] = l.type == JointType::Prismatic ? "prismatic" : "revolute";
  d["joint_name"] = l.jointName;
  d["link_name"] = l.linkName;
  d["placement"] = fromMatrix(l.placement);
  d["a"] = l.a;
  d["alpha"] = l.alpha;
  d["d"] = l.d;
  d["offset"] = l.offset;
  d["mass"] = l.mass;
  d["com"] = fromVector(l.com);
  d["inertia"] = fromMatrix(l.inertia);
  d["motor_inertia"] = l.motorInertia;
  d["gear_ratio"] = l.gearRatio;
  d["viscous_friction"] = l.viscousFriction;
  d["coulomb_friction"] = py::make_tuple(l.coulombFrictionNegative, l.coulombFrictionPositive);
  return d;
}

// Rows of a batch: `n` inputs of `cols` each, or a ValueError if the batches differ in size.
py::ssize_t batchRows(std::initializer_list<const py::array_t<double, py::array::c_style>*> inputs) {
  const py::ssize_t rows = (*inputs.begin())->shape(0);
  for (const auto* a : inputs)
    if (a->shape(0) != rows) throw py::value_error("the batched arrays must have the same number of rows");
  return rows;
}

JointVector row(const py::array_t<double, py::array::c_style>& a, py::ssize_t r, int n) {
  JointVector v(n);
  const double* p = a.data() + r * n;
  for (int i = 0; i < n; ++i) v(i) = p[i];
  return v;
}

}  // namespace

const ManipulatorModel& modelOf(const py::handle& object) { return *object.cast<const PyModel&>().model; }

std::shared_ptr<const ManipulatorModel> sharedModelOf(const py::handle& object) {
  return object.cast<const PyModel&>().model;
}

py::object makeModelCopy(const ManipulatorModel& model) {
  return py::cast(std::make_unique<PyModel>(std::make_shared<ManipulatorModel>(model)));
}

void bindModels(py::module_& m) {
  py::register_exception<UrdfError>(m, "UrdfError", PyExc_RuntimeError).doc() =
      "A URDF that cannot be loaded: the file and line, or the element, and what is wrong.";

  py::class_<PyModel>(m, "Model",
                      "A serial manipulator's kinematic and dynamic model (rp::ManipulatorModel). Joint vectors "
                      "are 1-D float64 arrays of length dof, poses 4 x 4 arrays, SI units.")
      .def_property_readonly("name", [](const PyModel& p) { return p.model->getName(); }, "the model's name")
      .def_property_readonly("dof", &PyModel::dof, "number of joints")
      .def_property_readonly("convention",
                             [](const PyModel& p) {
                               return p.model->getConvention() == DHConvention::Standard ? "standard" : "modified";
                             }, "the link convention: 'standard' (DH) or 'modified' (modified DH and URDF placements)")
      .def_property_readonly("joint_names",
                             [](const PyModel& p) {
                               std::vector<std::string> names;
                               for (int i = 0; i < p.dof(); ++i) names.push_back(p.model->getJointName(i));
                               return names;
                             },
                             "the joints' names (the URDF's; joint1... for the built-in arms)")
      .def_property_readonly("link_names",
                             [](const PyModel& p) {
                               std::vector<std::string> names;
                               for (int i = 0; i < p.dof(); ++i) names.push_back(p.model->getLinkName(i));
                               return names;
                             },
                             "the moving links' names")
      .def_property_readonly("home", [](const PyModel& p) { return fromVector(p.model->getHomePosition()); }, "the home joint positions [rad or m]")
      .def_property_readonly("position_min", [](const PyModel& p) { return fromVector(p.model->getPositionMin()); }, "lower joint limits [rad or m]")
      .def_property_readonly("position_max", [](const PyModel& p) { return fromVector(p.model->getPositionMax()); }, "upper joint limits [rad or m]")
      .def_property_readonly("velocity_limit", [](const PyModel& p) { return fromVector(p.model->getVelocityLimit()); }, "joint velocity limits [rad/s or m/s]")
      .def_property_readonly("acceleration_limit",
                             [](const PyModel& p) { return fromVector(p.model->getAccelerationLimit()); }, "joint acceleration limits [rad/s^2 or m/s^2]")
      .def_property_readonly("jerk_limit", [](const PyModel& p) { return fromVector(p.model->getJerkLimit()); }, "joint jerk limits [rad/s^3 or m/s^3]")
      .def_property_readonly("torque_limit", [](const PyModel& p) { return fromVector(p.model->getTorqueLimit()); }, "joint torque limits [N m or N]")
      .def_property_readonly("base", [](const PyModel& p) { return fromMatrix(p.model->getBaseTransform()); }, "the 4 x 4 pose of the base in the world [m]")
      .def_property_readonly("tool", [](const PyModel& p) { return fromMatrix(p.model->getToolTransform()); }, "the 4 x 4 pose of the end-effector in the last link frame [m]")
      .def_property_readonly("gravity", [](const PyModel& p) { return fromVector(p.model->getGravity()); }, "gravity in the world frame [m/s^2]")
      .def(
          "link",
          [](const PyModel& p, int i) {
            if (i < 0 || i >= p.dof())
              throw py::index_error("link " + std::to_string(i) + " is not in 0.." + std::to_string(p.dof() - 1));
            return linkDict(p.model->getLink(i));
          },
          py::arg("i"), "the parameters of joint/link i (0-based) as a dict")
      .def(
          "within_limits", [](const PyModel& p, const py::handle& q) { return p.model->isWithinLimits(p.q(q, "q")); },
          py::arg("q"), "whether the joint positions lie within the joint limits")
      .def(
          "fk", [](PyModel& p, const py::handle& q) { return fromMatrix(forwardKinematics(*p.model, p.data, p.q(q, "q"))); },
          py::arg("q"), "pose of the end-effector in the world (4 x 4)")
      .def(
          "link_transforms",
          [](PyModel& p, const py::handle& q) {
            forwardKinematics(*p.model, p.data, p.q(q, "q"));
            const int n = p.dof();
            py::array_t<double> out({n, 4, 4});
            double* o = out.mutable_data();
            for (int k = 0; k < n; ++k)
              for (int r = 0; r < 4; ++r)
                for (int c = 0; c < 4; ++c) o[(k * 4 + r) * 4 + c] = p.data.linkTransforms[static_cast<std::size_t>(k)](r, c);
            return out;
          },
          py::arg("q"), "pose of every link frame in the world (dof x 4 x 4)")
      .def(
          "jacobian",
          [](PyModel& p, const py::handle& q, const std::string& frame) {
            return fromMatrix(jacobian(*p.model, p.data, p.q(q, "q"), frameOf(frame)));
          },
          py::arg("q"), py::arg("frame") = "base",
          "geometric Jacobian (6 x dof; rows vx vy vz wx wy wz) in the 'base' (world) or 'end_effector' frame")
      .def(
          "rnea",
          [](PyModel& p, const py::handle& q, const py::handle& qd, const py::handle& qdd, bool gravity, bool motorInertia,
             bool friction) {
            return fromVector(inverseDynamics(*p.model, p.data, p.q(q, "q"), p.q(qd, "qd"), p.q(qdd, "qdd"),
                                              options(gravity, motorInertia, friction)));
          },
          py::arg("q"), py::arg("qd"), py::arg("qdd"), py::arg("gravity") = true, py::arg("motor_inertia") = false,
          py::arg("friction") = false, "inverse dynamics (recursive Newton-Euler): joint torques")
      .def(
          "gravity_torque",
          [](PyModel& p, const py::handle& q) {
            JointVector tau(p.dof());
            gravityTorque(*p.model, p.data, p.q(q, "q"), tau);
            return fromVector(tau);
          },
          py::arg("q"), "the torques that hold the arm at rest in q")
      .def(
          "crba",
          [](PyModel& p, const py::handle& q, bool motorInertia) {
            return fromMatrix(massMatrix(*p.model, p.data, p.q(q, "q"), motorInertia));
          },
          py::arg("q"), py::arg("motor_inertia") = false, "joint-space mass matrix (composite rigid body algorithm)")
      .def(
          "aba",
          [](PyModel& p, const py::handle& q, const py::handle& qd, const py::handle& tau, bool gravity, bool motorInertia,
             bool friction) {
            return fromVector(forwardDynamicsArticulatedBody(*p.model, p.data, p.q(q, "q"), p.q(qd, "qd"), p.q(tau, "tau"),
                                                             options(gravity, motorInertia, friction)));
          },
          py::arg("q"), py::arg("qd"), py::arg("tau"), py::arg("gravity") = true, py::arg("motor_inertia") = false,
          py::arg("friction") = false, "forward dynamics (articulated-body algorithm): joint accelerations")
      .def(
          "ik",
          [](PyModel& p, const py::handle& pose, const py::object& seed, double positionTolerance,
             double orientationTolerance, int maxAttempts, bool positionOnly) {
            const Transform target = toTransform(pose, "pose");
            const JointVector start = seed.is_none() ? p.model->getHomePosition() : p.q(seed, "seed");
            IkOptions o;
            o.positionTolerance = positionTolerance;
            o.orientationTolerance = orientationTolerance;
            o.maxAttempts = maxAttempts;
            o.positionOnly = positionOnly;
            JointVector q(p.dof());
            IkStatus status;
            {
              py::gil_scoped_release release;
              ManipulatorData data(*p.model);
              status = inverseKinematics(*p.model, data, target, start, q, o);
            }
            return py::make_tuple(statusName(status), fromVector(q));
          },
          py::arg("pose"), py::arg("seed") = py::none(), py::arg("position_tolerance") = 1e-6,
          py::arg("orientation_tolerance") = 1e-6, py::arg("max_attempts") = 100, py::arg("position_only") = false,
          "numeric inverse kinematics within the joint limits: (status, q), status 'solved', 'not_converged' or "
          "'unreachable'")
      // Batched forms: N x dof arrays in, the GIL released while C++ runs.
      .def(
          "fk_batch",
          [](const PyModel& p, const py::handle& qs, const py::object& out) {
            const int n = p.dof();
            auto q = toMatrix(qs, -1, n, "q");
            const py::ssize_t rows = q.shape(0);
            py::array_t<double> result = outputArray(out, {rows, 4, 4}, {&q});
            double* o = result.mutable_data();
            {
              py::gil_scoped_release release;
              ManipulatorData data(*p.model);
              for (py::ssize_t r = 0; r < rows; ++r) {
                const Transform& t = forwardKinematics(*p.model, data, row(q, r, n));
                for (int i = 0; i < 4; ++i)
                  for (int j = 0; j < 4; ++j) o[(r * 4 + i) * 4 + j] = t(i, j);
              }
            }
            return result;
          },
          py::arg("q"), py::kw_only(), py::arg("out") = py::none(), "fk of every row of an N x dof array: N x 4 x 4")
      .def(
          "link_transforms_batch",
          [](const PyModel& p, const py::handle& qs, const py::object& out) {
            const int n = p.dof();
            auto q = toMatrix(qs, -1, n, "q");
            const py::ssize_t rows = q.shape(0);
            py::array_t<double> result = outputArray(out, {rows, n, 4, 4}, {&q});
            double* o = result.mutable_data();
            {
              py::gil_scoped_release release;
              ManipulatorData data(*p.model);
              for (py::ssize_t r = 0; r < rows; ++r) {
                forwardKinematics(*p.model, data, row(q, r, n));
                for (int k = 0; k < n; ++k)
                  for (int i = 0; i < 4; ++i)
                    for (int j = 0; j < 4; ++j)
                      o[((r * n + k) * 4 + i) * 4 + j] = data.linkTransforms[static_cast<std::size_t>(k)](i, j);
              }
            }
            return result;
          },
          py::arg("q"), py::kw_only(), py::arg("out") = py::none(), "link_transforms of every row of an N x dof array: N x dof x 4 x 4")
      .def(
          "jacobian_batch",
          [](const PyModel& p, const py::handle& qs, const std::string& frame, const py::object& out) {
            const int n = p.dof();
            const ReferenceFrame f = frameOf(frame);
            auto q = toMatrix(qs, -1, n, "q");
            const py::ssize_t rows = q.shape(0);
            py::array_t<double> result = outputArray(out, {rows, 6, n}, {&q});
            double* o = result.mutable_data();
            {
              py::gil_scoped_release release;
              ManipulatorData data(*p.model);
              for (py::ssize_t r = 0; r < rows; ++r) {
                const Jacobian& J = jacobian(*p.model, data, row(q, r, n), f);
                for (int i = 0; i < 6; ++i)
                  for (int j = 0; j < n; ++j) o[(r * 6 + i) * n + j] = J(i, j);
              }
            }
            return result;
          },
          py::arg("q"), py::arg("frame") = "base", py::kw_only(), py::arg("out") = py::none(), "jacobian of every row of an N x dof array: N x 6 x dof")
      .def(
          "rnea_batch",
          [](const PyModel& p, const py::handle& qs, const py::handle& qds, const py::handle& qdds, bool gravity,
             bool motorInertia, bool friction, const py::object& out) {
            const int n = p.dof();
            auto q = toMatrix(qs, -1, n, "q");
            auto qd = toMatrix(qds, -1, n, "qd");
            auto qdd = toMatrix(qdds, -1, n, "qdd");
            const py::ssize_t rows = batchRows({&q, &qd, &qdd});
            py::array_t<double> result = outputArray(out, {rows, n}, {&q, &qd, &qdd});
            double* o = result.mutable_data();
            const DynamicsOptions opt = options(gravity, motorInertia, friction);
            {
              py::gil_scoped_release release;
              ManipulatorData data(*p.model);
              for (py::ssize_t r = 0; r < rows; ++r) {
                const JointVector& tau = inverseDynamics(*p.model, data, row(q, r, n), row(qd, r, n), row(qdd, r, n), opt);
                for (int i = 0; i < n; ++i) o[r * n + i] = tau(i);
              }
            }
            return result;
          },
          py::arg("q"), py::arg("qd"), py::arg("qdd"), py::arg("gravity") = true, py::arg("motor_inertia") = false,
          py::arg("friction") = false, py::kw_only(), py::arg("out") = py::none(), "rnea of every row: N x dof")
      .def(
          "gravity_torque_batch",
          [](const PyModel& p, const py::handle& qs, const py::object& out) {
            const int n = p.dof();
            auto q = toMatrix(qs, -1, n, "q");
            const py::ssize_t rows = q.shape(0);
            py::array_t<double> result = outputArray(out, {rows, n}, {&q});
            double* o = result.mutable_data();
            {
              py::gil_scoped_release release;
              ManipulatorData data(*p.model);
              JointVector tau(n);
              for (py::ssize_t r = 0; r < rows; ++r) {
                gravityTorque(*p.model, data, row(q, r, n), tau);
                for (int i = 0; i < n; ++i) o[r * n + i] = tau(i);
              }
            }
            return result;
          },
          py::arg("q"), py::kw_only(), py::arg("out") = py::none(), "gravity_torque of every row: N x dof")
      .def(
          "ik_batch",
          [](const PyModel& p, const py::handle& poses, const py::object& seeds, double positionTolerance,
             double orientationTolerance, int maxAttempts) {
            const int n = p.dof();
            const std::vector<Transform> targets = toTransforms(poses, "poses");
            const auto rows = static_cast<py::ssize_t>(targets.size());
            py::array_t<double, py::array::c_style> seed;
            if (!seeds.is_none()) {
              seed = toMatrix(seeds, -1, n, "seeds");
              if (seed.shape(0) != rows) throw py::value_error("seeds: one row per pose");
            }
            IkOptions o;
            o.positionTolerance = positionTolerance;
            o.orientationTolerance = orientationTolerance;
            o.maxAttempts = maxAttempts;
            py::array_t<double> out({rows, py::ssize_t{n}});
            py::array_t<bool> solved(rows);
            double* qo = out.mutable_data();
            bool* so = solved.mutable_data();
            {
              py::gil_scoped_release release;
              ManipulatorData data(*p.model);
              JointVector q(n);
              for (py::ssize_t r = 0; r < rows; ++r) {
                const JointVector start = seeds.is_none() ? p.model->getHomePosition() : row(seed, r, n);
                so[r] = inverseKinematics(*p.model, data, targets[static_cast<std::size_t>(r)], start, q, o) == IkStatus::Solved;
                for (int i = 0; i < n; ++i) qo[r * n + i] = q(i);
              }
            }
            return py::make_tuple(solved, out);
          },
          py::arg("poses"), py::arg("seeds") = py::none(), py::arg("position_tolerance") = 1e-6,
          py::arg("orientation_tolerance") = 1e-6, py::arg("max_attempts") = 100,
          "numeric ik of every pose of an N x 4 x 4 array: (solved: N booleans, q: N x dof)")
      .def(
          "crba_batch",
          [](const PyModel& p, const py::handle& qs, bool motorInertia, const py::object& out) {
            const int n = p.dof();
            auto q = toMatrix(qs, -1, n, "q");
            const py::ssize_t rows = q.shape(0);
            py::array_t<double> result = outputArray(out, {rows, n, n}, {&q});
            double* o = result.mutable_data();
            {
              py::gil_scoped_release release;
              ManipulatorData data(*p.model);
              for (py::ssize_t r = 0; r < rows; ++r) {
                const JointMatrix& M = massMatrix(*p.model, data, row(q, r, n), motorInertia);
                for (int i = 0; i < n; ++i)
                  for (int j = 0; j < n; ++j) o[(r * n + i) * n + j] = M(i, j);
              }
            }
            return result;
          },
          py::arg("q"), py::arg("motor_inertia") = false, py::kw_only(), py::arg("out") = py::none(), "crba of every row: N x dof x dof")
      .def(
          "aba_batch",
          [](const PyModel& p, const py::handle& qs, const py::handle& qds, const py::handle& taus, bool gravity,
             bool motorInertia, bool friction, const py::object& out) {
            const int n = p.dof();
            auto q = toMatrix(qs, -1, n, "q");
            auto qd = toMatrix(qds, -1, n, "qd");
            auto tau = toMatrix(taus, -1, n, "tau");
            const py::ssize_t rows = batchRows({&q, &qd, &tau});
            py::array_t<double> result = outputArray(out, {rows, n}, {&q, &qd, &tau});
            double* o = result.mutable_data();
            const DynamicsOptions opt = options(gravity, motorInertia, friction);
            {
              py::gil_scoped_release release;
              ManipulatorData data(*p.model);
              for (py::ssize_t r = 0; r < rows; ++r) {
                const JointVector& qdd =
                    forwardDynamicsArticulatedBody(*p.model, data, row(q, r, n), row(qd, r, n), row(tau, r, n), opt);
                for (int i = 0; i < n; ++i) o[r * n + i] = qdd(i);
              }
            }
            return result;
          },
          py::arg("q"), py::arg("qd"), py::arg("tau"), py::arg("gravity") = true, py::arg("motor_inertia") = false,
          py::arg("friction") = false, py::kw_only(), py::arg("out") = py::none(), "aba of every row: N x dof");

  py::class_<PyPuma, PyModel>(m, "Puma560Model",
                              "The Unimation Puma 560 (Corke & Armstrong-Helouvry parameters), with its closed-form "
                              "inverse kinematics.")
      .def(py::init<double, const py::object&, const py::object&>(), py::arg("pedestal_height") = 0.67183,
           py::arg("base") = py::none(), py::arg("tool") = py::none())
      .def(
          "ik_all",
          [](const PyPuma& p, const py::handle& pose) {
            const Transform target = toTransform(pose, "pose");
            std::array<Puma560IkSolution, 8> solutions;
            const IkStatus status = p.puma().inverseKinematicsAll(target, solutions);
            py::list out;
            if (status != IkStatus::Solved) return out;
            for (const Puma560IkSolution& s : solutions) {
              py::dict d;
              d["q"] = fromVector(s.q);
              d["branch"] = s.branchName();
              d["within_limits"] = s.withinLimits;
              out.append(d);
            }
            return out;
          },
          py::arg("pose"), "the eight closed-form solutions (dicts: q, branch, within_limits); empty if unreachable")
      .def(
          "ik_closest",
          [](const PyPuma& p, const py::handle& pose, const py::handle& current) {
            JointVector q(6);
            const IkStatus status = p.puma().inverseKinematicsClosest(toTransform(pose, "pose"), p.q(current, "current"), q);
            return py::make_tuple(statusName(status), fromVector(q));
          },
          py::arg("pose"), py::arg("current"), "the closed-form solution within the limits closest to current: (status, q)")
      .def(
          "ik_closest_batch",
          [](const PyPuma& p, const py::handle& poses, const py::handle& currents) {
            const std::vector<Transform> targets = toTransforms(poses, "poses");
            const auto rows = static_cast<py::ssize_t>(targets.size());
            auto current = toMatrix(currents, -1, 6, "current");
            if (current.shape(0) != rows) throw py::value_error("current: one row per pose");
            py::array_t<double> out({rows, py::ssize_t{6}});
            py::array_t<bool> solved(rows);
            double* qo = out.mutable_data();
            bool* so = solved.mutable_data();
            {
              py::gil_scoped_release release;
              JointVector q(6);
              for (py::ssize_t r = 0; r < rows; ++r) {
                so[r] = p.puma().inverseKinematicsClosest(targets[static_cast<std::size_t>(r)], row(current, r, 6), q) ==
                        IkStatus::Solved;
                for (int i = 0; i < 6; ++i) qo[r * 6 + i] = q(i);
              }
            }
            return py::make_tuple(solved, out);
          },
          py::arg("poses"), py::arg("current"),
          "ik_closest of every pose of an N x 4 x 4 array, each from its row of current (N x 6): (solved, q)")
      .def(
          "branch_of", [](const PyPuma& p, const py::handle& q) { return std::string(p.puma().branchOf(p.q(q, "q")).branchName()); },
          py::arg("q"), "the branch of a joint vector, e.g. 'right-up-noflip'");

  struct PyWam : PyModel {
    using PyModel::PyModel;
  };
  py::class_<PyWam, PyModel>(m, "WAMModel", "The Barrett WAM with 4 or 7 joints.")
      .def(py::init([](int dof, const py::object& base, const py::object& tool) {
             return std::make_unique<PyWam>(makeWam(dof, base.is_none() ? Transform::unit() : toTransform(base, "base"),
                                                    tool.is_none() ? Transform::unit() : toTransform(tool, "tool")));
           }),
           py::arg("dof") = 7, py::arg("base") = py::none(), py::arg("tool") = py::none());

  struct PyUrdf : PyModel {
    using PyModel::PyModel;
  };
  py::class_<PyUrdf, PyModel>(m, "UrdfModel", "A serial arm from a URDF file (a path) or URDF text.")
      .def(py::init([](const std::string& source, const std::string& tip, bool requireDynamics) {
             return std::make_unique<PyUrdf>(makeUrdf(source, tip, requireDynamics));
           }),
           py::arg("source"), py::arg("tip") = "", py::arg("require_dynamics") = false);
}

}  // namespace rp::python
