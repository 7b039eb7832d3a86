// Planning and sampling without an arm (rp/trajectory/OfflinePlanner.hpp).
#include "rp/trajectory/OfflinePlanner.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "rp/manipulator/Manipulator.hpp"
#include "rp/model/Kinematics.hpp"
#include "rp/model/Puma560Model.hpp"

namespace rp {

// The stand-in arm: a model and a joint position, nothing that moves. The generator asks it for
// its model, its joint position (the start) and its period.
class OfflinePlanner::Arm : public Manipulator {
 public:
  Arm(std::shared_ptr<const ManipulatorModel> model, const JointVector& start)
      : model_(std::move(model)), data_(*model_), q_(start) {
    setpoint_.position = start;
    setpoint_.velocity = JointVector::Zero(start.size());
    setpoint_.acceleration = JointVector::Zero(start.size());
  }
  ~Arm() override { withdrawObject(); }

  const ManipulatorModel& getModel() const override { return *model_; }
  double getServoPeriod() const override { return 1e-3; }
  JointVector getJointPosition() const override { return q_; }
  JointVector getJointVelocity() const override { return JointVector::Zero(q_.size()); }
  const Setpoint& getSetpoint() const override { return setpoint_; }
  JointVector getDesiredJointPosition() const override { return setpoint_.position; }
  JointVector getControlOutput() const override { return JointVector::Zero(q_.size()); }
  void setControlOutput(const Eigen::Ref<const Eigen::VectorXd>&) override { refuse("setControlOutput"); }
  void enableArmPower() override { refuse("enableArmPower"); }
  void disableArmPower() override {}
  bool isArmPowerOn() const override { return false; }
  Transform getEndEffectorTransform() const override { return forwardKinematics(*model_, data_, q_); }
  void endEffectorForceToJointTorque(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& force,
                                     Eigen::Ref<Eigen::VectorXd> torque) const override {
    rp::endEffectorForceToJointTorque(*model_, data_, JointVector(q), force, torque, ReferenceFrame::Base);
  }
  void setTrajectoryGenerator(TrajectoryGenerator& generator) override {
    generator.attach(*this);
    connectGenerator(generator);
    generator_ = &generator;
  }
  void clearTrajectoryGenerator() override { release(); }
  TrajectoryGenerator* getTrajectoryGenerator() const override { return generator_; }
  void setServoControl(ServoControl&) override { refuse("setServoControl"); }
  ServoControl& getServoControl() const override { refuse("getServoControl"); }
  void setGravityCompensationOn() override {}
  void setGravityCompensationOff() override {}
  bool isGravityCompensationOn() const override { return false; }
  void setZeroGravityModeOn() override { refuse("setZeroGravityModeOn"); }
  void setZeroGravityModeOff() override {}
  bool isZeroGravityModeOn() const override { return false; }
  void releaseServoControl(ServoControl&) override {}
  void releaseTrajectoryGenerator(TrajectoryGenerator& generator) override {
    if (generator_ == &generator) release();
  }
  void applyExternalWrench(const Vector<6>&) override { refuse("applyExternalWrench"); }
  void applyExternalWrench(int, const Vector<3>&, const Vector<6>&) override { refuse("applyExternalWrench"); }

 private:
  [[noreturn]] static void refuse(const char* what) {
    throw std::logic_error(std::string("OfflinePlanner: ") + what + " needs a real or simulated arm");
  }
  void release() {
    if (generator_ != nullptr) disconnectGenerator(*generator_);
    generator_ = nullptr;
  }

  std::shared_ptr<const ManipulatorModel> model_;
  mutable ManipulatorData data_;
  JointVector q_;
  Setpoint setpoint_;
  TrajectoryGenerator* generator_ = nullptr;
};

class OfflinePlanner::Generator : public DefaultTrajectoryGenerator<> {
 public:
  Generator() = default;
  using QueueTrajectoryGenerator::queueDwell;
};

namespace {
// A copy that keeps the model's class where the generator looks at it (the Puma's closed-form IK).
std::shared_ptr<const ManipulatorModel> copyOf(const ManipulatorModel& model) {
  if (const auto* puma = dynamic_cast<const Puma560Model*>(&model)) return std::make_shared<Puma560Model>(*puma);
  return std::make_shared<ManipulatorModel>(model);
}
constexpr double kMaxSamples = 1e7;
}  // namespace

OfflinePlanner::OfflinePlanner(const ManipulatorModel& model, const JointVector& start)
    : OfflinePlanner(copyOf(model), start) {}

OfflinePlanner::OfflinePlanner(std::shared_ptr<const ManipulatorModel> shared, const JointVector& start) {
  if (!shared) throw std::invalid_argument("OfflinePlanner: no model");
  const ManipulatorModel& model = *shared;
  const int n = model.getNumberOfJoints();
  if (start.size() != n)
    throw std::invalid_argument("OfflinePlanner: the start has " + std::to_string(start.size()) + " values for " +
                                std::to_string(n) + " joints");
  if (!start.allFinite() || !model.isWithinLimits(start))
    throw std::invalid_argument("OfflinePlanner: the start is outside the joint limits of '" + model.getName() + "'");
  arm_ = std::make_unique<Arm>(std::move(shared), start);
  generator_ = std::make_unique<Generator>();
  arm_->setTrajectoryGenerator(*generator_);
}

OfflinePlanner::~OfflinePlanner() {
  // Whatever was queued and not sampled is run through (the generator's destructor would wait
  // for it), in growing steps: the setpoints are not needed.
  Setpoint sp = arm_->getSetpoint();
  double step = 1.0;
  for (int i = 0; i < 1000 && !generator_->isDone(); ++i, step = std::min(step * 1.5, 1e6)) {
    time_ += step;
    generator_->getCurrentSetpoint(time_, sp);
  }
  generator_.reset();
}

const ManipulatorModel& OfflinePlanner::getModel() const { return arm_->getModel(); }

DefaultTrajectoryGenerator<>& OfflinePlanner::generator() {
  if (generator_->getSegmentsLeft() >= QueueTrajectoryGenerator::kCapacity - 4)
    throw std::length_error("OfflinePlanner: " + std::to_string(generator_->getSegmentsLeft()) +
                            " motions wait: sample() them before queueing more");
  return *generator_;
}

void OfflinePlanner::dwell(double seconds) {
  if (!(seconds >= 0) || !std::isfinite(seconds)) throw std::invalid_argument("OfflinePlanner::dwell: seconds must be >= 0");
  generator();  // the capacity check
  generator_->queueDwell(seconds);
}

OfflinePlanner::Samples OfflinePlanner::sample(double rate, double maxDuration) {
  if (!(rate > 0) || !std::isfinite(rate)) throw std::invalid_argument("OfflinePlanner::sample: the rate must be positive");
  const int n = arm_->getModel().getNumberOfJoints();
  if (maxDuration * rate > kMaxSamples)
    throw std::length_error("OfflinePlanner::sample: more than 1e7 samples (" + std::to_string(maxDuration) + " s at " +
                            std::to_string(rate) + " Hz); lower the rate or the longest duration");
  if (generator_->isDone()) return {};  // nothing queued since the last call
  Setpoint sp = arm_->getSetpoint();
  std::vector<double> times;
  std::vector<JointVector> q, qd, qdd;
  const double start = time_;
  for (long k = 0;; ++k) {
    const double t = start + static_cast<double>(k) / rate;
    if (t - start > maxDuration)
      throw std::length_error("OfflinePlanner::sample: the plan is longer than " + std::to_string(maxDuration) + " s");
    if (!generator_->getCurrentSetpoint(t, sp)) break;  // nothing was ever queued
    times.push_back(t - start);
    q.push_back(sp.position);
    qd.push_back(sp.velocity);
    qdd.push_back(sp.acceleration);
    time_ = t;
    if (generator_->isDone()) break;  // the first sample after the last motion ended: at its target
  }
  Samples out;
  out.time = times;
  out.q.resize(static_cast<Eigen::Index>(times.size()), n);
  out.qd.resizeLike(out.q);
  out.qdd.resizeLike(out.q);
  for (std::size_t k = 0; k < times.size(); ++k) {
    out.q.row(static_cast<Eigen::Index>(k)) = q[k].transpose();
    out.qd.row(static_cast<Eigen::Index>(k)) = qd[k].transpose();
    out.qdd.row(static_cast<Eigen::Index>(k)) = qdd[k].transpose();
  }
  out.duration = times.empty() ? 0 : times.back();
  time_ += 1.0 / rate;
  return out;
}

}  // namespace rp
