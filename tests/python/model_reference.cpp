// rp-python-reference: the C++ library's own results for the Python tests (tests/python/
// test_against_cpp.py), for every model function the module binds, as JSON.
//
//   rp-python-reference --robot puma560|wam4|wam7|PATH.urdf [--tip LINK] < cases.json
//
// Input: a JSON array of cases {"q": [...], "qd": [...], "qdd": [...], "tau": [...]}. Output: a JSON
// array, one object per case, of fk, link_transforms, jacobian (base and end-effector frames),
// rnea and aba (without and with motor inertia and friction, and without gravity), gravity_torque,
// crba (without and with motor inertia), within_limits, numeric ik from the home position to fk(q),
// and for the Puma its eight closed-form solutions, ik_closest from q and branch_of(q). Numbers are
// written with 17 significant digits: they read back exactly.
#include <nlohmann/json.hpp>

#include <array>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>

#include "../../apps/common/ToolSupport.hpp"
#include "rp/model/Model.hpp"

namespace {

using namespace rp;
using nlohmann::json;

json matrix(const auto& m) { return tool::matrixJson(m); }
json vector(const JointVector& v) { return tool::vectorJson(v); }

JointVector joints(const json& j, int n, const char* what) {
  if (!j.is_array() || static_cast<int>(j.size()) != n)
    throw std::invalid_argument(std::string(what) + ": expected " + std::to_string(n) + " numbers");
  JointVector v(n);
  for (int i = 0; i < n; ++i) v(i) = j[static_cast<std::size_t>(i)].get<double>();
  return v;
}

const char* statusName(IkStatus s) {
  switch (s) {
    case IkStatus::Solved: return "solved";
    case IkStatus::NotConverged: return "not_converged";
    case IkStatus::Unreachable: return "unreachable";
  }
  return "unknown";
}

DynamicsOptions dynamics(bool gravity, bool motorInertia, bool friction) {
  DynamicsOptions o;
  o.gravity = gravity;
  o.motorInertia = motorInertia;
  o.friction = friction;
  return o;
}

int run(int argc, char** argv) {
  std::string robot, tip;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--robot") robot = argv[i + 1];
    else if (a == "--tip") tip = argv[i + 1];
    else throw std::invalid_argument("unknown option " + a);
  }
  std::unique_ptr<ManipulatorModel> model;
  if (robot == "puma560") model = std::make_unique<Puma560Model>();
  else if (robot == "wam7") model = std::make_unique<WAM7Model>();
  else if (robot == "wam4") model = std::make_unique<WAM4Model>();
  else if (robot.size() > 5 && robot.substr(robot.size() - 5) == ".urdf") {
    UrdfOptions options;
    options.tip = tip;
    model = loadUrdf(robot, options);
  } else {
    throw std::invalid_argument("usage: rp-python-reference --robot puma560|wam4|wam7|PATH.urdf [--tip LINK] < cases.json");
  }
  const int n = model->getNumberOfJoints();
  const json cases = json::parse(std::cin);
  json out = json::array();
  for (const json& c : cases) {
    ManipulatorData data(*model);  // fresh for every case: nothing carried over
    const JointVector q = joints(c.at("q"), n, "q"), qd = joints(c.at("qd"), n, "qd"), qdd = joints(c.at("qdd"), n, "qdd"),
                      tau = joints(c.at("tau"), n, "tau");
    json r;
    const Transform pose = forwardKinematics(*model, data, q);
    r["fk"] = matrix(pose);
    json links = json::array();
    for (int k = 0; k < n; ++k) links.push_back(matrix(data.linkTransforms[static_cast<std::size_t>(k)]));
    r["link_transforms"] = links;
    r["jacobian"] = matrix(jacobian(*model, data, q, ReferenceFrame::Base));
    r["jacobian_end_effector"] = matrix(jacobian(*model, data, q, ReferenceFrame::EndEffector));
    r["rnea"] = vector(inverseDynamics(*model, data, q, qd, qdd));
    r["rnea_motor_friction"] = vector(inverseDynamics(*model, data, q, qd, qdd, dynamics(true, true, true)));
    r["rnea_no_gravity"] = vector(inverseDynamics(*model, data, q, qd, qdd, dynamics(false, false, false)));
    JointVector g(n);
    gravityTorque(*model, data, q, g);
    r["gravity_torque"] = vector(g);
    r["crba"] = matrix(massMatrix(*model, data, q, false));
    r["crba_motor"] = matrix(massMatrix(*model, data, q, true));
    r["aba"] = vector(forwardDynamicsArticulatedBody(*model, data, q, qd, tau));
    r["aba_motor_friction"] = vector(forwardDynamicsArticulatedBody(*model, data, q, qd, tau, dynamics(true, true, true)));
    r["aba_no_gravity"] = vector(forwardDynamicsArticulatedBody(*model, data, q, qd, tau, dynamics(false, false, false)));
    r["within_limits"] = model->isWithinLimits(q);
    JointVector solution(n);
    const IkStatus status = inverseKinematics(*model, data, pose, model->getHomePosition(), solution);
    r["ik"] = {{"status", statusName(status)}, {"q", vector(solution)}};
    if (const auto* puma = dynamic_cast<const Puma560Model*>(model.get())) {
      std::array<Puma560IkSolution, 8> all;
      json solutions = json::array();
      if (puma->inverseKinematicsAll(pose, all) == IkStatus::Solved)
        for (const Puma560IkSolution& s : all)
          solutions.push_back({{"q", vector(s.q)}, {"branch", s.branchName()}, {"within_limits", s.withinLimits}});
      r["ik_all"] = solutions;
      JointVector closest(n);
      const IkStatus s = puma->inverseKinematicsClosest(pose, q, closest);
      r["ik_closest"] = {{"status", statusName(s)}, {"q", vector(closest)}};
      r["branch_of"] = puma->branchOf(q).branchName();
    }
    out.push_back(r);
  }
  std::cout << out.dump() << std::endl;
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return rp::tool::runTool("rp-python-reference", run, argc, argv); }
