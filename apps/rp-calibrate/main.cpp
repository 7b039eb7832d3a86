// rp-calibrate [switches] [NAME] [options]: the calibration utility of the paper's Figure 1.
//
// Creates the manipulator NAME from rp.cfg (without NAME: the first manipulator rp.cfg describes,
// or else a simulated Puma 560 called `puma`; a real arm through its hwserver the same way), moves
// it through an excitation plan within its limits (slow passes through random poses in both
// directions, constant-velocity sweeps of each joint in both directions at several speeds), logs
// the torques its servo loop applied on the constant-velocity parts, and fits them by least
// squares: the encoder offsets (Gauss-Newton on the model's gravity), the base gravity parameters
// (the identifiable combinations of the links' first mass moments) and each joint's viscous and
// Coulomb friction. Prints the estimates with their standard errors as a table, or as JSON with
// --json; --write FILE writes what rp.cfg can take of them. See docs/calibration.md.
// Bad arguments: one line on stderr naming the argument, exit 2. A shutdown during the plan (a
// limit, a fault): exit 3. A fit that fails: exit 1.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "Calibration.hpp"
#include "ChooseManipulator.hpp"
#include "../common/ToolSupport.hpp"
#include "rp/core/Core.hpp"
#include "rp/manipulator/Manipulators.hpp"
#include "rp/trajectory/SynchronizedJointMotion.hpp"

namespace {

using namespace rp;
using namespace rp::calibration;
using nlohmann::json;

using tool::UsageError;  // the usage error of every tool (exit status 2)

const char* kUsage =
    "rp-calibrate [switches] [NAME] [--json] [--write FILE] [--offsets on|off] [--poses N] [--seed N]\n"
    "             [--pass-speed V] [--sweep-speeds V1,V2,...] [--sweep-range R]\n"
    "Moves the manipulator NAME (an rp.cfg section; default: the first manipulator of rp.cfg, or a simulated\n"
    "Puma 560) through an excitation plan and fits its encoder offsets, base gravity parameters and joint\n"
    "friction (viscous, Coulomb) to the torques its servo loop applied.\n"
    "  --json               print the result as JSON instead of a table\n"
    "  --write FILE         write the rp.cfg settings that can take the result (and why the rest cannot)\n"
    "  --offsets on|off     fit the encoder offsets (default on); off: they are known to be 0\n"
    "  --poses N            poses passed through for gravity and offsets (default 8)\n"
    "  --seed N             seed of the random poses (default 1)\n"
    "  --pass-speed V       speed of the passes through the poses [rad/s] (default 0.1, at least 0.01)\n"
    "  --sweep-speeds LIST  speeds of the friction sweeps [rad/s] (default 0.15,0.4,0.8)\n"
    "  --sweep-range R      the sweeps cover the middle of each joint's range +- R [rad] (default 0.5)\n"
    "Speeds are capped at half of each joint's velocity limit. Exit status: 0, 1 if the fit fails, 2 on a\n"
    "bad argument, 3 if the system shut down during the plan.";

double number(const std::string& option, const std::string& text) {
  char* end = nullptr;
  const double x = std::strtod(text.c_str(), &end);
  if (text.empty() || end == text.c_str() || *end != '\0' || !std::isfinite(x) || !(x > 0))
    throw UsageError(option + ": '" + text + "' is not a positive number");
  return x;
}

// The least speed of a pass or sweep [rad/s]: the plan's duration, and the samples it keeps, grow
// as 1 / speed (--pass-speed 1e-5 asked for about 10 GB, 1e-4 ran on for minutes).
constexpr double kMinSpeed = 0.01;

double speed(const std::string& option, const std::string& text) {
  const double x = number(option, text);
  if (x < kMinSpeed) throw UsageError(option + ": '" + text + "' is below the least speed, 0.01 rad/s");
  return x;
}

int integer(const std::string& option, const std::string& text, int lo, int hi) {
  std::size_t used = 0;
  long v = -1;
  try {
    v = std::stol(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || v < lo || v > hi)
    throw UsageError(option + ": '" + text + "' is not an integer in " + std::to_string(lo) + ".." + std::to_string(hi));
  return static_cast<int>(v);
}

struct Options {
  std::string name, write;
  bool json = false, offsets = true;
  PlanOptions plan;
};

Options parse(int argc, char** argv) {
  Options o;
  static const std::vector<std::string> valued = {"--write", "--offsets", "--poses", "--seed", "--pass-speed",
                                                  "--sweep-speeds", "--sweep-range"};
  std::map<std::string, bool> seen;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--json") {
      o.json = true;
      continue;
    }
    if (a.rfind("--", 0) != 0) {
      if (!o.name.empty()) throw UsageError("unexpected argument '" + a + "' (NAME is '" + o.name + "')");
      o.name = a;
      continue;
    }
    if (std::find(valued.begin(), valued.end(), a) == valued.end()) throw UsageError("unknown option " + a);
    if (i + 1 >= argc) throw UsageError(a + " needs a value");
    if (seen[a]) throw UsageError(a + " is given twice");
    seen[a] = true;
    const std::string v = argv[++i];
    if (a == "--write") {
      if (v.empty()) throw UsageError("--write needs a file name");
      o.write = v;
    } else if (a == "--offsets") {
      if (v != "on" && v != "off") throw UsageError("--offsets: '" + v + "' is not on or off");
      o.offsets = v == "on";
    } else if (a == "--poses") {
      o.plan.poses = integer(a, v, 1, 1000);
    } else if (a == "--seed") {
      o.plan.seed = static_cast<unsigned>(integer(a, v, 0, 1000000000));
    } else if (a == "--pass-speed") {
      o.plan.passSpeed = speed(a, v);
    } else if (a == "--sweep-range") {
      o.plan.sweepRange = number(a, v);
    } else {  // --sweep-speeds
      o.plan.sweepSpeeds.clear();
      std::stringstream ss(v);
      std::string item;
      while (std::getline(ss, item, ',')) o.plan.sweepSpeeds.push_back(speed(a, item));
      if (o.plan.sweepSpeeds.empty() || v.back() == ',') throw UsageError("--sweep-speeds: '" + v + "' is not a list of speeds");
    }
  }
  return o;
}

// Runs the plan's motions one after the other in the servo loop and logs, on the logged motions'
// constant-velocity parts (0.3 s after the setpoint's acceleration ended, every 5th cycle), the
// torques the servo loop applied from one reading of the joints to the next (read in the next
// cycle) with the state in the middle and the mean acceleration.
class PlanRunner : public TrajectoryGenerator {
 public:
  PlanRunner(const Manipulator& arm, const std::vector<PlanSegment>& plan) : TrajectoryGenerator("calibration") {
    const ManipulatorModel& model = arm.getModel();
    const int n = model.getNumberOfJoints();
    JointVector start = arm.getJointPosition();
    const JointVector amax = 0.25 * model.getAccelerationLimit(), jmax = 0.25 * model.getJerkLimit();
    double logged = 0;
    for (const PlanSegment& s : plan) {
      motions_.emplace_back(start, s.target, s.vmax, amax, jmax, Synchronization::Time);
      log_.push_back(s.log);
      if (s.log) logged += motions_.back().getDuration();
      start = s.target;
    }
    period_ = arm.getServoPeriod();
    const double rate = 1.0 / period_;
    samples_.reserve(static_cast<std::size_t>(logged * rate / kDecimation) + 16);
    last_ = plan.empty() ? start : plan.back().target;
    pendingQ_ = pendingQd_ = JointVector::Zero(n);
  }
  ~PlanRunner() override { releaseFromManipulators(); }

  void attach(Manipulator& manipulator) override { arm_ = &manipulator; }

  // Servo thread: no allocation (the sample buffer is reserved), no lock.
  bool getCurrentSetpoint(double time, Setpoint& setpoint) override {
    if (pending_ && samples_.size() < samples_.capacity()) {
      // The torque written in the cycle that read pendingQ_ acted until this cycle's reading.
      const JointVector q = arm_->getJointPosition(), qd = arm_->getJointVelocity();
      Sample s;
      s.q = 0.5 * (pendingQ_ + q);
      s.qd = 0.5 * (pendingQd_ + qd);
      s.qdd = (qd - pendingQd_) / period_;
      s.tau = arm_->getControlOutput();
      samples_.push_back(s);
      count_.store(samples_.size(), std::memory_order_release);
    }
    pending_ = false;
    if (!started_) {
      started_ = true;
      segmentStart_ = time;
    }
    while (segment_ < motions_.size() && time - segmentStart_ > motions_[segment_].getDuration()) {
      segmentStart_ += motions_[segment_].getDuration();
      ++segment_;
      cruising_ = false;
    }
    if (segment_ >= motions_.size()) {
      setpoint.position = last_;
      setpoint.velocity.setZero();
      setpoint.acceleration.setZero();
      done_.store(true, std::memory_order_release);
      return true;
    }
    motions_[segment_].evaluate(time - segmentStart_, setpoint);
    const bool cruise = setpoint.acceleration.cwiseAbs().maxCoeff() == 0 && setpoint.velocity.cwiseAbs().maxCoeff() > 0;
    if (cruise && !cruising_) cruiseStart_ = time;
    cruising_ = cruise;
    if (log_[segment_] && cruise && time - cruiseStart_ >= kSettle && ++cycle_ % kDecimation == 0) {
      pending_ = true;
      pendingQ_ = arm_->getJointPosition();
      pendingQd_ = arm_->getJointVelocity();
    }
    return true;
  }

  /// Whether the last motion has ended.
  bool done() const { return done_.load(std::memory_order_acquire); }
  /// Fraction of the motions started.
  double progress() const { return motions_.empty() ? 1.0 : static_cast<double>(segment_) / static_cast<double>(motions_.size()); }
  /// The samples (after done()).
  std::vector<Sample> samples() const { return std::vector<Sample>(samples_.begin(), samples_.begin() + static_cast<long>(count_.load())); }

 private:
  static constexpr double kSettle = 0.3;  // the servo's transient after the acceleration ends [s]
  static constexpr long kDecimation = 5;
  std::vector<SynchronizedJointMotion> motions_;
  std::vector<bool> log_;
  std::vector<Sample> samples_;
  std::atomic<std::size_t> count_{0};
  std::atomic<bool> done_{false};
  Manipulator* arm_ = nullptr;
  JointVector last_, pendingQ_, pendingQd_;
  std::size_t segment_ = 0;
  double segmentStart_ = 0, cruiseStart_ = 0, period_ = 0.001;
  long cycle_ = 0;
  bool started_ = false, cruising_ = false, pending_ = false;
};

const char* kSettingsNote =
    "rp.cfg: the controller's model has no setting for encoder offsets, friction or gravity parameters (re-zero\n"
    "the encoders; the servo's compensation uses the built-in model); --write FILE writes the counts to subtract\n"
    "and the settings of a simulated plant that matches the arm (simFrictionScale, simEncoderOffset).";

double toUser(const ManipulatorModel& model, int j, double v) { return model.isPrismatic(j) ? v * 1e3 : v * 180 / M_PI; }
const char* userUnit(const ManipulatorModel& model, int j) { return model.isPrismatic(j) ? "mm" : "deg"; }

json estimateJson(const Estimate& e) {
  return json{{"value", e.value}, {"stdError", e.stdError}, {"resolution", e.resolution}, {"nominal", e.nominal}};
}

// An offset the data resolves only to more than 0.1 degree (or 2 mm) is reported, not written.
bool poorlyObservable(const ManipulatorModel& model, int j, double resolution) {
  return resolution > (model.isPrismatic(j) ? 2e-3 : 0.1 * M_PI / 180);
}

json resultJson(const Manipulator& arm, const Result& r, std::size_t samples, bool offsets) {
  const ManipulatorModel& model = arm.getModel();
  const int n = model.getNumberOfJoints();
  json out;
  out["arm"] = arm.getName();
  out["class"] = arm.getClassName();
  out["joints"] = n;
  out["samples"] = samples;
  out["rowsPerJoint"] = r.rowsPerJoint;
  out["residualRms"] = r.residualRms;
  out["offsetsFitted"] = offsets;
  out["offsetResidualRms"] = r.offsetResidualRms;
  out["offsetIterations"] = r.offsetIterations;
  json off = json::array(), fr = json::array();
  for (int j = 0; j < n; ++j) {
    const auto i = static_cast<std::size_t>(j);
    json o = estimateJson(r.offset[i]);
    o["joint"] = j + 1;
    o["observable"] = r.offsetObservable[i];
    o["separableFromGravity"] = r.offsetSeparable[i];
    o["sensitivity"] = r.offsetSensitivity[i];
    off.push_back(o);
    fr.push_back(json{{"joint", j + 1},
                      {"viscous", estimateJson(r.viscous[i])},
                      {"coulomb", estimateJson(r.coulomb[i])},
                      {"asymmetry", estimateJson(r.asymmetry[i])}});
  }
  out["offsets"] = off;
  out["friction"] = fr;
  json base = json::array(), dependent = json::array(), unidentifiable = json::array();
  const BaseParameters& bp = r.baseParameters;
  for (std::size_t b = 0; b < bp.base.size(); ++b) {
    json e = estimateJson(r.gravity[b]);
    e["name"] = gravityParameterName(bp.base[b]);
    e["expression"] = bp.expression(static_cast<int>(b));
    base.push_back(e);
  }
  for (int d : bp.dependent) dependent.push_back(gravityParameterName(d));
  for (int u : bp.unidentifiable) unidentifiable.push_back(gravityParameterName(u));
  out["gravity"] = json{{"base", base}, {"dependent", dependent}, {"unidentifiable", unidentifiable}};
  out["settingsNote"] = kSettingsNote;
  return out;
}

void printTable(const Manipulator& arm, const Result& r, std::size_t samples, bool offsets) {
  const ManipulatorModel& model = arm.getModel();
  const int n = model.getNumberOfJoints();
  std::printf("rp-calibrate: %s (%s, %d joints): %zu samples, torque residual %.4g N m rms\n\n", arm.getName().c_str(),
              arm.getClassName().c_str(), n, samples, r.residualRms);
  std::printf("encoder offsets (reading - true angle)%s\n", offsets ? "" : ": not fitted (--offsets off)");
  bool separable = true;
  if (offsets) {
    std::printf("  joint  offset        std.err    resolution  sensitivity [N m/rad]\n");
    for (int j = 0; j < n; ++j) {
      const auto i = static_cast<std::size_t>(j);
      if (!r.offsetObservable[i]) {
        std::printf("  %5d  not observable: the gravity torque does not depend on it (left at 0)\n", j + 1);
        continue;
      }
      std::printf("  %5d  %+9.4f %s  %8.4f %s  %8.4f %s  %9.4g%s\n", j + 1, toUser(model, j, r.offset[i].value),
                  userUnit(model, j), toUser(model, j, r.offset[i].stdError), userUnit(model, j),
                  toUser(model, j, r.offset[i].resolution), userUnit(model, j), r.offsetSensitivity[i],
                  poorlyObservable(model, j, r.offset[i].resolution) ? "  poorly observable" : "");
      if (!r.offsetSeparable[i]) separable = false;
    }
  }
  if (offsets) {
    std::printf("  (resolution: the largest error a systematic torque error of the fit's residual, %.3g N m rms,\n"
                "  can cause; sensitivity: the gravity torque's change per radian, rms)\n",
                r.offsetResidualRms);
    if (!separable)
      std::printf("  The offsets are found with the model's masses: an offset error and a mass error change the gravity\n"
                  "  torque alike (see docs/calibration.md); with wrong masses, fit the offsets with a known load.\n");
  }
  std::printf("\nfriction (joint side)\n");
  std::printf("  joint  viscous [N m s/rad]            Coulomb [N m]                   asymmetry [N m]\n");
  std::printf("         value     std.err  model     value     std.err  model      value     std.err  model\n");
  for (int j = 0; j < n; ++j) {
    const auto i = static_cast<std::size_t>(j);
    std::printf("  %5d", j + 1);
    for (const Estimate* e : {&r.viscous[i], &r.coulomb[i], &r.asymmetry[i]})
      std::printf("  %8.4f %8.4f %8.4f", e->value, e->stdError, e->nominal);
    std::printf("\n");
  }
  const BaseParameters& bp = r.baseParameters;
  std::printf("\ngravity: %zu base parameters (first mass moments m [kg], m c [kg m] in link frames)\n", bp.base.size());
  std::printf("  value      std.err    model      parameter\n");
  for (std::size_t b = 0; b < bp.base.size(); ++b)
    std::printf("  %+9.5f  %9.5f  %+9.5f  %s\n", r.gravity[b].value, r.gravity[b].stdError, r.gravity[b].nominal,
                bp.expression(static_cast<int>(b)).c_str());
  auto list = [](const std::vector<int>& parameters) {
    std::string names;
    for (int k : parameters) names.append(" ").append(gravityParameterName(k));
    return names.empty() ? std::string(" none") : names;
  };
  std::printf("not identifiable (no effect on the gravity torque):%s\n", list(bp.unidentifiable).c_str());
  std::printf("identifiable only in the combinations above:%s\n", list(bp.dependent).c_str());
  std::printf("\n%s\n", kSettingsNote);
}

// The rp.cfg settings the library reads that can take the result, with a comment for the rest.
void writeSettings(const std::string& file, const Manipulator& arm, const Result& r, bool offsets) {
  const ManipulatorModel& model = arm.getModel();
  const int n = model.getNumberOfJoints();
  double counts = 20000;
  if (const ConfigSection* s = arm.configSection(); s && s->has("countsPerRadian")) counts = s->getNumbers("countsPerRadian").at(0);
  std::ofstream out(file);
  if (!out) throw UsageError("--write: cannot write '" + file + "'");
  out << "# rp-calibrate: " << arm.getName() << " (" << arm.getClassName() << ")\n"
      << "#\n"
      << "# The controller's model has no setting for any of the identified parameters: the encoder offsets\n"
      << "# (a joint's angle is its count divided by countsPerRadian), the friction and the gravity parameters\n"
      << "# (friction and gravity compensation use the built-in model) are not read from rp.cfg.\n";
  if (offsets) {
    out << "# Encoder offsets: re-zero the counters (see docs/arm-hardware.md), at " << counts << " counts/rad:\n";
    for (int j = 0; j < n; ++j) {
      const auto i = static_cast<std::size_t>(j);
      if (!r.offsetObservable[i]) {
        out << "#   joint " << j + 1 << ": not observable from gravity\n";
        continue;
      }
      if (poorlyObservable(model, j, r.offset[i].resolution)) {
        out << "#   joint " << j + 1 << ": poorly observable (resolution " << toUser(model, j, r.offset[i].resolution) << " "
            << userUnit(model, j) << "): not used\n";
        continue;
      }
      out << "#   joint " << j + 1 << ": reads " << toUser(model, j, r.offset[i].value) << " " << userUnit(model, j)
          << " too much: subtract " << std::lround(r.offset[i].value * counts) << " counts\n";
    }
  }
  out << "# Gravity: " << r.gravity.size() << " base parameters; no setting (simMassScale scales whole links of a\n"
      << "# simulation only).\n"
      << "#\n"
      << "# What rp.cfg can take: a simulation of this arm that matches it (the simulated plant's settings).\n"
      << "[" << arm.getName() << "]\n"
      << "class " << arm.getClassName() << "\n";
  std::string scale, why;
  bool any = false;
  for (int j = 0; j < n; ++j) {
    const auto i = static_cast<std::size_t>(j);
    double f = 1;
    if (r.coulomb[i].nominal > 0) {
      f = r.coulomb[i].value / r.coulomb[i].nominal;
    } else if (r.viscous[i].nominal > 0) {
      f = r.viscous[i].value / r.viscous[i].nominal;
    } else {
      why += "# joint " + std::to_string(j + 1) + ": the model has no friction, so no factor can give the identified one\n";
    }
    f = std::clamp(f, 0.0, 10.0);
    char buf[32];
    std::snprintf(buf, sizeof buf, " %.4g", f);
    scale += buf;
    any = true;
  }
  if (any) out << "# the Coulomb friction's factor (viscous: see rp-calibrate --json)\nsimFrictionScale" << scale << "\n" << why;
  if (offsets) {
    out << "simEncoderOffset";
    for (int j = 0; j < n; ++j) {
      char buf[32];
      const Estimate& e = r.offset[static_cast<std::size_t>(j)];
      const double value = poorlyObservable(model, j, e.resolution) ? 0.0 : toUser(model, j, e.value);
      std::snprintf(buf, sizeof buf, " %.5g", std::clamp(value, -10.0, 10.0));
      out << buf;
    }
    out << "   # " << userUnit(model, 0) << "\n";
  }
}

int run(int argc, char** argv) {
  RoboticPlatform::setGuiOff();
  RoboticPlatform::init(argc, argv, kUsage);
  Options options;
  std::vector<PlanSegment> plan;
  std::unique_ptr<Manipulator> own;
  Manipulator* arm = nullptr;
  try {
    options = parse(argc, argv);
  } catch (const UsageError& e) {
    std::cerr << "rp-calibrate: " << e.what() << "\n";
    return 2;
  }
  try {
    arm = apps::chooseManipulator(options.name, own);
  } catch (const std::exception& e) {
    std::cerr << "rp-calibrate: " << e.what() << "\n";
    return 2;
  }
  int status = 0;
  try {
    const ManipulatorModel& model = arm->getModel();
    if (model.hasMimicJoints()) throw UsageError(arm->getName() + ": arms with mimic joints are not supported");
    plan = makePlan(model, options.plan);
    const BaseParameters base = findBaseParameters(model);
    PlanRunner runner(*arm, plan);
    std::cerr << "rp-calibrate: moving " << arm->getName() << " through " << plan.size() << " motions" << std::endl;
    arm->setTrajectoryGenerator(runner);
    while (!runner.done()) {
      if (ObjectManager::isShutdownRequested()) {
        std::cerr << "rp-calibrate: the system shut down during the plan (at motion "
                  << static_cast<int>(runner.progress() * static_cast<double>(plan.size())) + 1 << ")\n";
        return 3;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    arm->clearTrajectoryGenerator();
    const std::vector<Sample> samples = runner.samples();
    const Result result = fit(model, samples, base, options.offsets);
    if (options.json) {
      std::cout << resultJson(*arm, result, samples.size(), options.offsets).dump() << "\n";
    } else {
      printTable(*arm, result, samples.size(), options.offsets);
    }
    if (!options.write.empty()) writeSettings(options.write, *arm, result, options.offsets);
  } catch (const UsageError& e) {
    std::cerr << "rp-calibrate: " << e.what() << "\n";
    status = 2;
  } catch (const std::exception& e) {
    std::cerr << "rp-calibrate: " << e.what() << "\n";
    status = 1;
  }
  ObjectManager om;
  (void)om.shutdownAllObjects("rp-calibrate finished");
  om.deleteAllObjects();
  return status;
}

}  // namespace

int main(int argc, char** argv) { return run(argc, argv); }
