// The platform in Python: init, manipulators (Puma560, WAM, UrdfManipulator, or any class rp.cfg
// names), the paper's motion commands through DefaultTrajectoryGenerator, parameters of the
// running control program, and the simulated clock stepped from Python. The servo loops stay in
// C++: no Python code runs inside a servo cycle, and every call that waits releases the GIL.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <string>
#include <vector>

#include "Arrays.hpp"
#include "Bindings.hpp"
#include "rp/RoboticPlatform.hpp"

namespace rp::python {

namespace {

// A manipulator the module made (owned) or one the ObjectManager made (not owned).
struct PyManipulator {
  std::unique_ptr<DefaultManipulator> owned;
  DefaultManipulator* arm = nullptr;
  py::object generator;  // the Python generator set on it: kept alive while the arm uses it

  DefaultManipulator& get() const {
    if (arm == nullptr) throw std::runtime_error("the manipulator was destroyed");
    return *arm;
  }
  int dof() const { return get().getNumberOfJoints(); }
};

using Generator = DefaultTrajectoryGenerator<Dynamic>;

SimulatedClock& simulatedClock() {
  auto* clock = dynamic_cast<SimulatedClock*>(&RoboticPlatform::getDefaultClock());
  if (clock == nullptr) throw std::runtime_error("the platform runs on the real clock: use rp.init(['-simclock']) to step it");
  return *clock;
}

DefaultManipulator* firstManipulator() {
  ObjectManager om;
  for (DefaultManipulator* m : om.getDerivedObjects<DefaultManipulator>())
    if (m->isRunning()) return m;
  throw std::runtime_error("rp.step: no manipulator is running");
}

template <typename Arm, typename... Args>
std::unique_ptr<PyManipulator> make(Args&&... args) {
  auto p = std::make_unique<PyManipulator>();
  {
    py::gil_scoped_release release;  // construction starts a servo loop
    p->owned = std::make_unique<Arm>(std::forward<Args>(args)...);
  }
  p->arm = p->owned.get();
  return p;
}

}  // namespace

void bindPlatform(py::module_& m) {
  m.def(
      "init",
      [](const std::vector<std::string>& args) {
        // Checked first, so that a bad switch or rp.cfg is a Python exception (init() would exit).
        const std::vector<std::string> own = RoboticPlatform::parseCommandLine(args);
        RoboticPlatform::loadConfiguration();
        std::vector<std::string> storage{"python"};
        storage.insert(storage.end(), args.begin(), args.end());
        std::vector<char*> argv;
        for (std::string& s : storage) argv.push_back(s.data());
        argv.push_back(nullptr);
        int argc = static_cast<int>(storage.size());
        RoboticPlatform::init(argc, argv.data());
        return own;
      },
      py::arg("args") = std::vector<std::string>{},
      "Initialises the platform with the paper's switches (-sim, -nosim, -simclock, -nogui, -config FILE, -log "
      "FILE, ...). Returns the arguments that are not platform switches. Raises ValueError for a bad switch and "
      "ConfigError for a bad rp.cfg. Installs the platform's SIGINT/SIGTERM handlers (Ctrl-C shuts the system "
      "down safely and completes the log).");
  m.def(
      "step",
      [](std::uint64_t cycles, PyManipulator* arm) {
        simulatedClock();
        DefaultManipulator& m = arm != nullptr ? arm->get() : *firstManipulator();
        bool ok = false;
        {
          py::gil_scoped_release release;
          ok = m.runCycles(cycles);
        }
        if (!ok) throw std::runtime_error("rp.step: the servo loop did not run " + std::to_string(cycles) + " cycles");
      },
      py::arg("cycles") = 1, py::arg("arm") = nullptr,
      "Runs exactly `cycles` servo cycles on the simulated clock (of `arm`, or of the first manipulator) and pauses the "
      "clock: reproducible notebooks. Needs -simclock.");
  m.def("pause", [] { simulatedClock().pause(); }, "Pauses the simulated clock.");
  m.def("resume", [] { simulatedClock().resume(); }, "Lets the simulated clock run (as fast as possible).");
  m.def("time", [] { return RoboticPlatform::getDefaultClock().getTime(); }, "The platform clock's time [s].");
  m.def("is_shutdown_requested", [] { return ObjectManager::isShutdownRequested(); });
  m.def("shutdown_reason", [] { return ObjectManager::getShutdownReason(); });

  py::class_<Generator>(m, "TrajectoryGenerator",
                        "The paper's DefaultTrajectoryGenerator: queued jerk-limited joint and Cartesian motions. "
                        "Destroying it waits until its motions have run.")
      .def(py::init([](const std::string& name) { return std::make_unique<Generator>(name); }), py::arg("name") = "")
      .def("move", [](Generator& g, const py::handle& degrees) {
             const JointVector d = toVector(degrees, g.getManipulators().empty() ? static_cast<int>(py::len(degrees))
                                                                                  : g.getManipulators()[0]->getNumberOfJoints(),
                                            "target");
             py::gil_scoped_release release;
             g.move(d);
           }, py::arg("target_degrees"), "queues a joint motion to a target in degrees (the paper's move())")
      .def("move_radians", [](Generator& g, const py::handle& q) {
             const JointVector r = toVector(q, g.getManipulators().empty() ? static_cast<int>(py::len(q))
                                                                            : g.getManipulators()[0]->getNumberOfJoints(),
                                            "target");
             py::gil_scoped_release release;
             g.moveRadians(r);
           }, py::arg("target"), "queues a joint motion to a target in radians")
      .def("move_to", [](Generator& g, const py::handle& pose) {
             const Transform t = toTransform(pose, "pose");
             py::gil_scoped_release release;
             g.moveTo(t);
           }, py::arg("pose"), "queues a straight-line Cartesian motion of the end-effector to a 4 x 4 pose")
      .def("move_to_through_joint_space", [](Generator& g, const py::handle& pose) {
             const Transform t = toTransform(pose, "pose");
             py::gil_scoped_release release;
             g.moveToThroughJointSpace(t);
           }, py::arg("pose"))
      .def("stop", [](Generator& g, double seconds) {
             py::gil_scoped_release release;
             g.stop(seconds);
           }, py::arg("seconds"), "queues a dwell (the paper's stop())")
      .def("wait_until_done", [](const Generator& g, double timeout) {
             py::gil_scoped_release release;
             return g.waitUntilDone(timeout);
           }, py::arg("timeout") = -1.0, "waits until every queued motion has run; False on time-out or a shutdown")
      .def("is_done", &Generator::isDone)
      .def("set_speed_fraction", &Generator::setSpeedFraction, py::arg("fraction"))
      .def("set_joint_blend_radius", &Generator::setJointBlendRadius, py::arg("radians"))
      .def("set_cartesian_blend_radius", &Generator::setCartesianBlendRadius, py::arg("metres"))
      .def_property_readonly("blend_count", &Generator::getBlendCount);

  py::class_<PyManipulator>(m, "Manipulator",
                            "A manipulator whose servo loop runs in C++ (DefaultManipulator): in simulation mode, "
                            "or behind its hardware server.")
      .def_property_readonly("name", [](const PyManipulator& p) { return p.get().getName(); })
      .def_property_readonly("dof", &PyManipulator::dof)
      .def_property_readonly(
          "model",
          [](const PyManipulator& p) { return makeModelCopy(p.get().getModel()); },
          "a copy of the model (for its pose now)")
      .def("joint_position", [](const PyManipulator& p) { return fromVector(p.get().getJointPosition()); })
      .def("joint_velocity", [](const PyManipulator& p) { return fromVector(p.get().getJointVelocity()); })
      .def("control_output", [](const PyManipulator& p) { return fromVector(p.get().getControlOutput()); })
      .def("end_effector_transform", [](const PyManipulator& p) { return fromMatrix(p.get().getEndEffectorTransform()); })
      .def("enable_arm_power", [](const PyManipulator& p) { p.get().enableArmPower(); })
      .def("disable_arm_power", [](const PyManipulator& p) { p.get().disableArmPower(); })
      .def_property_readonly("arm_power", [](const PyManipulator& p) { return p.get().isArmPowerOn(); })
      .def("set_gravity_compensation", [](const PyManipulator& p, bool on) {
             on ? p.get().setGravityCompensationOn() : p.get().setGravityCompensationOff();
           }, py::arg("on"))
      .def("set_zero_gravity_mode", [](const PyManipulator& p, bool on) {
             on ? p.get().setZeroGravityModeOn() : p.get().setZeroGravityModeOff();
           }, py::arg("on"))
      .def("apply_external_wrench", [](const PyManipulator& p, const py::handle& w) {
             const JointVector v = toVector(w, 6, "wrench");
             p.get().applyExternalWrench(Vector<6>(v));
           }, py::arg("wrench"), "force [N] and moment [N m] on the simulated end-effector, in world coordinates")
      .def("set_transform", [](const PyManipulator& p, const py::handle& pose) {
             const Transform t = toTransform(pose, "pose");
             py::gil_scoped_release release;
             p.get().setTransform(t);
           }, py::arg("pose"))
      .def("set_simulation_mode", [](const PyManipulator& p, bool on) {
             py::gil_scoped_release release;
             on ? p.get().setSimulationModeOn() : p.get().setSimulationModeOff();
           }, py::arg("on"))
      .def_property_readonly("simulation_mode", [](const PyManipulator& p) { return p.get().isSimulationModeOn(); })
      .def_property_readonly("uses_hardware", [](const PyManipulator& p) { return p.get().usesHardware(); })
      .def_property_readonly("error_code", [](const PyManipulator& p) { return p.get().getErrorCode(); })
      .def_property_readonly("error_message", [](const PyManipulator& p) { return p.get().getErrorStatus().message; })
      .def_property_readonly("cycle_count", [](const PyManipulator& p) { return p.get().getCycleCount(); })
      .def("parameter", [](const PyManipulator& p, const std::string& name) { return p.get().getParameter(name); },
           py::arg("name"), "the values of a parameter of the servo loop (e.g. 'kp', 'kd', 'ki')")
      .def("set_parameter", [](const PyManipulator& p, const std::string& name, const std::vector<double>& values) {
             try {
               p.get().setParameter(name, values);
             } catch (const std::out_of_range& e) {
               throw py::value_error(e.what());  // a value outside the parameter's range
             }
           }, py::arg("name"), py::arg("values"), "new values for every element (checked against the parameter's range)")
      .def("parameters", [](const PyManipulator& p) {
             std::vector<std::string> names;
             for (const ParameterInfo& info : p.get().getParameters()) names.push_back(info.name);
             return names;
           })
      .def("set_trajectory_generator", [](PyManipulator& p, py::object generator) {
             Generator& g = generator.cast<Generator&>();
             {
               py::gil_scoped_release release;
               p.get().setTrajectoryGenerator(g);
             }
             p.generator = std::move(generator);
           }, py::arg("generator"), "connects a TrajectoryGenerator (kept alive while connected)")
      .def("clear_trajectory_generator", [](PyManipulator& p) {
             {
               py::gil_scoped_release release;
               p.get().clearTrajectoryGenerator();
             }
             p.generator = py::none();
           })
      .def("run_cycles", [](const PyManipulator& p, std::uint64_t cycles) {
             py::gil_scoped_release release;
             return p.get().runCycles(cycles);
           }, py::arg("cycles"), "runs exactly this many servo cycles (simulated clock: then pauses it)")
      .def("close", [](PyManipulator& p) {
             if (p.owned) {
               py::gil_scoped_release release;
               p.owned.reset();  // holds a moving arm until at rest, powers it off
             }
             p.arm = nullptr;
             p.generator = py::none();
           }, "destroys the manipulator now (holding a moving arm until at rest first)");

  m.def("Puma560", [](const std::string& name) { return make<Puma560>(name); }, py::arg("name") = "",
        "A Puma 560 (simulated unless -nosim and rp.cfg give it a hardware server).");
  m.def("WAM", [](const std::string& name) { return make<WAM>(name); }, py::arg("name") = "");
  m.def("UrdfManipulator", [](const std::string& name, const std::string& urdf, const std::string& tip) {
          return make<UrdfManipulator>(name, urdf, tip);
        }, py::arg("name") = "", py::arg("urdf") = "", py::arg("tip") = "");

  py::class_<DefaultGripper>(m, "DefaultGripper",
                             "The paper's DefaultGripper: open/close through an I/O board, or simulated.")
      .def(py::init([](const std::string& name) {
             py::gil_scoped_release release;
             return std::make_unique<DefaultGripper>(name);
           }),
           py::arg("name") = "")
      .def("open", [](DefaultGripper& g) {
             py::gil_scoped_release release;
             return g.open();
           }, "opens the gripper; False if the hardware refused")
      .def("close", [](DefaultGripper& g) {
             py::gil_scoped_release release;
             return g.close();
           })
      .def("relax", [](DefaultGripper& g) {
             py::gil_scoped_release release;
             return g.relax();
           })
      .def_property_readonly("state", [](const DefaultGripper& g) { return std::string(Gripper::stateName(g.getState())); });

  py::class_<ObjectManager>(m, "ObjectManager", "The paper's object manager.")
      .def(py::init<>())
      .def("create_derived_object", [](ObjectManager& om, const std::string& name) {
             auto p = std::make_unique<PyManipulator>();
             {
               py::gil_scoped_release release;
               p->arm = om.createDerivedObject<DefaultManipulator>(name);
             }
             if (p->arm == nullptr) throw std::invalid_argument("object '" + name + "' is not a manipulator");
             return p;
           }, py::arg("name"), "creates the manipulator rp.cfg's section [name] describes (owned by the manager)")
      .def("createDerivedObject", [](ObjectManager& om, const std::string& name) {
             auto p = std::make_unique<PyManipulator>();
             {
               py::gil_scoped_release release;
               p->arm = om.createDerivedObject<DefaultManipulator>(name);
             }
             if (p->arm == nullptr) throw std::invalid_argument("object '" + name + "' is not a manipulator");
             return p;
           }, py::arg("name"), "the paper's spelling of create_derived_object()");
}

}  // namespace rp::python
