// rp-plan: a jerk-limited rest-to-rest joint motion planned from the command line, as JSON.
//
//   rp-plan --start q1,q2,... --target q1,q2,... --vmax v1,... --amax a1,... --jmax j1,...
//           [--sync time|phase|none] [--rate HZ]
//
// One value per joint in each list; --vmax, --amax and --jmax also take a single value for every
// joint. --sync says how the joints are synchronised (see rp::Synchronization; default time).
// Prints {"duration":T,"sync":"time","joints":n,"durations":[...]} and, with --rate, the samples
// from 0 at 1/HZ up to and including the first at or after T (the last one at T):
// "time":[...], "q":[[...],...], "qd":[[...],...], "qdd":[[...],...] (one row per sample).
// Units: SI and radians. Bad input: one line on stderr naming the argument, exit 2.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "../common/ToolSupport.hpp"
#include "rp/model/ManipulatorModel.hpp"
#include "rp/trajectory/SynchronizedJointMotion.hpp"

namespace {

using namespace rp;
using nlohmann::json;

using tool::UsageError;

// A comma-separated list of finite numbers, not empty and without a trailing comma.
std::vector<double> numbers(const std::string& option, const std::string& text) {
  std::vector<double> v = tool::numbers(option, text);
  if (v.empty() || (!text.empty() && text.back() == ',')) throw UsageError(option + ": '" + text + "' is not a list of numbers");
  return v;
}

constexpr double kMaxSamples = 1e7;


JointVector joints(const std::map<std::string, std::string>& opts, const std::string& option, int n, bool limit) {
  const auto it = opts.find(option);
  if (it == opts.end()) throw UsageError("missing " + option);
  std::vector<double> v = numbers(option, it->second);
  if (limit && v.size() == 1) v.assign(static_cast<std::size_t>(n), v[0]);
  if (static_cast<int>(v.size()) != n) {
    throw UsageError(option + " has " + std::to_string(v.size()) + " values; --start has " + std::to_string(n));
  }
  JointVector q(n);
  for (int i = 0; i < n; ++i) {
    q(i) = v[static_cast<std::size_t>(i)];
    if (limit && !(q(i) > 0)) {
      throw UsageError(option + ": the limit of joint " + std::to_string(i + 1) + " must be positive, got " + std::to_string(q(i)));
    }
  }
  return q;
}

json row(const JointVector& v) { return tool::vectorJson(v); }

int run(int argc, char** argv) {
  std::map<std::string, std::string> opts;
  static const std::vector<std::string> known = {"--start", "--target", "--vmax", "--amax", "--jmax", "--sync", "--rate"};
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      std::cout << "usage: rp-plan --start q1,... --target q1,... --vmax v1,... --amax a1,... --jmax j1,...\n"
                   "               [--sync time|phase|none] [--rate HZ]\n";
      return 0;
    }
    if (std::find(known.begin(), known.end(), a) == known.end()) {
      throw UsageError(a.rfind("--", 0) == 0 ? "unknown option " + a : "unexpected argument '" + a + "'");
    }
    if (i + 1 >= argc) throw UsageError(a + " needs a value");
    if (opts.count(a)) throw UsageError(a + " is given twice");
    opts[a] = argv[++i];
  }
  if (!opts.count("--start")) throw UsageError("missing --start");
  const std::vector<double> start = numbers("--start", opts.at("--start"));
  const int n = static_cast<int>(start.size());
  if (n > kMaxJoints) throw UsageError("--start has " + std::to_string(n) + " values; at most " + std::to_string(kMaxJoints) + " joints");
  JointVector q0(n);
  for (int i = 0; i < n; ++i) q0(i) = start[static_cast<std::size_t>(i)];
  const JointVector q1 = joints(opts, "--target", n, false);
  const JointVector v = joints(opts, "--vmax", n, true), a = joints(opts, "--amax", n, true),
                    j = joints(opts, "--jmax", n, true);
  Synchronization mode = Synchronization::Time;
  if (opts.count("--sync")) {
    const std::string s = opts.at("--sync");
    if (s == "time") mode = Synchronization::Time;
    else if (s == "phase") mode = Synchronization::Phase;
    else if (s == "none") mode = Synchronization::None;
    else throw UsageError("--sync: '" + s + "' is not one of time, phase, none");
  }
  double rate = 0;
  if (opts.count("--rate")) {
    const std::vector<double> r = numbers("--rate", opts.at("--rate"));
    if (r.size() != 1 || !(r[0] > 0)) throw UsageError("--rate: '" + opts.at("--rate") + "' is not a positive number of samples per second");
    rate = r[0];
  }
  const SynchronizedJointMotion motion(q0, q1, v, a, j, mode);
  const double T = motion.getDuration();
  json out;
  out["duration"] = T;
  out["sync"] = toString(mode);
  out["joints"] = n;
  json durations = json::array();
  for (int i = 0; i < n; ++i) durations.push_back(motion.getJointDuration(i));
  out["durations"] = durations;
  if (rate > 0) {
    const double count = std::ceil(T * rate - 1e-9);
    if (!(count < kMaxSamples)) {
      throw UsageError("--rate: " + std::to_string(rate) + " Hz over " + std::to_string(T) + " s is more than 1e7 samples");
    }
    json time = json::array(), q = json::array(), qd = json::array(), qdd = json::array();
    Setpoint s;
    s.position = s.velocity = s.acceleration = JointVector(n);
    const long last = static_cast<long>(count);
    for (long k = 0; k <= last; ++k) {
      const double t = k == last ? T : static_cast<double>(k) / rate;
      motion.evaluate(t, s);
      time.push_back(t);
      q.push_back(row(s.position));
      qd.push_back(row(s.velocity));
      qdd.push_back(row(s.acceleration));
    }
    out["time"] = time;
    out["q"] = q;
    out["qd"] = qd;
    out["qdd"] = qdd;
  }
  std::cout << out.dump() << std::endl;
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return rp::tool::runTool("rp-plan", run, argc, argv); }
