// rp-model: kinematics and dynamics of a built-in robot from the command line, as JSON.
//
//   rp-model --robot puma560|wam4|wam7|PATH.urdf [--tip LINK] [--offchain name=value,...] COMMAND --q v1,v2,... [options]
//
// COMMAND: fk | jacobian | gravity | rnea --qd .. --qdd .. | inertia | fd --qd .. --tau .. |
//          ik --pose p1,...,p16 [--seed ..] | urdf | mjcf
// Options: --motor-inertia and --friction add those effects to inertia, rnea and fd.
// Joint values (--q, --qd, --qdd, --tau, --seed): "v1,v2,..." in joint order, or "name=value,..."
// naming every joint once. Every result also lists the model's "joints" and "links" by name.
// --offchain (URDF robots): where moving joints off the chain (fingers, a jaw) stand when their
// links are lumped into the arm, "name=value,..." (UrdfOptions::offChainPositions; default zero).
// Units: SI and radians. Matrices are JSON arrays of rows. Bad input: one line on stderr, exit 2
// (values that are not finite numbers, a --pose that is not a rigid transform).
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "../common/ToolSupport.hpp"
#include "rp/model/Model.hpp"

namespace {

using namespace rp;
using nlohmann::json;

using tool::UsageError;
using tool::numbers;


// One value per joint: "v1,v2,..." in joint order, or "name=value,..." naming every joint once.
// --offchain "name=value,...": positions of moving joints off the chain [rad or m], each joint once.
std::map<std::string, double> offChainOf(const std::string& text) {
  std::map<std::string, double> positions;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    const std::size_t eq = item.find('=');
    if (eq == std::string::npos || eq == 0) throw UsageError("--offchain: '" + item + "' is not a name=value pair");
    const std::string joint = item.substr(0, eq);
    const std::vector<double> v = numbers("--offchain", item.substr(eq + 1));
    if (v.size() != 1) throw UsageError("--offchain: '" + item + "' is not a name=value pair");
    if (!positions.emplace(joint, v[0]).second) throw UsageError("--offchain: joint '" + joint + "' is given twice");
  }
  if (positions.empty()) throw UsageError("--offchain: no name=value pair");
  return positions;
}

JointVector jointsOf(const ManipulatorModel& model, const std::map<std::string, std::string>& opts,
                     const std::string& name, bool required) {
  const int n = model.getNumberOfJoints();
  const auto it = opts.find(name);
  if (it == opts.end()) {
    if (required) throw UsageError("missing " + name + " (" + std::to_string(n) + " comma-separated values, or name=value pairs)");
    return JointVector(n);
  }
  JointVector q(n);
  if (it->second.find('=') != std::string::npos) {
    std::vector<bool> given(static_cast<std::size_t>(n), false);
    std::stringstream ss(it->second);
    std::string item;
    while (std::getline(ss, item, ',')) {
      const std::size_t eq = item.find('=');
      if (eq == std::string::npos) throw UsageError(name + ": '" + item + "' is not a name=value pair (give all values by name or none)");
      const std::string joint = item.substr(0, eq);
      const int i = model.findJoint(joint);
      if (const int k = model.getChain().findJoint(joint); i < 0 && k >= 0 && model.hasMimicJoints()) {
        const JointCoupling& c = model.getCoupling()[static_cast<std::size_t>(k)];
        throw UsageError(name + ": joint '" + joint + "' is a mimic joint: it follows '" + model.getJointName(c.joint) +
                         "'; give that joint's value");
      }
      if (i < 0) {
        std::string names;
        for (int k = 0; k < n; ++k) {
          if (k > 0) names += ", ";
          names += model.getJointName(k);
        }
        throw UsageError(name + ": the robot has no joint '" + joint + "' (joints: " + names + ")");
      }
      if (given[static_cast<std::size_t>(i)]) throw UsageError(name + ": joint '" + joint + "' is given twice");
      given[static_cast<std::size_t>(i)] = true;
      const std::vector<double> v = numbers(name, item.substr(eq + 1));
      if (v.size() != 1) throw UsageError(name + ": '" + item + "' is not a name=value pair");
      q(i) = v[0];
    }
    for (int i = 0; i < n; ++i)
      if (!given[static_cast<std::size_t>(i)]) throw UsageError(name + ": no value for joint '" + model.getJointName(i) + "'");
    return q;
  }
  const std::vector<double> v = numbers(name, it->second);
  if (static_cast<int>(v.size()) != n) {
    throw UsageError(name + " has " + std::to_string(v.size()) + " values; the robot has " + std::to_string(n) +
                     " joints");
  }
  for (int i = 0; i < n; ++i) q(i) = v[static_cast<std::size_t>(i)];
  return q;
}

json matrix(const auto& m) { return tool::matrixJson(m); }
json vector(const JointVector& v) { return tool::vectorJson(v); }

int run(int argc, char** argv) {
  std::map<std::string, std::string> opts;
  std::string command;
  const std::vector<std::string> flags = {"--motor-inertia", "--friction"};
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      std::cout << "usage: rp-model --robot puma560|wam4|wam7|PATH.urdf [--tip LINK] [--offchain name=value,...] COMMAND\n"
                   "                --q v1,v2,...|name=value,... [--qd ..] [--qdd ..] [--tau ..]\n"
                   "                [--pose p1,...,p16] [--seed ..] [--motor-inertia] [--friction]\n"
                   "COMMAND: fk jacobian gravity rnea inertia fd ik urdf mjcf\n";
      return 0;
    }
    if (a.rfind("--", 0) == 0 && opts.count(a)) throw UsageError(a + " is given twice");
    if (a == "--motor-inertia" || a == "--friction") {
      opts[a] = "1";
    } else if (a.rfind("--", 0) == 0) {
      if (i + 1 >= argc) throw UsageError(a + " needs a value");
      opts[a] = argv[++i];
    } else if (command.empty()) {
      command = a;
    } else {
      throw UsageError("unexpected argument '" + a + "'");
    }
  }
  const auto robotIt = opts.find("--robot");
  if (robotIt == opts.end()) throw UsageError("missing --robot puma560|wam4|wam7|PATH.urdf");
  std::unique_ptr<ManipulatorModel> model;
  const std::string robot = robotIt->second;
  if (robot == "puma560") model = std::make_unique<Puma560Model>();
  else if (robot == "wam7") model = std::make_unique<WAM7Model>();
  else if (robot == "wam4") model = std::make_unique<WAM4Model>();
  else if (robot.size() > 5 && robot.substr(robot.size() - 5) == ".urdf") {
    UrdfOptions urdf;
    if (opts.count("--tip")) urdf.tip = opts.at("--tip");
    urdf.requireDynamics =
        command == "gravity" || command == "rnea" || command == "inertia" || command == "fd" || command == "mjcf";
    if (opts.count("--offchain")) urdf.offChainPositions = offChainOf(opts.at("--offchain"));
    std::vector<std::string> notes;
    urdf.notes = &notes;
    try {
      model = loadUrdf(robot, urdf);
    } catch (const UrdfOptionError& e) {
      throw UsageError("--offchain: " + e.problem() + " in " + robot);
    }
    for (const std::string& note : notes) std::cerr << "rp-model: note: " << note << std::endl;
  } else {
    throw UsageError("unknown robot '" + robot + "' (known: puma560, wam4, wam7, or a .urdf file)");
  }
  if (opts.count("--tip") && robot.find(".urdf") == std::string::npos) throw UsageError("--tip applies to URDF robots only");
  if (opts.count("--offchain") && robot.find(".urdf") == std::string::npos)
    throw UsageError("--offchain applies to URDF robots only");
  for (const auto& [key, value] : opts) {
    static const std::vector<std::string> known = {"--robot", "--tip", "--offchain", "--q", "--qd", "--qdd", "--tau", "--pose",
                                                   "--seed", "--motor-inertia", "--friction"};
    if (std::find(known.begin(), known.end(), key) == known.end()) throw UsageError("unknown option " + key);
    (void)value;
  }
  // An option the command does not read is refused rather than ignored (fk --tau 1,2 was taken
  // without a word, and puma560 ik never parsed its --seed).
  static const std::map<std::string, std::vector<std::string>> reads = {
      {"fk", {"--q"}},
      {"jacobian", {"--q"}},
      {"gravity", {"--q"}},
      {"rnea", {"--q", "--qd", "--qdd", "--motor-inertia", "--friction"}},
      {"inertia", {"--q", "--motor-inertia"}},
      {"fd", {"--q", "--qd", "--tau", "--motor-inertia", "--friction"}},
      {"ik", {"--pose", "--seed"}},
      {"urdf", {}},
      {"mjcf", {}}};
  if (const auto r = reads.find(command); r != reads.end()) {
    for (const auto& [key, value] : opts) {
      if (key == "--robot" || key == "--tip" || key == "--offchain") continue;
      if (std::find(r->second.begin(), r->second.end(), key) == r->second.end())
        throw UsageError(key + " does not apply to " + command);
      if (key == "--seed" && dynamic_cast<const Puma560Model*>(model.get()))
        throw UsageError("--seed does not apply to puma560 ik (its closed form gives all eight solutions)");
      (void)value;
    }
  }
  const int n = model->getNumberOfJoints();
  ManipulatorData data(*model);
  DynamicsOptions dyn;
  dyn.motorInertia = opts.count("--motor-inertia") > 0;
  dyn.friction = opts.count("--friction") > 0;
  json out;
  if (command == "urdf") {
    std::cout << toUrdf(*model);
    return 0;
  } else if (command == "mjcf") {
    std::cout << exportMjcf(*model);
    return 0;
  } else if (command == "ik") {
    const auto poseIt = opts.find("--pose");
    if (poseIt == opts.end()) throw UsageError("ik needs --pose with 16 values (a 4x4 matrix, row-major)");
    const std::vector<double> p = numbers("--pose", poseIt->second);
    if (p.size() != 16) throw UsageError("--pose has " + std::to_string(p.size()) + " values; give 16 (4x4, row-major)");
    Transform T;
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) T(r, c) = p[static_cast<std::size_t>(4 * r + c)];
    if (const std::string problem = rigidTransformError(T); !problem.empty())
      throw UsageError("--pose is not a rigid transform: it " + problem);
    json solutions = json::array();
    if (const auto* puma = dynamic_cast<const Puma560Model*>(model.get())) {
      std::array<Puma560IkSolution, 8> all;
      if (puma->inverseKinematicsAll(T, all) != IkStatus::Solved) throw UsageError("the pose is out of reach");
      for (const Puma560IkSolution& s : all)
        solutions.push_back({{"q", vector(s.q)}, {"branch", s.branchName()}, {"withinLimits", s.withinLimits}});
    } else {
      const JointVector seed = opts.count("--seed") ? jointsOf(*model, opts, "--seed", true) : model->getHomePosition();
      JointVector q(n);
      if (inverseKinematics(*model, data, T, seed, q) != IkStatus::Solved)
        throw UsageError("no solution found within the joint limits (unreachable pose?)");
      solutions.push_back({{"q", vector(q)}, {"branch", "numeric"}, {"withinLimits", model->isWithinLimits(q)}});
    }
    out["solutions"] = solutions;
  } else {
    const JointVector q = jointsOf(*model, opts, "--q", true);
    if (command == "fk") {
      out["fk"] = matrix(forwardKinematics(*model, data, q));
    } else if (command == "jacobian") {
      out["jacobian"] = matrix(jacobian(*model, data, q));
    } else if (command == "gravity") {
      JointVector g(n);
      gravityTorque(*model, data, q, g);
      out["tau"] = vector(g);
    } else if (command == "rnea") {
      out["tau"] = vector(inverseDynamics(*model, data, q, jointsOf(*model, opts, "--qd", true),
                                          jointsOf(*model, opts, "--qdd", true), dyn));
    } else if (command == "inertia") {
      out["M"] = matrix(massMatrix(*model, data, q, dyn.motorInertia));
    } else if (command == "fd") {
      out["qdd"] = vector(forwardDynamics(*model, data, q, jointsOf(*model, opts, "--qd", true),
                                          jointsOf(*model, opts, "--tau", true), dyn));
    } else {
      throw UsageError(command.empty() ? "missing COMMAND (fk jacobian gravity rnea inertia fd ik urdf mjcf)"
                                       : "unknown command '" + command + "' (fk jacobian gravity rnea inertia fd ik urdf mjcf)");
    }
  }
  json joints = json::array(), links = json::array();
  for (int i = 0; i < n; ++i) {
    joints.push_back(model->getJointName(i));
    links.push_back(model->getLinkName(i));
  }
  out["joints"] = joints;
  out["links"] = links;
  if (model->hasMimicJoints()) {
    // The mimic joints on the chain: not joints of the model, moved with the joint they follow
    // (and where --q was given, their value there).
    JointVector chainQ;
    const bool atQ = opts.count("--q") > 0 && command != "ik";
    if (atQ) model->toChain(jointsOf(*model, opts, "--q", true), chainQ);
    json mimics = json::array();
    const ManipulatorModel& chain = model->getChain();
    for (int k = 0; k < chain.getNumberOfJoints(); ++k) {
      const JointCoupling& c = model->getCoupling()[static_cast<std::size_t>(k)];
      if (!c.mimic) continue;
      json m = {{"joint", chain.getJointName(k)}, {"link", chain.getLinkName(k)}, {"follows", model->getJointName(c.joint)},
                {"multiplier", c.multiplier}, {"offset", c.offset}};
      if (atQ) m["position"] = chainQ(k);
      mimics.push_back(m);
    }
    out["mimic"] = mimics;
  }
  std::cout << out.dump() << std::endl;
  return 0;
}

}  // namespace

// (Not tool::runTool(): GCC 12 then sees a bogus overflow in the Eigen copy of jointsOf().)
int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "rp-model: " << e.what() << std::endl;
    return 2;
  }
}
