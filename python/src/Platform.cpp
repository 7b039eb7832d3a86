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

// A manipulator the module made (owned) or one the ObjectManager made (owned by the manager: a
// shared pointer that deletes nothing). Calls that release the GIL take a copy of the pointer
// first, so close() in another thread never frees an arm under them.
struct PyManipulator {
  std::shared_ptr<DefaultManipulator> arm;
  py::object generator;  // the Python generator set on it: kept alive while the arm uses it

  ~PyManipulator() { close(); }
  // The arm, or RuntimeError once closed. Hold the result across a released GIL.
  std::shared_ptr<DefaultManipulator> ptr() const {
    if (!arm) throw std::runtime_error("the manipulator was closed");
    return arm;
  }
  DefaultManipulator& get() const { return *ptr(); }
  int dof() const { return get().getNumberOfJoints(); }
  // Destroys an owned arm (holding a moving arm until at rest) without the GIL, then lets the
  // generator go: the arm has disconnected it by then.
  void close() {
    std::shared_ptr<DefaultManipulator> last = std::move(arm);
    if (last) {
      py::gil_scoped_release release;
      last.reset();
    }
    generator = py::object();
  }
};

// Deletes with the GIL released: a generator's destructor waits until its motions have run.
struct ReleaseGilDeleter {
  template <typename T>
  void operator()(T* p) const {
    py::gil_scoped_release release;
    delete p;
  }
};

using Generator = DefaultTrajectoryGenerator<Dynamic>;

// The joints of the generator's arm, or the length of the target when it has none yet.
int jointsOf(const Generator& g, const py::handle& target) {
  const std::vector<Manipulator*> arms = g.getManipulators();  // one copy
  return arms.empty() ? static_cast<int>(py::len(target)) : arms.front()->getNumberOfJoints();
}

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
  py::gil_scoped_release release;  // construction starts a servo loop
  p->arm = std::make_shared<Arm>(std::forward<Args>(args)...);
  return p;
}

std::unique_ptr<PyManipulator> fromManager(ObjectManager& om, const std::string& name) {
  DefaultManipulator* arm = nullptr;
  {
    py::gil_scoped_release release;
    arm = om.createDerivedObject<DefaultManipulator>(name);
  }
  if (arm == nullptr) throw std::invalid_argument("object '" + name + "' is not a manipulator");
  auto p = std::make_unique<PyManipulator>();
  p->arm = std::shared_ptr<DefaultManipulator>(arm, [](DefaultManipulator*) {});  // the manager owns it
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
        std::shared_ptr<DefaultManipulator> keep = arm != nullptr ? arm->ptr() : nullptr;
        DefaultManipulator& m = keep ? *keep : *firstManipulator();
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
  m.def("is_shutdown_requested", [] { return ObjectManager::isShutdownRequested(); },
        "whether a system shutdown (a fault, Ctrl-C) has been requested");
  m.def("shutdown_reason", [] { return ObjectManager::getShutdownReason(); },
        "why the system shutdown was requested ('' if none)");

  py::class_<Generator, std::unique_ptr<Generator, ReleaseGilDeleter>>(m, "TrajectoryGenerator",
                        "The paper's DefaultTrajectoryGenerator: queued jerk-limited joint and Cartesian motions. "
                        "Destroying it waits until its motions have run.")
      .def(py::init([](const std::string& name) { return std::unique_ptr<Generator, ReleaseGilDeleter>(new Generator(name)); }),
           py::arg("name") = "")
      .def("move", [](Generator& g, const py::handle& degrees) {
             const JointVector d = toVector(degrees, jointsOf(g, degrees), "target");
             py::gil_scoped_release release;
             g.move(d);
           }, py::arg("target_degrees"), "queues a joint motion to a target in degrees (the paper's move())")
      .def("move_radians", [](Generator& g, const py::handle& q) {
             const JointVector r = toVector(q, jointsOf(g, q), "target");
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
           }, py::arg("pose"), "queues a joint-interpolated motion to a 4 x 4 end-effector pose (the inverse kinematics of the arm's model)")
      .def("stop", [](Generator& g, double seconds) {
             py::gil_scoped_release release;
             g.stop(seconds);
           }, py::arg("seconds"), "queues a dwell (the paper's stop())")
      .def("wait_until_done", [](const Generator& g, double timeout) {
             py::gil_scoped_release release;
             return g.waitUntilDone(timeout);
           }, py::arg("timeout") = -1.0, "waits until every queued motion has run; False on time-out or a shutdown")
      .def("is_done", &Generator::isDone, "whether every queued motion has been run")
      // These wait for the generator's planning lock, which a queueing thread may hold: without the GIL.
      .def("set_speed_fraction", &Generator::setSpeedFraction, py::arg("fraction"),
           py::call_guard<py::gil_scoped_release>(), "fraction (0..1] of the joint limits the motions that follow use")
      .def("set_joint_blend_radius", &Generator::setJointBlendRadius, py::arg("radians"),
           py::call_guard<py::gil_scoped_release>(), "blend radius of the joint motions that follow [rad] (0: stop at each point)")
      .def("set_synchronization", [](Generator& g, const std::string& mode) {
             const Synchronization s = synchronizationOf(mode);
             py::gil_scoped_release release;
             g.setSynchronization(s);
           }, py::arg("mode"), "'time' (the default), 'phase' or 'none' (see Planner.set_synchronization)")
      .def("set_cartesian_blend_radius", &Generator::setCartesianBlendRadius, py::arg("metres"),
           py::call_guard<py::gil_scoped_release>(), "blend radius of the Cartesian motions that follow [m] (0: stop at each point)")
      .def_property_readonly("blend_count", [](const Generator& g) {
             py::gil_scoped_release release;
             return g.getBlendCount();
           }, "the number of via points blended so far (motions joined without stopping)");

  py::class_<PyManipulator>(m, "Manipulator",
                            "A manipulator whose servo loop runs in C++ (DefaultManipulator): in simulation mode, "
                            "or behind its hardware server.")
      .def_property_readonly("name", [](const PyManipulator& p) { return p.get().getName(); }, "the object's name (its rp.cfg section)")
      .def_property_readonly("dof", &PyManipulator::dof, "number of joints")
      .def_property_readonly(
          "model",
          [](const PyManipulator& p) { return makeModelCopy(p.get().getModel()); },
          "a copy of the model (for its pose now)")
      .def("joint_position", [](const PyManipulator& p) { return fromVector(p.get().getJointPosition()); }, "the joint positions measured in the last servo cycle [rad or m]")
      .def("joint_velocity", [](const PyManipulator& p) { return fromVector(p.get().getJointVelocity()); }, "the joint velocities of the last servo cycle [rad/s or m/s]")
      .def("desired_joint_position", [](const PyManipulator& p) { return fromVector(p.get().getDesiredJointPosition()); },
           "the setpoint's position the last servo cycle published [rad]")
      .def("control_output", [](const PyManipulator& p) { return fromVector(p.get().getControlOutput()); }, "the joint torques the servo loop commanded in its last cycle [N m or N]")
      .def("end_effector_transform", [](const PyManipulator& p) { return fromMatrix(p.get().getEndEffectorTransform()); }, "the 4 x 4 end-effector pose in the world of the last servo cycle [m]")
      .def("enable_arm_power", [](const PyManipulator& p) { p.get().enableArmPower(); }, "switches the arm power on (motors enabled, brakes released); the arm holds its position")
      .def("disable_arm_power", [](const PyManipulator& p) { p.get().disableArmPower(); }, "switches the arm power off (brakes on)")
      .def_property_readonly("arm_power", [](const PyManipulator& p) { return p.get().isArmPowerOn(); }, "whether the arm power is on")
      .def("set_gravity_compensation", [](const PyManipulator& p, bool on) {
             on ? p.get().setGravityCompensationOn() : p.get().setGravityCompensationOff();
           }, py::arg("on"), "switches the servo loop's gravity compensation on or off")
      .def("set_zero_gravity_mode", [](const PyManipulator& p, bool on) {
             on ? p.get().setZeroGravityModeOn() : p.get().setZeroGravityModeOff();
           }, py::arg("on"), "on: only the gravity torque goes out (the arm can be pushed by hand); off: the servo control holds again")
      .def("apply_external_wrench", [](const PyManipulator& p, const py::handle& w) {
             const JointVector v = toVector(w, 6, "wrench");
             p.get().applyExternalWrench(Vector<6>(v));
           }, py::arg("wrench"), "force [N] and moment [N m] on the simulated end-effector, in world coordinates")
      .def("set_transform", [](const PyManipulator& p, const py::handle& pose) {
             const Transform t = toTransform(pose, "pose");
             const auto arm = p.ptr();
             py::gil_scoped_release release;
             arm->setTransform(t);
           }, py::arg("pose"), "places the arm's base at a 4 x 4 pose in the world (allowed while nothing drives the arm)")
      .def("set_simulation_mode", [](const PyManipulator& p, bool on) {
             const auto arm = p.ptr();
             py::gil_scoped_release release;
             on ? arm->setSimulationModeOn() : arm->setSimulationModeOff();
           }, py::arg("on"), "switches between the simulated arm (True) and the hardware (False), at the next cycle boundary")
      .def_property_readonly("simulation_mode", [](const PyManipulator& p) { return p.get().isSimulationModeOn(); }, "whether the arm runs in simulation mode")
      .def_property_readonly("uses_hardware", [](const PyManipulator& p) { return p.get().usesHardware(); }, "whether the arm is reached through a hardware server (simulation mode off)")
      .def_property_readonly("error_code", [](const PyManipulator& p) { return p.get().getErrorCode(); }, "the object's error code (0: no error)")
      .def_property_readonly("error_message", [](const PyManipulator& p) { return p.get().getErrorStatus().message; }, "the object's error message ('' if none)")
      .def_property_readonly("cycle_count", [](const PyManipulator& p) { return p.get().getCycleCount(); }, "the number of servo cycles run")
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
           }, "the names of the servo loop's parameters (gains and the like)")
      .def("set_trajectory_generator", [](PyManipulator& p, py::object generator) {
             Generator& g = generator.cast<Generator&>();
             const auto arm = p.ptr();
             {
               py::gil_scoped_release release;
               arm->setTrajectoryGenerator(g);
             }
             p.generator = std::move(generator);
           }, py::arg("generator"), "connects a TrajectoryGenerator (kept alive while connected)")
      .def("clear_trajectory_generator", [](PyManipulator& p) {
             const auto arm = p.ptr();
             {
               py::gil_scoped_release release;
               arm->clearTrajectoryGenerator();
             }
             p.generator = py::none();
           }, "detaches the trajectory generator: the arm holds where it is")
      .def("run_cycles", [](const PyManipulator& p, std::uint64_t cycles) {
             const auto arm = p.ptr();
             py::gil_scoped_release release;
             return arm->runCycles(cycles);
           }, py::arg("cycles"), "runs exactly this many servo cycles (simulated clock: then pauses it)")
      .def("close", &PyManipulator::close,
           "destroys the manipulator now (holding a moving arm until at rest first); later calls raise RuntimeError");

  m.def("Puma560", [](const std::string& name) { return make<Puma560>(name); }, py::arg("name") = "",
        "A Puma 560 (simulated unless -nosim and rp.cfg give it a hardware server).");
  m.def("WAM", [](const std::string& name) { return make<WAM>(name); }, py::arg("name") = "",
        "A Barrett WAM, 7 joints or 4 (rp.cfg `links 4`); simulated unless -nosim and rp.cfg give it a hardware server.");
  m.def("UrdfManipulator", [](const std::string& name, const std::string& urdf, const std::string& tip) {
          return make<UrdfManipulator>(name, urdf, tip);
        }, py::arg("name") = "", py::arg("urdf") = "", py::arg("tip") = "",
        "An arm from a URDF file (urdf) up to its link tip, or as its rp.cfg section says; simulated unless -nosim and a hardware server.");

  py::class_<DefaultGripper, std::unique_ptr<DefaultGripper, ReleaseGilDeleter>>(m, "DefaultGripper",
                             "The paper's DefaultGripper: open/close through an I/O board, or simulated.")
      .def(py::init([](const std::string& name) {
             py::gil_scoped_release release;
             return std::unique_ptr<DefaultGripper, ReleaseGilDeleter>(new DefaultGripper(name));
           }),
           py::arg("name") = "")
      .def("open", [](DefaultGripper& g) {
             py::gil_scoped_release release;
             return g.open();
           }, "opens the gripper; False if the hardware refused")
      .def("close", [](DefaultGripper& g) {
             py::gil_scoped_release release;
             return g.close();
           }, "closes the gripper; False if the hardware refused")
      .def("relax", [](DefaultGripper& g) {
             py::gil_scoped_release release;
             return g.relax();
           }, "neither opens nor closes (the actuator off); False if the hardware refused")
      .def_property_readonly("state", [](const DefaultGripper& g) { return std::string(Gripper::stateName(g.getState())); }, "the gripper's state: 'open', 'closed', 'relaxed' or 'unknown' (before the first command)");

  py::class_<ObjectManager>(m, "ObjectManager", "The paper's object manager.")
      .def(py::init<>())
      .def("create_derived_object", &fromManager, py::arg("name"),
           "creates the manipulator rp.cfg's section [name] describes (owned by the manager)")
      .def("createDerivedObject", &fromManager, py::arg("name"), "the paper's spelling of create_derived_object()");
}

}  // namespace rp::python
