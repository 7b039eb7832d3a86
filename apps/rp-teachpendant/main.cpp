// rp-teachpendant [-config FILE] [NAME]: the Teachpendant (paper section 4.2, Figure 20).
//
// Creates the manipulator NAME (as rp-jointmove does) and opens the Scene Viewer on the
// Teachpendant page: switch zero-gravity mode on and push the arm around (in simulation: drag
// the end-effector with Shift held, which applies a force to it), store the current position in
// a list, move back to a stored position with the trajectory generator, cycle through all or
// selected positions. Runs until Ctrl-C (SIGINT) or SIGTERM.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <iostream>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "../common/JsonInteger.hpp"
#include "ChooseManipulator.hpp"
#include "rp/core/Core.hpp"
#include "rp/gui/SceneViewer.hpp"
#include "rp/manipulator/Manipulators.hpp"

namespace {

using nlohmann::json;

// Brings the arm to rest at once from the motion it is in (the Teachpendant's Stop): each
// joint's setpoint velocity falls to zero at 80 % of the model's acceleration limit, the share the
// pendant's motions are planned with, so the arm stops no further than the motion it interrupts
// would have taken it (that motion ends at a stored position, inside the limits). The servo
// thread calls it: no allocation, no lock.
class Brake : public rp::TrajectoryGenerator {
 public:
  // name: the object's (unique: the last Stop's brake still exists while the next one is built);
  // velocity: the joints' velocity when the brake takes over [rad/s]
  Brake(const std::string& name, const rp::ManipulatorModel& model, const rp::JointVector& velocity)
      : rp::TrajectoryGenerator(name), n_(model.getNumberOfJoints()) {
    for (int i = 0; i < n_; ++i) {
      a_[static_cast<std::size_t>(i)] = 0.8 * model.getAccelerationLimit()(i);
      v_[static_cast<std::size_t>(i)] = velocity(i);
    }
    publishObject();
  }
  ~Brake() override {
    withdrawObject();
    releaseFromManipulators();
  }
  void attach(rp::Manipulator& manipulator) override {
    if (manipulator.getNumberOfJoints() != n_) throw std::invalid_argument("Brake: wrong number of joints");
    started_ = false;
  }
  bool getCurrentSetpoint(double time, rp::Setpoint& setpoint) override {
    if (!started_) {  // from the hold the manipulator hands a new generator: where the arm is
      for (int i = 0; i < n_; ++i) p_[static_cast<std::size_t>(i)] = setpoint.position(i);
      lastTime_ = time;
      started_ = true;
    }
    const double dt = std::clamp(time - lastTime_, 0.0, 0.1);
    lastTime_ = time;
    for (int i = 0; i < n_; ++i) {
      const auto k = static_cast<std::size_t>(i);
      double a = 0;
      if (std::abs(v_[k]) <= a_[k] * dt) {
        p_[k] += 0.5 * v_[k] * dt;
        v_[k] = 0;
      } else {
        a = -std::copysign(a_[k], v_[k]);
        p_[k] += (v_[k] + 0.5 * a * dt) * dt;
        v_[k] += a * dt;
      }
      setpoint.position(i) = p_[k];
      setpoint.velocity(i) = v_[k];
      setpoint.acceleration(i) = a;
    }
    return true;
  }

 private:
  int n_;
  std::array<double, rp::kMaxJoints> a_{}, v_{}, p_{};  // (servo thread once attached)
  double lastTime_ = 0;
  bool started_ = false;
};

// The Teachpendant's state and commands; the GUI reaches it with `message` requests (they run in
// the viewer's worker thread, one at a time). Motions run in a thread of their own.
class Teachpendant : public rp::RoboticObject {
 public:
  Teachpendant(const std::string& name, rp::Manipulator& arm) : rp::RoboticObject(name), arm_(arm) {
    pushWatch_ = std::thread([this] { watchPush(); });
    publishObject();  // complete: the Scene Viewer may send it messages
  }
  ~Teachpendant() override {
    withdrawObject();  // first: waits for a message being handled; no new ones reach it
    {
      std::lock_guard<std::mutex> lock(pushMutex_);
      quit_ = true;
    }
    pushCv_.notify_all();
    pushWatch_.join();
    abort_ = true;
    if (job_.joinable()) job_.join();
    generator_.reset();
    brake_.reset();
    arm_.clearExternalWrench();
  }

  bool handleMessage(const std::string& type, const std::string& payload, std::string& reply) override {
    json j = payload.empty() ? json::object() : json::parse(payload, nullptr, false);
    if (j.is_discarded()) throw std::invalid_argument(type + ": the payload is not JSON");
    reply.clear();
    if (type == "read") {
      reply = state().dump();
    } else if (type == "zeroGravity") {
      if (!j.is_boolean()) throw std::invalid_argument("zeroGravity needs true or false");
      if (busy()) throw std::invalid_argument("the arm is moving to a stored position");
      if (j.get<bool>()) {
        // The last motion's generator (holding its target) or a Stop's brake, left set, would
        // pull the arm back to its setpoint when zero-gravity mode ends: cleared, the arm is held
        // where it is pushed to (the next motion starts there with a fresh generator).
        arm_.clearTrajectoryGenerator();
        arm_.setZeroGravityModeOn();
      } else {
        arm_.setZeroGravityModeOff();
      }
    } else if (type == "push") {
      if (!arm_.isSimulationModeOn()) throw std::invalid_argument("pushing the arm from the browser works in simulation only");
      if (!j.is_object() || !j.contains("force") || !j["force"].is_array() || j["force"].size() != 3)
        throw std::invalid_argument("push needs {\"force\": [fx, fy, fz]} in newtons");
      rp::Vector<6> wrench;
      for (int i = 0; i < 3; ++i) {
        const json& f = j["force"][static_cast<std::size_t>(i)];
        if (!f.is_number() || !std::isfinite(f.get<double>()) || std::abs(f.get<double>()) > kMaxForce)
          throw std::invalid_argument("push: each force component must be a number within +-" + std::to_string(static_cast<int>(kMaxForce)) + " N");
        wrench(i) = f.get<double>();
      }
      // The force holds for kPushLapse only: the page repeats it every 50 ms while the pointer
      // drags; a page that stops (closed, hidden, frozen, disconnected) lets it lapse.
      std::lock_guard<std::mutex> lock(pushMutex_);
      pushing_ = !wrench.isZero();
      pushDeadline_ = std::chrono::steady_clock::now() + kPushLapse;
      arm_.applyExternalWrench(wrench);
      pushCv_.notify_all();
    } else if (type == "store") {
      std::lock_guard<std::mutex> lock(mutex_);
      if (positions_.size() >= 1000) throw std::invalid_argument("the list is full (1000 positions)");
      std::string label(1, 'P');  // (not "P" + ...: GCC 12 -Wrestrict false positive at -O3)
      label += std::to_string(++stored_);
      if (j.is_object() && j.contains("name")) {
        if (!j["name"].is_string() || j["name"].get<std::string>().empty() || j["name"].get<std::string>().size() > 64)
          throw std::invalid_argument("store: 'name' must be a string of 1 to 64 characters");
        label = j["name"].get<std::string>();
      }
      positions_.push_back({label, arm_.getJointPosition()});
    } else if (type == "delete") {
      std::lock_guard<std::mutex> lock(mutex_);
      positions_.erase(positions_.begin() + static_cast<long>(index(j)));
    } else if (type == "goto") {
      std::size_t i;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        i = index(j);
      }
      start({i}, 1);
    } else if (type == "cycle") {
      std::vector<std::size_t> which;
      int times = 1;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        if (j.is_object() && j.contains("indices")) {
          if (!j["indices"].is_array()) throw std::invalid_argument("cycle: 'indices' must be an array");
          if (j["indices"].size() > kMaxCycleIndices)
            throw std::invalid_argument("cycle: 'indices' must list at most " + std::to_string(kMaxCycleIndices) + " positions");
          for (const json& k : j["indices"]) which.push_back(index(json{{"index", k}}));
        }
        if (which.empty())
          for (std::size_t k = 0; k < positions_.size(); ++k) which.push_back(k);
        if (which.empty()) throw std::invalid_argument("cycle: no stored positions");
      }
      if (j.is_object() && j.contains("times")) {
        if (!rp::apps::integerIn(j["times"], 1, 100)) throw std::invalid_argument("cycle: 'times' must be 1 to 100");
        times = j["times"].get<int>();
      }
      start(which, times);
    } else if (type == "stop") {
      // Stops at once: no further position, and the motion under way is braked now (its
      // generator, disconnected from the arm, ends its waits).
      abort_ = true;
      if (busy()) {
        // The reply says where and how fast the arm was when the brake took over, and how hard
        // each joint brakes: the page's own state frame may be a frame or more old by then.
        const rp::JointVector q = arm_.getJointPosition(), qd = arm_.getJointVelocity();
        // A name of its own: the last Stop's brake is released only after the arm has taken
        // this one (built under one fixed name, every Stop after the first was refused, "an
        // object named 'teachpendant.brake' already exists", and the motion went on).
        auto brake = std::make_unique<Brake>("teachpendant.brake" + std::to_string(++brakes_), arm_.getModel(), qd);
        arm_.setTrajectoryGenerator(*brake);
        brake_ = std::move(brake);  // the previous brake, if any, after the arm left it
        json from = {{"q", json::array()}, {"qd", json::array()}, {"deceleration", json::array()}};
        for (Eigen::Index i = 0; i < q.size(); ++i) {
          from["q"].push_back(q(i));
          from["qd"].push_back(qd(i));
          from["deceleration"].push_back(0.8 * arm_.getModel().getAccelerationLimit()(i));
        }
        json r = state();
        r["brake"] = from;
        reply = r.dump();
      }
    } else {
      return rp::RoboticObject::handleMessage(type, payload, reply);
    }
    if (reply.empty()) reply = state().dump();
    return true;
  }

 private:
  struct Position {
    std::string name;
    rp::JointVector q;
  };
  // [N] per component: the page pulls with at most 60 N (web/src/teachpendant.js), enough to move
  // the arm by hand; another client may not push harder.
  static constexpr double kMaxForce = 60;
  static constexpr std::size_t kMaxCycleIndices = 1000;  // as many as the list holds
  static constexpr std::chrono::milliseconds kPushLapse{250};  // a push not repeated within this ends

  // Thread: zeroes the push force once it has not been repeated for kPushLapse.
  void watchPush() {
    std::unique_lock<std::mutex> lock(pushMutex_);
    while (!quit_) {
      if (!pushing_) {
        pushCv_.wait(lock);
      } else if (pushCv_.wait_until(lock, pushDeadline_) == std::cv_status::timeout && pushing_ &&
                 std::chrono::steady_clock::now() >= pushDeadline_) {
        arm_.clearExternalWrench();
        pushing_ = false;
        ++pushesLapsed_;
      }
    }
  }

  bool busy() const { return running_.load(); }

  std::size_t index(const json& j) const {  // under mutex_
    if (!j.is_object() || !j.contains("index") || !j["index"].is_number_integer())
      throw std::invalid_argument("needs {\"index\": n}");
    const long long i = j["index"].get<long long>();
    if (i < 0 || i >= static_cast<long long>(positions_.size()))
      throw std::invalid_argument("no stored position " + std::to_string(i) + " (" + std::to_string(positions_.size()) + " stored)");
    return static_cast<std::size_t>(i);
  }

  json state() const {
    std::lock_guard<std::mutex> lock(mutex_);
    json list = json::array();
    for (const Position& p : positions_) {
      json q = json::array();
      for (Eigen::Index i = 0; i < p.q.size(); ++i) q.push_back(p.q(i));
      list.push_back({{"name", p.name}, {"q", q}});
    }
    bool pushing = false;
    int lapsed = 0;
    {
      std::lock_guard<std::mutex> pushLock(pushMutex_);
      pushing = pushing_;
      lapsed = pushesLapsed_;
    }
    return {{"zeroGravity", arm_.isZeroGravityModeOn()}, {"simulation", arm_.isSimulationModeOn()},
            {"pushing", pushing}, {"pushesLapsed", lapsed},
            {"busy", running_.load()}, {"target", target_}, {"positions", list}};
  }

  // Moves through the positions `which`, `times` times, in a thread: a fresh trajectory generator
  // each time, so that the first motion starts where the arm was pushed to.
  void start(const std::vector<std::size_t>& which, int times) {
    if (running_.exchange(true)) throw std::invalid_argument("the arm is already moving to a stored position");
    if (job_.joinable()) job_.join();
    std::vector<Position> targets;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      for (int t = 0; t < times; ++t)
        for (std::size_t i : which) targets.push_back(positions_[i]);
    }
    abort_ = false;
    {
      std::lock_guard<std::mutex> lock(pushMutex_);
      pushing_ = false;
      arm_.clearExternalWrench();
    }
    arm_.setZeroGravityModeOff();
    generator_.reset();
    generator_ = std::make_unique<rp::DefaultTrajectoryGenerator<>>();
    arm_.setTrajectoryGenerator(*generator_);
    job_ = std::thread([this, targets] {
      try {
        for (const Position& p : targets) {
          if (abort_ || rp::ObjectManager::isShutdownRequested()) break;
          {
            std::lock_guard<std::mutex> lock(mutex_);
            target_ = p.name;
          }
          generator_->moveRadians(p.q);
          generator_->stop(0.5);
        }
      } catch (const std::exception& e) {
        std::cerr << "rp-teachpendant: " << e.what() << "\n";
      }
      {
        std::lock_guard<std::mutex> lock(mutex_);
        target_.clear();
      }
      running_ = false;
    });
  }

  rp::Manipulator& arm_;
  mutable std::mutex mutex_;
  std::vector<Position> positions_;
  int stored_ = 0;
  std::string target_;
  std::unique_ptr<rp::DefaultTrajectoryGenerator<>> generator_;
  std::unique_ptr<Brake> brake_;  // the last Stop's brake (the arm may still use it)
  int brakes_ = 0;                // Stops so far (each brake's name)
  std::thread job_;
  std::atomic<bool> running_{false}, abort_{false};
  // The push force's deadline (watchPush()).
  mutable std::mutex pushMutex_;
  std::condition_variable pushCv_;
  bool pushing_ = false, quit_ = false;
  int pushesLapsed_ = 0;
  std::chrono::steady_clock::time_point pushDeadline_{};
  std::thread pushWatch_;
};

const char* kUsage =
    "rp-teachpendant [switches] [NAME]: teach the manipulator NAME (an rp.cfg section; default: the first manipulator "
    "of rp.cfg, or a simulated Puma 560) positions in the browser; Ctrl-C ends it.";

}  // namespace

int main(int argc, char** argv) {
  std::unique_ptr<rp::Manipulator> ownArm;
  rp::Manipulator* arm = rp::apps::startUtility("rp-teachpendant", "teachpendant.html", argc, argv, kUsage, ownArm);
  if (!arm) return 2;
  Teachpendant pendant("teachpendant", *arm);
  rp::apps::runUntilShutdown("rp-teachpendant", "teaching", *arm);
  return 0;
}
