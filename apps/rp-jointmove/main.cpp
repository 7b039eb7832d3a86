// rp-jointmove [-config FILE] [NAME]: the Joint Move utility (paper section 4.2, Figure 19).
//
// Creates the manipulator NAME from rp.cfg (without NAME: the first manipulator rp.cfg describes,
// or else a simulated Puma 560 called `puma`), connects a joint follower to it and opens the
// Scene Viewer on the Joint Move page: a slider per joint. Each slider sends its joint's new
// target; the follower, a trajectory generator the servo loop calls every cycle, moves the
// setpoint towards the targets at once, within half the model's velocity and acceleration limits.
// Runs until Ctrl-C (SIGINT) or SIGTERM.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <iostream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "rp/core/Core.hpp"
#include "rp/gui/SceneViewer.hpp"
#include "rp/manipulator/Manipulators.hpp"
#include "../common/JsonInteger.hpp"
#include "ChooseManipulator.hpp"

namespace {

using rp::JointVector;
using rp::kMaxJoints;

// The margin inside a joint's limits [lo, hi] that targets keep: 5 % of the range, at most 5
// degrees (the Joint Move page's sliders end there too, see web/src/jointmove.js).
double limitMargin(double lo, double hi) { return std::min(0.05 * (hi - lo), 5 * M_PI / 180); }

// Follows joint targets set from any thread (lock-free atomics) with a velocity- and
// acceleration-limited setpoint: the arm moves as soon as a slider moves.
class JointFollower : public rp::TrajectoryGenerator {
 public:
  JointFollower(const std::string& name, const rp::ManipulatorModel& model, const JointVector& start)
      : rp::TrajectoryGenerator(name), n_(model.getNumberOfJoints()) {
    for (int i = 0; i < n_; ++i) {
      // Targets stay a margin inside the joint limits: the arm lags its setpoint and would
      // overshoot a target on the limit, which shuts the system down.
      const double lo = model.getPositionMin()(i), hi = model.getPositionMax()(i);
      const double margin = limitMargin(lo, hi);
      qmin_[i] = lo + margin;
      qmax_[i] = hi - margin;
      vmax_[i] = 0.5 * model.getVelocityLimit()(i);
      amax_[i] = 0.5 * model.getAccelerationLimit()(i);
      target_[i].store(start(i));
    }
    publishObject();  // complete: the Scene Viewer may use it
  }
  ~JointFollower() override {
    withdrawObject();  // first: the Scene Viewer keeps off from here on
    releaseFromManipulators();
  }

  void attach(rp::Manipulator& manipulator) override {
    if (manipulator.getNumberOfJoints() != n_)
      throw std::invalid_argument("JointFollower: the manipulator has " + std::to_string(manipulator.getNumberOfJoints()) +
                                  " joints, not " + std::to_string(n_));
    if (!getManipulators().empty()) throw std::invalid_argument("JointFollower drives one manipulator");
    started_ = false;
  }

  // Servo thread: no allocation, no lock.
  bool getCurrentSetpoint(double time, rp::Setpoint& setpoint) override {
    if (!started_) {
      for (int i = 0; i < n_; ++i) {
        p_[i] = setpoint.position(i);
        v_[i] = 0;
      }
      lastTime_ = time;
      started_ = true;
    }
    const double dt = std::clamp(time - lastTime_, 0.0, 0.1);
    lastTime_ = time;
    for (int i = 0; i < n_; ++i) {
      const double e = target_[i].load(std::memory_order_relaxed) - p_[i];
      // The fastest velocity from which the joint can still stop at the target, limited.
      double want = std::copysign(std::min(vmax_[i], std::sqrt(2 * amax_[i] * std::abs(e))), e);
      if (dt > 0) want = std::clamp(want, v_[i] - amax_[i] * dt, v_[i] + amax_[i] * dt);
      double a = dt > 0 ? (want - v_[i]) / dt : 0;
      double step = want * dt;
      if (std::abs(step) >= std::abs(e) || (std::abs(e) < 1e-6 && std::abs(want) < amax_[i] * dt)) {
        step = e;  // arrive exactly
        want = 0;
        a = 0;
      }
      p_[i] += step;
      v_[i] = want;
      setpoint.position(i) = p_[i];
      setpoint.velocity(i) = v_[i];
      setpoint.acceleration(i) = a;
    }
    return true;
  }

  // GUI messages: setJoint {"joint": i, "value": rad}, setJoints [rad, ...], read.
  bool handleMessage(const std::string& type, const std::string& payload, std::string& reply) override {
    if (type == "read") {
      nlohmann::json t = nlohmann::json::array();
      for (int i = 0; i < n_; ++i) t.push_back(target_[i].load());
      reply = nlohmann::json{{"target", t}}.dump();
      return true;
    }
    if (type != "setJoint" && type != "setJoints") return rp::TrajectoryGenerator::handleMessage(type, payload, reply);
    const nlohmann::json j = nlohmann::json::parse(payload, nullptr, false);
    if (j.is_discarded()) throw std::invalid_argument(type + ": the payload is not JSON");
    std::vector<std::pair<int, double>> set;
    if (type == "setJoint") {
      if (!j.is_object() || !j.contains("joint") || !j["joint"].is_number_integer() || !j.contains("value") ||
          !j["value"].is_number())
        throw std::invalid_argument("setJoint needs {\"joint\": index, \"value\": radians}");
      if (!rp::apps::integerIn(j["joint"], 0, n_ - 1))
        throw std::invalid_argument("setJoint: 'joint' must be an integer in 0.." + std::to_string(n_ - 1));
      set.emplace_back(j["joint"].get<int>(), j["value"].get<double>());
    } else {
      if (!j.is_array() || static_cast<int>(j.size()) != n_)
        throw std::invalid_argument("setJoints needs an array of " + std::to_string(n_) + " angles [rad]");
      for (int i = 0; i < n_; ++i) {
        if (!j[static_cast<std::size_t>(i)].is_number()) throw std::invalid_argument("setJoints: angles must be numbers");
        set.emplace_back(i, j[static_cast<std::size_t>(i)].get<double>());
      }
    }
    for (const auto& [i, v] : set) {
      if (i < 0 || i >= n_) throw std::invalid_argument("joint " + std::to_string(i) + " out of range 0.." + std::to_string(n_ - 1));
      if (!std::isfinite(v) || v < qmin_[i] || v > qmax_[i])
        throw std::invalid_argument("joint " + std::to_string(i + 1) + ": " + std::to_string(v) + " rad is outside [" +
                                    std::to_string(qmin_[i]) + ", " + std::to_string(qmax_[i]) +
                                    "] (the joint limits less a margin)");
    }
    for (const auto& [i, v] : set) target_[i].store(v, std::memory_order_relaxed);
    reply.clear();
    return true;
  }

 private:
  int n_;
  std::array<double, kMaxJoints> qmin_{}, qmax_{}, vmax_{}, amax_{};
  std::array<std::atomic<double>, kMaxJoints> target_{};
  // Servo thread only.
  std::array<double, kMaxJoints> p_{}, v_{};
  double lastTime_ = 0;
  bool started_ = false;
};

const char* kUsage =
    "rp-jointmove [switches] [NAME]: moves each joint of the manipulator NAME (an rp.cfg section; default: the first "
    "manipulator of rp.cfg, or a simulated Puma 560) with a slider in the browser; Ctrl-C ends it.";

}  // namespace

int main(int argc, char** argv) {
  std::unique_ptr<rp::Manipulator> ownArm;
  rp::Manipulator* arm = rp::apps::startUtility("rp-jointmove", "jointmove.html", argc, argv, kUsage, ownArm);
  if (!arm) return 2;
  JointFollower follower("jointmove", arm->getModel(), arm->getJointPosition());
  arm->setTrajectoryGenerator(follower);
  // Without NAME the page shows the first manipulator: this one.
  rp::apps::runUntilShutdown("rp-jointmove", "moving", *arm);
  arm->clearTrajectoryGenerator();
  return 0;
}
