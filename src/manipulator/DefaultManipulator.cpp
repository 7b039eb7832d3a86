// The servo loop of open-architecture manipulators (rp/manipulator/DefaultManipulator.hpp).
#include "rp/manipulator/DefaultManipulator.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <stdexcept>

#include "rp/control/ServoControl.hpp"
#include "rp/core/ObjectManager.hpp"
#include "rp/model/Dynamics.hpp"
#include "rp/io/HwServerIoBoard.hpp"
#include "rp/ros2/Ros2IoBoard.hpp"
#include "../ros2/Ros2Common.hpp"
#include "ArmSnapshot.hpp"
#include "rp/io/IoException.hpp"
#include "rp/model/Kinematics.hpp"
#include "rp/rt/Clock.hpp"
#include "rp/trajectory/TrajectoryGenerator.hpp"
#include "../model/ChainInternal.hpp"
#include "../model/ThreadWorkspace.hpp"
#include "LinkShapes.hpp"
#include "SeqlockHandover.hpp"

namespace rp {

// External wrenches (slot 0: the end-effector's; slot k: link k's, with its point) cross from
// user threads to the servo thread through a SeqlockHandover: writers (serialised by a mutex)
// never block the reader, which retries a torn read and skips the copy when nothing changed.
struct DefaultManipulator::WrenchBox {
  static constexpr int kSlot = 9;  // point (3), then force and moment (6)
  static constexpr std::size_t kSize = kSlot * (kMaxJoints + 1);
  std::mutex writerMutex;
  internal::SeqlockHandover<kSize> values;
  // Servo thread's: the last consistent copy and the version it was read at.
  double snapshot[kSize] = {};
  std::uint64_t lastRead = 0;

  void write(int slot, const Vector<3>& point, const Vector<6>& w) {
    const double v[kSlot] = {point(0), point(1), point(2), w(0), w(1), w(2), w(3), w(4), w(5)};
    std::lock_guard<std::mutex> lock(writerMutex);
    values.store(static_cast<std::size_t>(slot * kSlot), v, kSlot);
  }
  // Real-time safe: lock-free. Returns true with a new snapshot (the first `slots` slots) when a
  // write happened since the last read; gives up (keeping the old one) after a few torn reads.
  bool read(int slots) {
    if (current()) return false;
    for (int attempt = 0; attempt < 8; ++attempt)
      if (values.tryLoad(snapshot, static_cast<std::size_t>(slots * kSlot), &lastRead)) return true;
    return false;
  }
  // Whether the snapshot has every write so far.
  bool current() const noexcept { return values.version() == lastRead; }
};

namespace {
constexpr double kRestVelocity = 1e-3;  // [rad/s] below which the arm counts as at rest
constexpr double kRestDuration = 0.05;  // [s] at rest before the power goes off in a shutdown
constexpr double kShutdownTimeout = 3.0;  // [s] longest damped hold
constexpr double kSwitchRestVelocity = 0.01;  // [rad/s] at rest enough to leave the hardware
constexpr double kVelocityCutoffHz = 50.0;    // a hardware arm's velocity filter (second order)

// What a test for rest may ask of a hardware arm's velocity, at least `floor` [rad/s]. The velocity
// is the encoders' backward difference through a second-order Butterworth low-pass at
// kVelocityCutoffHz (readHardware()), which answers a step of one count with a pulse peaking at
// wc e^(-pi/4) counts per second, wc = 2 pi fc (the peak of the filter's impulse response
// sqrt(2) wc e^(-wc t/sqrt(2)) sin(wc t/sqrt(2))): 0.0072 rad/s at the Puma's 20000 counts/rad. An
// arm held still dithers by a count or two, so anything below three counts' pulse is rest: a
// stricter test would refuse or wait on a still arm at random.
double restTolerance(double floor, double countsPerRadian) {
  const double countPulse = 2.0 * M_PI * kVelocityCutoffHz * std::exp(-M_PI / 4.0) / countsPerRadian;
  return std::max(floor, 3.0 * countPulse);
}
const std::string kServoControlCommand = "Servo Control: ";  // + the control's name

// A setpoint that an arm standing at q can take over without a jump: within these of it.
constexpr double kHandOverPosition = 0.01;  // [rad or m]
constexpr double kHandOverVelocity = 0.05;  // [rad/s or m/s]

// The first joint whose setpoint is no hand-over from standing at q, or -1.
int awayFromTheArm(const JointVector& q, const Setpoint& setpoint) {
  for (int i = 0; i < q.size(); ++i)
    if (std::abs(setpoint.position(i) - q(i)) > kHandOverPosition || std::abs(setpoint.velocity(i)) > kHandOverVelocity)
      return i;
  return -1;
}

int firstNonFinite(const JointVector& v) {
  for (int i = 0; i < v.size(); ++i)
    if (!std::isfinite(v(i))) return i;
  return -1;
}

// Whether rp.cfg wires the arm to hardware: a hardware server, or a remote arm over DDS.
bool configuresHardware(const ConfigSection* section) {
  return section != nullptr && (section->has("hwserver") || section->has("remote"));
}

// The settings that belong to a remote arm are refused without `remote`, and countsPerRadian with
// it (the remote board's counts are its own): a setting that would be ignored is a mistake.
void checkRemoteSettings(const ConfigSection& section) {
  const bool remote = section.has("remote");
  for (const char* key : {"domain", "interfaces", "timeout", "connectTimeout"})
    if (!remote)
      if (const ConfigSetting* s = section.find(key))
        throw section.errorAt(*s, std::string("setting '") + key + "' is for an arm in another process: add 'remote NS/OBJECT'");
  if (remote)
    if (const ConfigSetting* s = section.find("countsPerRadian"))
      throw section.errorAt(*s, "setting 'countsPerRadian' is not for a remote arm (its joint_states are in radians)");
}

// The I/O board of a remote arm (rp.cfg `remote NS/OBJECT` and its settings); a bad setting is a
// ConfigError at its line, a remote arm that does not answer an IoException.
std::unique_ptr<IoBoard> makeRemoteBoard(const ConfigSection& section, const ManipulatorModel& model) {
  const ConfigSetting& remote = *section.find("remote");
  if (const ConfigSetting* hw = section.find("hwserver"))
    throw section.errorAt(*hw, "an arm is wired to a hardware server (hwserver) or to a remote arm (remote), not both");
  Ros2IoBoardOptions o;
  o.remote = section.getWord("remote");
  if (section.has("domain")) o.domain = static_cast<int>(section.getNumbers("domain").at(0));
  if (section.has("interfaces")) o.interfaces = section.find("interfaces")->values;
  if (section.has("timeout")) o.timeout = section.getNumbers("timeout").at(0);
  if (section.has("connectTimeout")) o.connectTimeout = section.getNumbers("connectTimeout").at(0);
  if (const std::string why = Ros2IoBoard::checkOptions(o); !why.empty()) {
    const ConfigSetting* at = &remote;
    for (const char* key : {"interfaces", "timeout", "connectTimeout"})
      if (why.rfind(key, 0) == 0 && section.find(key) != nullptr) at = section.find(key);
    throw section.errorAt(*at, "setting " + why);
  }
  std::vector<std::string> joints;
  std::vector<double> newtonMetresPerVolt;
  for (int i = 0; i < model.getNumberOfJoints(); ++i) {
    joints.push_back(model.getJointName(i));
    newtonMetresPerVolt.push_back(model.getTorqueLimit()(i) / 10.0);  // as writeHardware()'s amplifier: 10 V is the limit
  }
  try {
    return std::make_unique<Ros2IoBoard>(o, joints, newtonMetresPerVolt);
  } catch (const IoException& e) {
    throw IoException(section.fileName() + ":" + std::to_string(remote.line) + ": setting 'remote " + o.remote + "': " + e.what());
  }
}
}  // namespace

// The payload of setPayload(): kept for makeSetup() and getPayload...() under setupMutex_, and handed
// to the servo thread.
struct DefaultManipulator::PayloadBox {
  double mass = 0;
  Vector<3> centre = Vector<3>::Zero();
  internal::SeqlockHandover<4> handover;  // mass [kg], centre [m]
};

struct DefaultManipulator::Setup {
  std::unique_ptr<ManipulatorModel> model;
  std::unique_ptr<ManipulatorData> data;
  std::unique_ptr<ManipulatorSimulation> sim;
  std::unique_ptr<IoBoard> board;  // a new hardware connection (none: simulation, or keepBoard)
  std::unique_ptr<Differentiator<JointVector>> velocity;
  double countsPerRadian = 20000;
  bool noHardware = false;  // simulation off, no hardware configured
  bool keepBoard = false;   // the hardware stays: only the pose changed
};

std::unique_ptr<DefaultManipulator::Setup> DefaultManipulator::makeSetup(bool simulation, const Transform& base) const {
  if (const ConfigSection* section = configSection()) checkRemoteSettings(*section);
  auto setup = std::make_unique<Setup>();
  setup->model = modelFactory_(base);
  if (!setup->model) throw std::invalid_argument("DefaultManipulator '" + getName() + "': no model");
  if (!simulation) {
    const ConfigSection* section = configSection();
    if (board_ != nullptr) {
      setup->keepBoard = true;
    } else if (!configuresHardware(section)) {
      // No hardware: the arm stays unpowered until the program switches it to simulation
      // (setSimulationModeOn() right after the declaration, as the paper's Figure 23 does); see
      // control() and enableArmPower().
      setup->noHardware = true;
    } else {
      if (section->has("remote")) {
        // An arm in another process, driven by torque over DDS (Ros2IoBoard).
        setup->countsPerRadian = Ros2IoBoard::kCountsPerRadian;
        setup->board = makeRemoteBoard(*section, *setup->model);
      } else {
        if (section->has("countsPerRadian")) setup->countsPerRadian = section->getNumbers("countsPerRadian").at(0);
        setup->board = std::make_unique<HwServerIoBoard>(section->getWord("hwserver"));  // throws IoException if absent
      }
      setup->velocity = std::make_unique<Differentiator<JointVector>>(getPeriod(), kVelocityCutoffHz, 2);
    }
  }
  setup->data = std::make_unique<ManipulatorData>(*setup->model);
  setup->sim = makeSimulation(*setup->model, configSection());  // the plant, with rp.cfg's deviations
  if (payload_ != nullptr && payload_->mass > 0) setup->sim->setPayload(payload_->mass, payload_->centre);
  return setup;
}

void DefaultManipulator::install(Setup& setup) noexcept {
  std::swap(model_, setup.model);
  std::swap(data_, setup.data);
  std::swap(sim_, setup.sim);
  if (!setup.keepBoard) {
    std::swap(board_, setup.board);
    std::swap(velocity_, setup.velocity);
    countsPerRadian_ = setup.countsPerRadian;
  }
  noHardware_.store(setup.noHardware, std::memory_order_relaxed);
  noHardwareSince_ = -1;
  usesHardware_.store(board_ != nullptr, std::memory_order_release);
  modelView_.store(model_.get(), std::memory_order_release);
}

DefaultManipulator::SetupResult DefaultManipulator::checkSetup(const Setup& setup) const noexcept {
  // In the servo thread, between cycles: what the caller checked may have changed since.
  if (shutdownPhase_.load(std::memory_order_acquire) != 0 || loopEnded_.load()) return SetupResult::kShutdown;
  if (generator_.load(std::memory_order_acquire) != nullptr ||
      servoControl_.load(std::memory_order_acquire) != defaultControl_.get() ||
      zeroGravity_.load(std::memory_order_relaxed)) {
    return SetupResult::kDriven;
  }
  // Leaving the hardware switches its amplifiers off: only with the arm at rest.
  if (board_ != nullptr && !setup.keepBoard && power_ &&
      qd_.cwiseAbs().maxCoeff() > restTolerance(kSwitchRestVelocity, countsPerRadian_))
    return SetupResult::kMoving;
  // The new hardware must answer before it takes over.
  if (setup.board != nullptr) {
    for (int i = 0; i < q_.size(); ++i) {
      std::int64_t counts = 0;
      if (setup.board->readEncoder(i, counts) != IoStatus::kOk) return SetupResult::kHardwareFailed;
    }
  }
  return SetupResult::kApplied;
}

void DefaultManipulator::applySetup(Setup& setup) noexcept {
  if (board_ != nullptr && !setup.keepBoard) writeOutputsOff();  // leaving this hardware: amplifiers off, 0 V
  install(setup);
  if (board_ != nullptr) {
    // The hardware takes over: the arm is where its encoders say.
    velocity_->reset();
    lastSampleTime_ = 0;
    if (!readHardware(getPeriod())) return ioFailure("reading the encoders", 0);
    (void)velocity_->differentiate(q_);
    qd_.setZero();
  } else {
    // A simulation takes over from the joint state the arm had.
    sim_->setState(q_, qd_);
    sim_->setBrakes(!power_);
    applyWrenches(static_cast<int>(q_.size()));
  }
  hold_ = q_;
  setpoint_.position = q_;
  activeControl_ = nullptr;  // the servo control starts afresh (activate())
  lastCycleTime_ = -1;       // nothing to catch up across the change
}

void DefaultManipulator::applyWrenches(int n) {
  Vector<3> point;
  Vector<6> wrench;
  for (int k = 0; k <= n; ++k) {
    const double* slot = wrench_->snapshot + k * WrenchBox::kSlot;
    for (int i = 0; i < 3; ++i) point(i) = slot[i];
    for (int i = 0; i < 6; ++i) wrench(i) = slot[3 + i];
    if (k == 0) {
      sim_->setExternalWrench(wrench);
    } else {
      sim_->setExternalLinkWrench(k, point, wrench);
    }
  }
}

void DefaultManipulator::physicalSetupChanged() {
  if (modelView_.load() == nullptr) return;  // the constructor has not built the parts yet
  std::lock_guard<std::mutex> lock(setupMutex_);
  const bool simulation = isSimulationModeOn();
  const Transform base = getWorldTransform();
  if (simulation == builtForSimulation_ && base == builtBase_) return;
  if (shutdownPhase_.load() != 0 || loopEnded_.load()) {
    throw std::logic_error("manipulator '" + getName() +
                           "': the pose, mount and simulation mode cannot change during or after a shutdown");
  }
  if (inServoThread() || ControlProgram::isLoopThread()) {
    throw std::logic_error("manipulator '" + getName() +
                           "': the pose, mount and simulation mode cannot change from inside a control loop");
  }
  if (generator_.load() != nullptr || servoControl_.load() != defaultControl_.get() || zeroGravity_.load()) {
    throw std::logic_error("manipulator '" + getName() +
                           "': set the pose, mount and simulation mode before a trajectory generator or a servo "
                           "control of the program drives the arm, and not in zero-gravity mode (clear them first)");
  }
  if (!simulation && builtForSimulation_) {
    const ConfigSection* section = configSection();
    if (!configuresHardware(section)) throw std::runtime_error(noHardwareMessage());
  }
  std::unique_ptr<Setup> setup = makeSetup(simulation, base);  // may throw: nothing changed yet
  if (!isRunning()) {
    // No servo thread (a derived constructor): checked and applied here.
    setupResult_.store(static_cast<int>(checkSetup(*setup)));
    if (setupResult_.load() == static_cast<int>(SetupResult::kApplied)) {
      applySetup(*setup);
      for (int i = 0; i < initial_.n; ++i) initial_.q[i] = initial_.qdes[i] = q_(i);
    }
  } else {
    // The servo thread takes it between two cycles; a paused simulated clock is stepped until it has.
    Setup* handed = setup.get();
    appliedSetup_.store(nullptr);
    pendingSetup_.store(handed, std::memory_order_release);
    auto* simulated = dynamic_cast<SimulatedClock*>(&getClock());
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
    while (appliedSetup_.load(std::memory_order_acquire) != handed) {
      if (!isRunning() || loopEnded_.load() || std::chrono::steady_clock::now() > deadline) {
        Setup* expected = handed;
        if (pendingSetup_.compare_exchange_strong(expected, nullptr)) {
          throw std::runtime_error("manipulator '" + getName() +
                                   "': the servo loop did not take the change of pose or simulation mode");
        }
        // Taken just now: it is being applied.
      }
      if (simulated != nullptr && simulated->isPaused()) {
        (void)runCycles(1, 1.0);  // a cycle already under way when the clock stopped may not take it
      } else {
        std::this_thread::sleep_for(std::chrono::microseconds(200));
      }
    }
  }
  switch (static_cast<SetupResult>(setupResult_.load(std::memory_order_acquire))) {
    case SetupResult::kApplied:
      break;
    case SetupResult::kShutdown:
      throw std::logic_error("manipulator '" + getName() +
                             "': the pose, mount and simulation mode cannot change during or after a shutdown");
    case SetupResult::kDriven:
      throw std::logic_error("manipulator '" + getName() +
                             "': set the pose, mount and simulation mode before a trajectory generator or a servo "
                             "control of the program drives the arm, and not in zero-gravity mode (clear them first)");
    case SetupResult::kMoving:
      throw std::logic_error("manipulator '" + getName() +
                             "': the arm must be at rest to leave the hardware (its amplifiers go off)");
    case SetupResult::kHardwareFailed:
      throw IoException("manipulator '" + getName() + "': the hardware (rp.cfg '" + std::string(configSection() && configSection()->has("remote") ? "remote" : "hwserver") +
                        "') does not answer: cannot read the joints");
  }
  builtForSimulation_ = simulation;
  builtBase_ = base;
  retiredModels_.push_back(std::move(setup->model));  // the old parts (outputs already off)
}

DefaultManipulator::DefaultManipulator(const std::string& name, const ModelFactory& modelFactory)
    : Manipulator(name), ControlProgram(name.empty() ? "manipulator" : name), modelFactory_(modelFactory) {
  setProgramName(getName());
  builtForSimulation_ = isSimulationModeOn();
  builtBase_ = getWorldTransform();
  std::unique_ptr<Setup> setup = makeSetup(builtForSimulation_, builtBase_);
  install(*setup);
  payload_ = std::make_unique<PayloadBox>();
  const int n = model_->getNumberOfJoints();
  wrench_ = std::make_unique<WrenchBox>();
  for (JointVector* v : {&q_, &qd_, &tau_, &gravity_, &hold_}) v->setZero(n);
  for (JointVector* v : {&setpoint_.position, &setpoint_.velocity, &setpoint_.acceleration}) v->setZero(n);
  q_ = sim_->getPosition();
  if (board_) {
    if (!readHardware(getPeriod())) {
      throw std::runtime_error("manipulator '" + getName() + "': cannot read the joints: " + board_->lastError());
    }
  }
  hold_ = q_;  // (the loop's first cycle holds again, where it reads the arm)
  setpoint_.position = q_;
  std::snprintf(nameBuffer_, sizeof nameBuffer_, "%s", getName().c_str());

  initial_.n = n;
  for (int i = 0; i < n; ++i) initial_.q[i] = initial_.qdes[i] = q_(i);

  defaultControl_ = std::make_unique<DefaultPositionControl>(getName() + ".control");
  defaultControl_->attach(*this);
  servoControl_.store(defaultControl_.get());

  registerLogVariable("q", q_.data(), static_cast<std::size_t>(n), "rad");
  registerLogVariable("qd", qd_.data(), static_cast<std::size_t>(n), "rad/s");
  registerLogVariable("qdes", setpoint_.position.data(), static_cast<std::size_t>(n), "rad");
  registerLogVariable("qddes", setpoint_.velocity.data(), static_cast<std::size_t>(n), "rad/s");
  registerLogVariable("qdddes", setpoint_.acceleration.data(), static_cast<std::size_t>(n), "rad/s^2");
  registerLogVariable("tau", tau_.data(), static_cast<std::size_t>(n), "N m");
  registerLogVariable("saturated", saturatedJoints_, "joints");
  registerLogVariable("missed", missedCycles_, "cycles");
  registerParameter("kp", defaultControl_->getKp().data(), static_cast<std::size_t>(n), 0, 1e7, "N m/rad",
                    "proportional gains of the default position control");
  registerParameter("kd", defaultControl_->getKd().data(), static_cast<std::size_t>(n), 0, 1e6, "N m s/rad",
                    "derivative gains of the default position control");
  registerParameter("ki", defaultControl_->getKi().data(), static_cast<std::size_t>(n), 0, 1e8, "N m/(rad s)",
                    "integral gains of the default position control");
  applyQMotorConfigFile();  // (once: startControlLoop() does not apply it again)
  addOperatorCommands();
}

void DefaultManipulator::addOperatorCommands() {
  // The pop-up menu's and the control panel's commands (paper Figures 17 and 18): each says what
  // it did, or throws saying why it cannot be done. The servo controls offered come last (the
  // DefaultPositionControl first, then those set or added).

  addCommandWithResult("Power On", [this] {
    // A generator's setpoint may have moved on while the arm stood braked: the servo loop would
    // refuse that hand-over with a safe stop (control()); the operator gets a refusal instead.
    if (generator_.load() != nullptr)
      throw std::logic_error("a trajectory generator drives the arm: its program powers it on (or release the generator first)");
    enableArmPower();  // refused during a shutdown, or without hardware and simulation
    return std::string("arm power on: the arm holds where it is");
  }, "switch the amplifiers on; the arm holds where it is");
  addCommandWithResult("Power Off", [this] {
    disableArmPower();
    return std::string("arm power off: brakes on");
  }, "switch the amplifiers off and engage the brakes");
  addCommandWithResult("Gravity Compensation On", [this] {
    setGravityCompensationOn();
    return std::string("gravity compensation on");
  }, "add the model's gravity torques to the servo control's command");
  addCommandWithResult("Gravity Compensation Off", [this] {
    setGravityCompensationOff();
    return std::string("gravity compensation off");
  }, "the servo control alone holds the arm against gravity");
  addCommandWithResult("Zero Gravity On", [this] {
    if (shutdownPhase_.load() != 0) throw std::logic_error("not during a shutdown");
    setZeroGravityModeOn();
    return std::string("zero-gravity mode on: the arm floats and stays where it is pushed");
  }, "gravity compensation only: the arm can be moved by hand");
  addCommandWithResult("Zero Gravity Off", [this] {
    setZeroGravityModeOff();
    return std::string("zero-gravity mode off: the arm holds where it is");
  }, "the servo control takes over where the arm is");
  addCommandWithResult("Hold Here", [this] {
    if (generator_.load() != nullptr)
      throw std::logic_error("a trajectory generator drives the arm: its program holds or moves it (release the generator first)");
    setZeroGravityModeOff();
    holdHere_.store(true);
    return std::string("holding the arm where it is");
  }, "hold the arm at its present position");
  std::lock_guard<std::mutex> lock(offersMutex_);
  offerLocked(*defaultControl_);
}

DefaultManipulator::~DefaultManipulator() {
  stopControlLoop();  // holds a powered arm first (beforeControlLoopStops())
  if (TrajectoryGenerator* g = generator_.exchange(nullptr)) {
    disconnectGenerator(*g);
    g->detach(*this);
  }
}

bool DefaultManipulator::inServoThread() const {
  return isRunning() && servoThread_.load(std::memory_order_relaxed) == std::this_thread::get_id();
}

JointVector DefaultManipulator::getJointPosition() const {
  if (inServoThread()) return q_;
  PublishedState s = initial_;
  published_.read(s);
  JointVector q(s.n);
  for (int i = 0; i < s.n; ++i) q(i) = s.q[i];
  return q;
}

JointVector DefaultManipulator::getJointVelocity() const {
  if (inServoThread()) return qd_;
  PublishedState s = initial_;
  published_.read(s);
  JointVector qd(s.n);
  for (int i = 0; i < s.n; ++i) qd(i) = s.qd[i];
  return qd;
}

const Setpoint& DefaultManipulator::getSetpoint() const { return setpoint_; }

JointVector DefaultManipulator::getDesiredJointPosition() const {
  if (inServoThread()) return setpoint_.position;
  PublishedState s = initial_;
  published_.read(s);
  JointVector qdes(s.n);
  for (int i = 0; i < s.n; ++i) qdes(i) = s.qdes[i];
  return qdes;
}

JointVector DefaultManipulator::getControlOutput() const {
  if (inServoThread()) return tau_;
  PublishedState s = initial_;
  published_.read(s);
  JointVector tau(s.n);
  for (int i = 0; i < s.n; ++i) tau(i) = s.tau[i];
  return tau;
}

void DefaultManipulator::setControlOutput(const Eigen::Ref<const Eigen::VectorXd>& torque) {
  if (torque.size() != tau_.size()) {
    throw MathException(std::string("setControlOutput: ") + std::to_string(torque.size()) + " torques for " +
                        std::to_string(tau_.size()) + " joints");
  }
  tau_ = torque;
}

std::string DefaultManipulator::noHardwareMessage() const {
  return "manipulator '" + getName() +
         "': simulation mode is off but no hardware is configured for it; switch simulation on (-sim, "
         "'simulationMode on' in rp.cfg, or setSimulationModeOn()) or name a hardware server (rp.cfg 'hwserver NAME')";
}

void DefaultManipulator::enableArmPower() {
  if (shutdownPhase_.load() != 0) throw std::logic_error(getName() + ": cannot power the arm during a shutdown");
  if (noHardware_.load() && !isSimulationModeOn()) throw std::runtime_error(noHardwareMessage());
  powerRequested_.store(true);
}

void DefaultManipulator::disableArmPower() { powerRequested_.store(false); }

bool DefaultManipulator::isArmPowerOn() const {
  if (inServoThread()) return power_;
  PublishedState s = initial_;
  if (!published_.read(s)) return powerRequested_.load() && !noHardware_.load();
  return s.power;
}

Transform DefaultManipulator::getEndEffectorTransform() const {
  if (inServoThread()) return forwardKinematics(*model_, *data_, q_);
  const ManipulatorModel& model = getModel();
  ManipulatorData data(model);
  return forwardKinematics(model, data, getJointPosition());
}

void DefaultManipulator::endEffectorForceToJointTorque(const Eigen::Ref<const Eigen::VectorXd>& q,
                                                       const Eigen::Ref<const Eigen::VectorXd>& force,
                                                       Eigen::Ref<Eigen::VectorXd> torque) const {
  const ManipulatorModel& model = inServoThread() ? *model_ : getModel();
  if (q.size() != model.getNumberOfJoints()) {
    throw MathException("endEffectorForceToJointTorque: " + std::to_string(q.size()) + " joint positions for " +
                        std::to_string(model.getNumberOfJoints()) + " joints");
  }
  const JointVector qv = q;
  if (inServoThread()) {
    rp::endEffectorForceToJointTorque(model, *data_, qv, force, torque, ReferenceFrame::Base);
  } else {
    ManipulatorData data(model);
    rp::endEffectorForceToJointTorque(model, data, qv, force, torque, ReferenceFrame::Base);
  }
}

void DefaultManipulator::setTrajectoryGenerator(TrajectoryGenerator& generator) {
  generator.attach(*this);
  connectGenerator(generator);
  TrajectoryGenerator* old = generator_.exchange(&generator);
  if (old != nullptr && old != &generator) {
    waitUntilNotExecuting(old);
    disconnectGenerator(*old);
    old->detach(*this);
  }
}

void DefaultManipulator::clearTrajectoryGenerator() {
  holdHere_.store(true);
  TrajectoryGenerator* old = generator_.exchange(nullptr);
  if (old != nullptr) {
    waitUntilNotExecuting(old);
    disconnectGenerator(*old);
    old->detach(*this);
  }
}

void DefaultManipulator::releaseTrajectoryGenerator(TrajectoryGenerator& generator) {
  TrajectoryGenerator* expected = &generator;
  if (generator_.compare_exchange_strong(expected, nullptr)) holdHere_.store(true);
  waitUntilNotExecuting(&generator);
  disconnectGenerator(generator);
}

void DefaultManipulator::releaseServoControl(ServoControl& control) {
  {
    std::lock_guard<std::mutex> lock(offersMutex_);
    ServoControl* expected = &control;
    servoControl_.compare_exchange_strong(expected, defaultControl_.get());
    if (&control != defaultControl_.get()) {
      if (const auto it = std::find(offers_.begin(), offers_.end(), &control); it != offers_.end()) {
        offers_.erase(it);
        removeCommand(kServoControlCommand + control.getName());
      }
    }
  }
  waitUntilNotExecuting(&control);
}

void DefaultManipulator::waitUntilNotExecuting(const void* object) const {
  // A cycle runs a control or generator for microseconds; yield until it is done with `object`.
  while (isRunning() && executing_.load(std::memory_order_acquire) == object) std::this_thread::yield();
}

TrajectoryGenerator* DefaultManipulator::getTrajectoryGenerator() const { return generator_.load(); }

void DefaultManipulator::setServoControl(ServoControl& control) {
  std::lock_guard<std::mutex> lock(offersMutex_);
  if (control.getManipulator() != this) control.attach(*this);
  offerLocked(control);
  servoControl_.store(&control);
}

ServoControl& DefaultManipulator::getServoControl() const { return *servoControl_.load(); }

void DefaultManipulator::addServoControl(ServoControl& control) {
  std::lock_guard<std::mutex> lock(offersMutex_);
  if (control.getManipulator() != this) control.attach(*this);
  offerLocked(control);
}

void DefaultManipulator::offerLocked(ServoControl& control) {
  if (std::find(offers_.begin(), offers_.end(), &control) != offers_.end()) return;
  const std::string name = control.getName();  // unique among live objects, so among the offers
  addCommandWithResult(kServoControlCommand + name, [this, name] {
    // By name, under the lock: a control released (destroyed) meanwhile is not found.
    std::lock_guard<std::mutex> lock(offersMutex_);
    const auto it = std::find_if(offers_.begin(), offers_.end(), [&](const ServoControl* c) { return c->getName() == name; });
    if (it == offers_.end()) throw std::invalid_argument("the servo control '" + name + "' is no longer offered");
    if (shutdownPhase_.load() != 0) throw std::logic_error("not during a shutdown");
    servoControl_.store(*it);
    return "servo control " + name + " in use: it starts holding the arm where it is";
  }, "use the servo control " + name + " (it takes over holding the arm where it is)");
  offers_.push_back(&control);
}

std::vector<std::string> DefaultManipulator::getServoControlNames() const {
  std::lock_guard<std::mutex> lock(offersMutex_);
  std::vector<std::string> names;
  for (const ServoControl* c : offers_) names.push_back(c->getName());
  return names;
}

std::string DefaultManipulator::getServoControlName() const {
  std::lock_guard<std::mutex> lock(offersMutex_);
  return servoControl_.load()->getName();
}

void DefaultManipulator::setZeroGravityModeOff() {
  holdHere_.store(true);  // the servo control takes over where the arm was pushed to
  zeroGravity_.store(false);
}

void DefaultManipulator::applyExternalWrench(const Vector<6>& wrench) {
  wrench_->write(0, Vector<3>(), wrench);
  wrenchesSet_.fetch_add(1, std::memory_order_release);  // after the write: a cycle that sees it reads it
}

void DefaultManipulator::applyExternalWrench(int link, const Vector<3>& point, const Vector<6>& wrench) {
  const int n = initial_.n;
  if (link < 1 || link > n) {
    throw std::out_of_range(getName() + ": applyExternalWrench: link " + std::to_string(link) + " is not in 1.." +
                            std::to_string(n));
  }
  wrench_->write(link, point, wrench);
  wrenchesSet_.fetch_add(1, std::memory_order_release);
}

void DefaultManipulator::startShutdown() {
  // Not RoboticObject::startShutdown(): that stops the loop, and the loop must run the damped
  // hold until the arm is at rest. The loop then switches the power off (phase 2); the system
  // shutdown stops it after that.
  int expected = 0;
  shutdownPhase_.compare_exchange_strong(expected, 1);
  if (!isRunning() || loopEnded_.load()) {
    if (board_) writeOutputsOff();
    shutdownPhase_.store(2);
  }
}

void DefaultManipulator::holdUntilSafe() {
  if (!isRunning() || loopEnded_.load()) return;
  // A loop stopped by runCycles() on a paused simulated clock cannot run the hold: nothing
  // moves while the simulated clock stands still, and the brakes go on when the loop ends.
  pauseAtCycle_.store(0, std::memory_order_relaxed);
  if (auto* simulated = dynamic_cast<SimulatedClock*>(&getClock()); simulated != nullptr && simulated->isPaused()) return;
  int expected = 0;
  shutdownPhase_.compare_exchange_strong(expected, 1);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(kShutdownTimeout + 2.0);
  while (isRunning() && !loopEnded_.load() && shutdownPhase_.load() != 2 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::microseconds(500));
}

std::string DefaultManipulator::stopControlProgram() {
  if (!isRunning()) throw std::logic_error(getName() + ": the control program is not running");
  const bool powered = isArmPowerOn();
  holdUntilSafe();  // at rest, power off, brakes on (as in a shutdown: shutdown phase 2)
  std::string result = RoboticObject::stopControlProgram();
  // Asked for by the operator, not a shutdown: the arm may be started again. After a fault (an
  // error, or a system shutdown) the phase stays: the arm cannot be started again.
  if (!ObjectManager::isShutdownRequested() && getErrorCode() == 0) {
    shutdownPhase_.store(0);  // the loop has ended: its own variables are this thread's now
    shutdownStart_ = 0;
    restTime_ = 0;
  }
  const JointVector q = getJointPosition();
  char joints[256] = "";
  for (int i = 0, at = 0; i < q.size() && at < static_cast<int>(sizeof joints) - 16; ++i)
    at += std::snprintf(joints + at, sizeof joints - static_cast<std::size_t>(at), "%s%.2f", i ? " " : "", q(i) * 180 / M_PI);
  return result + (powered ? "; the arm came to rest, is braked and powered off at q = [" : "; the arm is braked at q = [") +
         joints + "] deg";
}

std::string DefaultManipulator::startControlProgram() {
  if (isRunning()) throw std::logic_error(getName() + ": the control program is running already");
  if (shutdownPhase_.load() != 0) throw std::logic_error(getName() + ": the arm was shut down (a fault or a system shutdown)");
  std::string why;
  if (powerRequested_.load() && generator_.load() != nullptr) {
    powerRequested_.store(false);
    why = " (a trajectory generator drives the arm: its program powers it on, or release the generator first)";
  }
  const bool power = powerRequested_.load();
  std::string result = RoboticObject::startControlProgram();
  return result + (power ? "; the arm holds where it is (power on)" : "; the arm stays braked where it is (power off)" + why);
}

bool DefaultManipulator::isShutdownComplete() const { return shutdownPhase_.load() == 2; }

bool DefaultManipulator::runCycles(std::uint64_t cycles, double timeoutSeconds) {
  const std::uint64_t target = getCycleCount() + cycles;
  auto* simulated = dynamic_cast<SimulatedClock*>(&getClock());
  if (simulated != nullptr) {
    pauseAtCycle_.store(target, std::memory_order_release);
    simulated->resume();
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeoutSeconds);
  while (getCycleCount() < target) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    if (ObjectManager::isShutdownRequested() && !isRunning()) return false;
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  return true;
}

bool DefaultManipulator::waitForCycles(std::uint64_t cycles, double timeoutSeconds) const {
  const std::uint64_t target = getCycleCount() + cycles;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeoutSeconds);
  while (getCycleCount() < target) {
    if (!isRunning() || std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  return true;
}

void DefaultManipulator::declareSettings(SettingSchema& schema) {
  Manipulator::declareSettings(schema);
  schema.addWord("hwserver", "name of the hardware server the arm is wired to");
  schema.addNumbers("countsPerRadian", 1, "counts/rad", "encoder counts per joint radian");
  schema.addWord("remote", "the arm runs in another process: its Ros2Bridge's namespace / its object name (NS/OBJECT), "
                           "driven by torque over DDS (Ros2IoBoard) when simulation is off");
  schema.addInteger("domain", "with remote: DDS domain id (ROS_DOMAIN_ID) of the remote bridge", 0, ros2detail::kMaxDomain);
  ros2detail::addInterfacesSetting(schema);
  schema.addNumbers("timeout", 1, "s", "with remote: silence of the remote arm's joint_states that is a fault", 0.005, 60);
  schema.addNumbers("connectTimeout", 1, "s", "with remote: longest wait for the remote arm when the hardware is set up", 0.1, 600);
  ManipulatorSimulation::declareSettings(schema);
  schema.setDefault("hwserver", "(none: no hardware, the arm stays unpowered unless simulated)");
  schema.setDefault("countsPerRadian", "20000 (with remote: 1e9, Ros2IoBoard's)");
  schema.setDefault("remote", "(none)");
  schema.setDefault("domain", "0");
  schema.setDefault("interfaces", "lo");
  schema.setDefault("timeout", "0.1");
  schema.setDefault("connectTimeout", "10");
}

bool DefaultManipulator::readHardware(double elapsed) {
  // A board that samples its inputs on its own clock (the hardware server, once per server
  // cycle) says when: all joints are read from one sample (a few bounded retries while the server
  // stores a new one), and the velocity is the change between samples over the time between them.
  // A server descheduled for a few cycles otherwise shows the joints standing still (velocity 0,
  // and the servo control pushes) and then jumping (a spike, a false velocity fault).
  std::int64_t sampled = -1;
  JointVector q = q_;  // the joints of one sample, taken into q_ only once the sample is known whole
  for (int attempt = 0; attempt < 8 && sampled < 0; ++attempt) {
    const std::int64_t before = board_->inputSampleTime();
    for (int i = 0; i < q.size(); ++i) {  // read even while a sample is stored: a failure shows
      std::int64_t counts = 0;
      if (board_->readEncoder(i, counts) != IoStatus::kOk) return false;
      q(i) = static_cast<double>(counts) / countsPerRadian_;
    }
    if (before >= 0 && board_->inputSampleTime() == before) sampled = before;
  }
  if (sampled < 0) return true;  // the server was storing a sample each time: none new this cycle
  q_ = q;
  if (sampled > 0) {
    if (sampled == lastSampleTime_) return true;  // no new sample: position and velocity as they were
    if (lastSampleTime_ > 0) elapsed = static_cast<double>(sampled - lastSampleTime_) * 1e-9;
    lastSampleTime_ = sampled;
  }
  // Over the time that really passed: after a stalled cycle the encoders moved for several
  // periods, which divided by one period would be a velocity spike (and a false velocity fault).
  qd_ = velocity_->differentiate(q_, elapsed);
  return true;
}

void DefaultManipulator::writeHardware() {
  for (int i = 0; i < tau_.size(); ++i) {
    const double gain = model_->getTorqueLimit()(i) / 10.0;  // amplifier: 10 V is the torque limit
    if (board_->writeAnalogOutput(i, tau_(i) / gain) != IoStatus::kOk) return ioFailure("writing the torques", i);
  }
  if (board_->writeDigitalOutput(0, power_) != IoStatus::kOk) ioFailure("switching the amplifiers", 0);
}

void DefaultManipulator::writeOutputsOff() noexcept {
  // Every output is written even if one fails: the amplifiers off first, then 0 V.
  (void)board_->writeDigitalOutput(0, false);
  for (int i = 0; i < initial_.n; ++i) (void)board_->writeAnalogOutput(i, 0.0);
}

void DefaultManipulator::ioFailure(const char* what, int line) {
  // Real-time safe: formats into a member buffer. The arm cannot be controlled: shut down.
  // The board's error gets all the room the rest leaves (cut at 120 characters, the cause of a
  // Modbus failure, "Connection timed out", was lost).
  const int n = std::snprintf(errorBuffer_, sizeof errorBuffer_, "%.60s: hardware failure %.40s (line %d): ", nameBuffer_,
                              what, line);
  if (n > 0 && static_cast<std::size_t>(n) < sizeof errorBuffer_ - 1) {
    const char* cause = board_->lastError();
    const std::size_t used = static_cast<std::size_t>(n), length = ::strnlen(cause, sizeof errorBuffer_ - 1 - used);
    std::memcpy(errorBuffer_ + used, cause, length);
    errorBuffer_[used + length] = '\0';
  }
  setError(2, errorBuffer_);
  power_ = false;
  tau_.setZero();
  writeOutputsOff();  // best effort: the amplifiers off, 0 V
  if (shutdownPhase_.load() != 2) shutdownPhase_.store(2);
  requestSystemShutdown(errorBuffer_);
}

void DefaultManipulator::enterControl() {
  servoThread_.store(std::this_thread::get_id());
  simulatedClock_ = dynamic_cast<SimulatedClock*>(&getClock());
  lastCycleTime_ = -1;
  loopEnded_.store(false);
  // The rate is final now (rp.cfg's qmotorConfig may have set it after construction): the
  // velocity filter takes this period (the servo controls take it in activate()); a restarted
  // loop starts the filter afresh with its first reading (not with the joints read at
  // construction: divided by one period, the motion since then would be a velocity spike).
  if (board_) {
    if (velocity_->getSamplePeriod() != getPeriod()) velocity_ = std::make_unique<Differentiator<JointVector>>(getPeriod(), kVelocityCutoffHz, 2);
    velocity_->reset();
    lastSampleTime_ = 0;
  }
  power_ = powerRequested_.load();
  sim_->setBrakes(!power_);
  activeControl_ = nullptr;  // a hand-over: the servo control starts (activate()), holding where the first cycle reads the arm
}

void DefaultManipulator::exitControl() {
  // The loop ends, however it ends: the amplifiers go off with 0 V on every joint (hardware),
  // the brakes go on (simulation and hardware alike), and a hold in progress is over.
  power_ = false;
  tau_.setZero();
  if (board_) writeOutputsOff();
  sim_->setBrakes(true);
  publish();
  loopEnded_.store(true);
  int hold = 1;
  shutdownPhase_.compare_exchange_strong(hold, 2);
}

void DefaultManipulator::readInputs() {
  const double t = getTime();
  // When the joints are read (StateSnapshot::readTime): a clock read, no system call (vDSO), for
  // hardware (a hardware server's sample time instead, below). A simulated arm's joints are its
  // state at the cycle's time t, however late the cycle runs (a late cycle integrates to t, below,
  // and a cycle after skipped deadlines catches up to its t): stamped with the clock instead, a late sample and the next would carry times that do
  // not match their motion, and a reader differentiating over the stamps (a program driving this
  // arm by torque over ROS 2) would see a velocity spike of 40 % at 1.6 rad/s after a 3 ms stall.
  readTime_ = getClock().isSimulated() || !board_ ? t : getClock().getTime();
  const double dt = getPeriod();
  const int n = model_->getNumberOfJoints();

  // A change of pose or simulation mode (physicalSetupChanged()) takes effect between cycles.
  if (pendingSetup_.load(std::memory_order_relaxed) != nullptr) {
    if (Setup* setup = pendingSetup_.exchange(nullptr, std::memory_order_acq_rel)) {
      const SetupResult result = checkSetup(*setup);
      if (result == SetupResult::kApplied) applySetup(*setup);
      setupResult_.store(static_cast<int>(result), std::memory_order_relaxed);
      appliedSetup_.store(setup, std::memory_order_release);
    }
  }

  // 0. An arm with no hardware waits, unpowered, for setSimulationModeOn(); half a second
  // without it is a fault (a program that forgot it, or -nosim without the arm's hardware).
  if (noHardware_.load(std::memory_order_relaxed)) {
    // Real time, whatever the loop's clock: the program's own thread must get to run.
    const double now = std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
    if (noHardwareSince_ < 0) noHardwareSince_ = now;
    // (setSimulationModeOn() ends the wait through physicalSetupChanged(), which installs a
    // simulation; only that clears noHardware_.)
    if (now - noHardwareSince_ > 0.5 && shutdownPhase_.load() == 0) {
      std::snprintf(errorBuffer_, sizeof errorBuffer_,
                    "%.60s: simulation mode is off but no hardware is configured for it (rp.cfg 'hwserver NAME', "
                    "or simulation on)", nameBuffer_);
      setError(3, errorBuffer_);
      shutdownPhase_.store(2, std::memory_order_release);
      requestSystemShutdown(errorBuffer_);
    }
  }

  // The simulation integrates the time since the last cycle under that cycle's torque (tau_),
  // before this cycle changes the brakes: one step of one period normally, the step the last
  // cycle's write phase used to take. On the real clock a cycle delayed by a busy machine skips
  // deadlines; the arm moved on under the last torque meanwhile, as a real one does: the whole time
  // since the last cycle is integrated (ManipulatorSimulation::advance(): in steps of up to 4
  // periods). One step covers a few skipped deadlines: the cycle after an overrun costs what any
  // cycle costs, and an executor loaded near its period recovers. (With one step per skipped
  // period, the cycle after an overrun took two steps, overran in turn, and an executor above
  // about 60 % load ran every other deadline for good.)
  // (A simulated clock skips no deadline: one period.)
  if (!board_ && lastCycleTime_ >= 0) (void)sim_->advance(tau_, simulatedClock_ != nullptr ? dt : t - lastCycleTime_, dt);

  // 1. Commands from other threads, then the joints.
  int phase = shutdownPhase_.load(std::memory_order_acquire);
  const bool wantPower =
      powerRequested_.load(std::memory_order_relaxed) && phase == 0 && !noHardware_.load(std::memory_order_relaxed);
  poweredOn_ = false;  // in this cycle: a generator must then start where the arm is (control())
  if (wantPower != power_ && phase == 0) {
    power_ = wantPower;
    sim_->setBrakes(!power_);
    poweredOn_ = power_;
    if (power_) activeControl_ = nullptr;  // a hand-over: activate() again below, holding where the arm is
  }
  if (board_) {
    if (!readHardware(lastCycleTime_ >= 0 && t > lastCycleTime_ ? t - lastCycleTime_ : dt)) {
      ioFailure("reading the encoders", 0);
    } else if (lastSampleTime_ > 0) {
      // A board that samples on its own clock (the hardware server): the joints hold for the
      // sample's time, not for this read. A cycle that finds no new sample (the server late)
      // keeps the joints and their time: a new stamp on old joints would be a velocity dip to a
      // reader differentiating over the stamps, and the next sample a spike.
      // (The real clock is one object: a pointer comparison, no dynamic_cast in the cycle.)
      if (const RealClock& real = RealClock::instance(); &getClock() == &real)
        readTime_ = 1e-9 * static_cast<double>(lastSampleTime_ - real.epochNanoseconds());
    }
  } else {
    // (The count first: the box is read only after a write, and taken when it is current.)
    if (const std::uint64_t set = wrenchesSet_.load(std::memory_order_acquire); set != wrenchesTaken_) {
      if (wrench_->read(n + 1)) applyWrenches(n);
      if (wrench_->current()) wrenchesTaken_ = set;
    }
    q_ = sim_->getPosition();
    qd_ = sim_->getVelocity();
  }
  missedCycles_ = static_cast<double>(getMissedCycleCount());
  // A joint reading that is not a number cannot be controlled: power off at once (no damped
  // hold can be computed from it).
  readFailed_ = false;
  if (const int bad = std::max(firstNonFinite(q_), firstNonFinite(qd_)); bad >= 0) {
    std::snprintf(errorBuffer_, sizeof errorBuffer_, "%.60s: joint %d reading is not a number (position %g, velocity %g)",
                  nameBuffer_, bad + 1, q_(bad), qd_(bad));
    powerOffNow();
    readFailed_ = true;
  }
}

void DefaultManipulator::control() {
  if (readFailed_) return;  // powered off in the read phase; the write phase writes the outputs off
  const double t = getTime();
  const double dt = getPeriod();
  const bool poweredOn = poweredOn_;
  int phase = shutdownPhase_.load(std::memory_order_acquire);

  // 2. The setpoint: the trajectory generator's, or hold. Every hand-over holds the arm where it
  // is in this cycle (the joints just read), never at a stale pose: the servo control in use
  // starting (again): at the loop's first cycle (a program's start), when the power comes on,
  // when zero-gravity mode ends, or another control set or one released; a trajectory generator
  // set, replaced or released (a new generator's first call gets this hold as the setpoint it
  // starts from); zero-gravity mode, and no power, hold wherever the arm goes.
  const bool zeroG = zeroGravity_.load(std::memory_order_relaxed);
  // In zero-gravity mode no servo control runs: the one in use starts afresh (activate(), e.g. no
  // integral wound up before) when the mode ends, as a newly set one does.
  if (zeroG) activeControl_ = nullptr;
  const bool controlChanges = servoControl_.load(std::memory_order_acquire) != activeControl_;
  TrajectoryGenerator* generator = generator_.load(std::memory_order_acquire);
  const bool generatorChanges = generator != activeGenerator_;
  activeGenerator_ = generator;
  // (The request is taken in every cycle: one left pending would move the hold a cycle later. It
  // is looked at first: the exchange, a full barrier on x86, only when there is one.)
  const bool holdRequested =
      holdHere_.load(std::memory_order_relaxed) && holdHere_.exchange(false, std::memory_order_acq_rel);
  if (!power_ || zeroG || controlChanges || generatorChanges || holdRequested) hold_ = q_;
  setpoint_.position = hold_;
  setpoint_.velocity.setZero();
  setpoint_.acceleration.setZero();
  if (generator != nullptr && power_ && !zeroG && phase == 0) {
    executing_.store(generator, std::memory_order_seq_cst);
    // Re-check: a generator being released is not called any more.
    try {
      if (generator_.load(std::memory_order_seq_cst) == generator && generator->getCurrentSetpoint(t, setpoint_)) {
        if (!(setpoint_.position.allFinite() && setpoint_.velocity.allFinite() && setpoint_.acceleration.allFinite())) {
          fault("the trajectory generator gave a setpoint that is not a number");
        } else if (const int j = poweredOn ? awayFromTheArm(q_, setpoint_) : -1; j >= 0) {
          // The generator was not followed while the arm stood braked, but its motion went on
          // (or was queued): following it now would pull the arm there at once.
          fault("power on with the trajectory generator's setpoint %.3g rad, %.3g rad/s away from joint %d: its "
                "motion went on while the arm was off (release the generator before powering on)",
                std::abs(setpoint_.position(j) - q_(j)), std::abs(setpoint_.velocity(j)), j + 1);
        } else {
          hold_ = setpoint_.position;
        }
      }
    } catch (const std::exception& e) {
      fault("the trajectory generator threw: %.150s", e.what());
    } catch (...) {
      fault("the trajectory generator threw an exception");
    }
    executing_.store(nullptr, std::memory_order_release);
    if (shutdownPhase_.load(std::memory_order_relaxed) != 0) {  // faulted: hold where the arm is
      setpoint_.position = hold_;
      setpoint_.velocity.setZero();
      setpoint_.acceleration.setZero();
    }
  }

  // 3. Servo control.
  phase = shutdownPhase_.load(std::memory_order_acquire);
  tau_.setZero();
  if (phase == 0 && !zeroG) {
    ServoControl* control = servoControl_.load(std::memory_order_acquire);
    executing_.store(control, std::memory_order_seq_cst);
    if (servoControl_.load(std::memory_order_seq_cst) != control) {
      // Released between the two loads: take the new one (the default control on a release).
      control = servoControl_.load(std::memory_order_acquire);
      executing_.store(control, std::memory_order_seq_cst);
    }
    try {
      if (control != activeControl_) {
        activeControl_ = control;
        control->activate();
      }
      control->calculate();
      if (const int bad = firstNonFinite(tau_); bad >= 0)
        fault("the servo control gave joint %d a torque that is not a number (%g)", bad + 1, tau_(bad));
    } catch (const std::exception& e) {
      fault("the servo control threw: %.150s", e.what());
    } catch (...) {
      fault("the servo control threw an exception");
    }
    executing_.store(nullptr, std::memory_order_release);
  }
  phase = shutdownPhase_.load(std::memory_order_acquire);
  if (phase != 0) {
    holdTorque();
  } else if (gravityCompensation_.load(std::memory_order_relaxed) || zeroG) {
    gravityWithPayload();
    tau_ += gravity_;
  }

  // 4. The command is saturated at the torque limits (control and gravity together), then the
  // position and velocity limits are checked.
  saturate();
  if (saturatedJoints_ > 0 && power_) saturatedCycles_.fetch_add(1, std::memory_order_relaxed);
  if (power_ && phase == 0) checkLimits();

  // Shutdown: at rest for a while (or timed out), then power off.
  if (shutdownPhase_.load(std::memory_order_relaxed) == 1) {
    if (shutdownStart_ == 0) shutdownStart_ = t > 0 ? t : 1e-9;
    const double rest = board_ ? restTolerance(kRestVelocity, countsPerRadian_) : kRestVelocity;
    restTime_ = qd_.cwiseAbs().maxCoeff() < rest ? restTime_ + dt : 0;
    if (restTime_ >= kRestDuration || t - shutdownStart_ > kShutdownTimeout || !power_) {
      power_ = false;
      sim_->setBrakes(true);
      shutdownPhase_.store(2, std::memory_order_release);
    }
  }
}

void DefaultManipulator::writeOutputs() { finishCycle(getTime()); }

void DefaultManipulator::finishCycle(double t) {
  // 5. Output: no torque without power. The simulation integrates this torque at the next cycle's
  // read (readInputs()), over the time that really passed until then.
  if (!power_) tau_.setZero();
  if (board_) writeHardware();
  lastCycleTime_ = t;

  // 6. State for other threads (log samples are taken by the ControlProgram after control()).
  publish();

  // runCycles() on a simulated clock: stop the clock right after the requested cycle.
  const std::uint64_t pauseAt = pauseAtCycle_.load(std::memory_order_acquire);
  if (pauseAt != 0 && getCycleCount() + 1 >= pauseAt && simulatedClock_ != nullptr) {
    // getCycleCount() counts finished cycles; this one finishes next.
    pauseAtCycle_.store(0, std::memory_order_relaxed);
    simulatedClock_->pause();  // not real-time, but this is the simulated clock
  }
}

void DefaultManipulator::checkLimits() {
  const int n = model_->getNumberOfJoints();
  for (int i = 0; i < n; ++i) {
    if (q_(i) < model_->getPositionMin()(i)) {
      violation("position", i, q_(i), model_->getPositionMin()(i), "rad");
      return;
    }
    if (q_(i) > model_->getPositionMax()(i)) {
      violation("position", i, q_(i), model_->getPositionMax()(i), "rad");
      return;
    }
    if (std::abs(qd_(i)) > model_->getVelocityLimit()(i)) {
      violation("velocity", i, qd_(i), std::copysign(model_->getVelocityLimit()(i), qd_(i)), "rad/s");
      return;
    }
  }
}

void DefaultManipulator::violation(const char* what, int joint, double value, double limit, const char* unit) {
  fault("joint %d %s %.6g %s exceeds the limit %.6g %s", joint + 1, what, value, unit, limit, unit);
  // Damped hold from this very cycle.
  holdTorque();
  saturate();
}

void DefaultManipulator::saturate() noexcept {
  saturatedJoints_ = 0;
  for (int i = 0; i < tau_.size(); ++i) {
    const double limit = model_->getTorqueLimit()(i);
    if (std::abs(tau_(i)) > limit) {
      tau_(i) = std::copysign(limit, tau_(i));
      saturatedJoints_ += 1;
    }
  }
}

void DefaultManipulator::fault(const char* format, ...) noexcept {
  // Real-time safe: formats into member buffers, never allocates. The first fault wins.
  if (shutdownPhase_.load(std::memory_order_relaxed) != 0) return;
  char detail[200];
  va_list args;
  va_start(args, format);
  std::vsnprintf(detail, sizeof detail, format, args);
  va_end(args);
  std::snprintf(errorBuffer_, sizeof errorBuffer_, "%.60s: %.190s", nameBuffer_, detail);
  setError(1, errorBuffer_);
  shutdownPhase_.store(1, std::memory_order_release);
  requestSystemShutdown(errorBuffer_);
}

void DefaultManipulator::holdTorque() {
  // Velocity damping with the default derivative gains, plus gravity; within the torque limits.
  tau_ = -(defaultControl_->getKd().cwiseProduct(qd_));
  gravityWithPayload();
  tau_ += gravity_;
}

void DefaultManipulator::gravityWithPayload() {
  // In this thread's workspace (ThreadWorkspace.hpp: an arm's own data is cold by its next cycle
  // when an executor steps many arms), or the arm's own data with mimic joints.
  ManipulatorData& d = internal::workspaceOr(*model_, *data_);
  gravityTorque(*model_, d, q_, gravity_);
  if (const std::uint64_t set = payloadsSet_.load(std::memory_order_acquire); set != payloadsTaken_) {
    std::array<double, 4> v{};
    if (payload_->handover.tryLoad(v)) {  // being changed: the next cycle takes it
      payloadsTaken_ = set;  // (v is set's or a later call's: a later one is loaded again)
      payloadMass_ = v[0];
      payloadCentre_ << v[1], v[2], v[3];
    }
  }
  if (payloadMass_ == 0) return;
  // The weight W = m g at the centre p: the torque that holds it is -J_p^T W, J_p's columns the
  // end-effector's (Jv_j + Jw_j x (p - e)).
  // gravityTorque() above left the forward kinematics of q_ in d: the Jacobian from them,
  // without computing them again in this cycle.
  internal::jacobianFromKinematics(*model_, d);
  const Jacobian& J = d.jacobian;
  const Transform& e = d.endEffector;
  const Eigen::Vector3d r = e.topLeftCorner<3, 3>() * Eigen::Vector3d(payloadCentre_);
  const Eigen::Vector3d weight = payloadMass_ * Eigen::Vector3d(model_->getGravity());
  for (int j = 0; j < gravity_.size(); ++j)
    gravity_(j) -= (J.col(j).head<3>() + J.col(j).tail<3>().cross(r)).dot(weight);
}

void DefaultManipulator::setPayload(double mass, const Vector<3>& centre) {
  if (!std::isfinite(mass) || mass < 0)
    throw std::invalid_argument("manipulator '" + getName() + "': the payload mass must be finite and not negative");
  if (!centre.allFinite())
    throw std::invalid_argument("manipulator '" + getName() + "': the payload centre must be finite");
  std::lock_guard<std::mutex> lock(setupMutex_);  // the simulation is replaced only under it
  sim_->setPayload(mass, centre);
  payload_->mass = mass;
  payload_->centre = centre;
  payload_->handover.store({mass, centre(0), centre(1), centre(2)});
  payloadsSet_.fetch_add(1, std::memory_order_release);
}

double DefaultManipulator::getPayloadMass() const {
  std::lock_guard<std::mutex> lock(setupMutex_);
  return payload_->mass;
}

Vector<3> DefaultManipulator::getPayloadCentre() const {
  std::lock_guard<std::mutex> lock(setupMutex_);
  return payload_->centre;
}

void DefaultManipulator::powerOffNow() noexcept {
  setError(2, errorBuffer_);
  power_ = false;
  tau_.setZero();
  sim_->setBrakes(true);
  shutdownPhase_.store(2, std::memory_order_release);
  requestSystemShutdown(errorBuffer_);
}

void DefaultManipulator::publish() {
  // In place: the arm's n joints of the arrays sized for kMaxJoints (the others stay 0), every
  // other field set.
  published_.update([&](PublishedState& s) noexcept {
    s.time = getTime();
    s.readTime = readTime_;
    s.cycle = getCycleCount();
    s.n = static_cast<int>(q_.size());
    s.power = power_;
    s.missed = missedCycles_;
    s.saturated = static_cast<double>(saturatedCycles_.load(std::memory_order_relaxed));
    for (int i = 0; i < s.n; ++i) {
      s.q[i] = q_(i);
      s.qd[i] = qd_(i);
      s.tau[i] = tau_(i);
      s.qdes[i] = setpoint_.position(i);
    }
  });
}

Model3D DefaultManipulator::get3DModel() const {
  Model3D m;
  const int n = initial_.n;
  for (int i = 1; i <= n; ++i) m.frames.push_back("link" + std::to_string(i));
  m.frames.push_back("endEffector");
  // The links as the kinematics place them (a Puma 560 and a WAM look like themselves); an arm
  // with mimic joints is drawn as frames the viewer links (its chain has frames of its own).
  if (const ManipulatorModel& model = getModel(); !model.hasMimicJoints() && model.getNumberOfJoints() == n) {
    internal::addLinkShapes(model, m);
    return m;
  }
  Shape base;
  base.kind = ShapeKind::Cylinder;
  base.size = Vector<3>{{0.1}, {0.2}, {0}};
  base.pose = translation(0, 0, 0.1);
  m.shapes.push_back(base);
  for (int i = 0; i < n; ++i) {
    Shape joint;
    joint.kind = ShapeKind::Sphere;
    joint.frame = "link" + std::to_string(i + 1);
    joint.size = Vector<3>{{0.06}, {0}, {0}};
    joint.color = Color{0.9, 0.5, 0.1, 1.0};
    m.shapes.push_back(joint);
  }
  return m;
}

ControlPanel DefaultManipulator::getControlPanel() const {
  ControlPanel panel = Manipulator::getControlPanel();
  const int n = initial_.n;
  auto field = [&](const char* name, const char* label, const char* unit, int index) {
    ControlPanelField f;
    f.name = name;
    f.label = label;
    f.kind = FieldKind::Vector;
    f.size = n;
    f.unit = unit;
    f.stateIndex = index;
    panel.fields.push_back(f);
  };
  field("q", "Joint positions", "rad", 0);
  field("qd", "Joint velocities", "rad/s", n);
  field("tau", "Joint torques", "N m", 2 * n);
  ControlPanelField power;
  power.name = "power";
  power.label = "Arm power";
  power.kind = FieldKind::Boolean;
  power.stateIndex = 3 * n;
  panel.fields.push_back(power);
  auto counter = [&](const char* name, const char* label, int index) {
    ControlPanelField f;
    f.name = name;
    f.label = label;
    f.kind = FieldKind::Number;
    f.unit = "cycles";
    f.stateIndex = index;
    panel.fields.push_back(f);
  };
  counter("missed", "Servo cycles missed", 3 * n + 1);
  counter("saturated", "Cycles at a torque limit", 3 * n + 2);
  return panel;
}

bool DefaultManipulator::getStateSnapshot(StateSnapshot& snapshot) const {
  PublishedState s = initial_;
  published_.read(s);
  snapshot.time = s.time;
  snapshot.readTime = s.readTime;
  snapshot.cycle = s.cycle;
  snapshot.size = internal::armSnapshotSize(s.n);  // the layout ArmSnapshot.hpp reads
  for (int i = 0; i < s.n; ++i) {
    snapshot.values[i] = s.q[i];
    snapshot.values[s.n + i] = s.qd[i];
    snapshot.values[2 * s.n + i] = s.tau[i];
  }
  snapshot.values[3 * s.n] = s.power ? 1 : 0;
  snapshot.values[3 * s.n + 1] = s.missed;
  snapshot.values[3 * s.n + 2] = s.saturated;
  return true;
}

}  // namespace rp
