#include "rp/effector/ForceTorqueSensor.hpp"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <sstream>

#include "Json.hpp"
#include "rp/core/ObjectManager.hpp"
#include "rp/effector/Gripper.hpp"
#include "rp/math/Transform.hpp"

namespace rp {

namespace {
constexpr double kGravity = 9.80665;  // standard gravity [m/s^2]
}

ForceTorqueSensor::ForceTorqueSensor(const std::string& name) : PhysicalObject(name) {
  if (const ConfigSection* section = configSection()) {
    if (const ConfigSetting* s = section->find("payload")) {
      payloadMass_ = section->getNumbers("payload").at(0);
      if (payloadMass_ < 0) throw section->errorAt(*s, "setting 'payload' must not be negative");
    }
    if (section->has("payloadCenter")) {
      const auto c = section->getNumbers("payloadCenter");
      payloadCenter_ << c.at(0) / 1000.0, c.at(1) / 1000.0, c.at(2) / 1000.0;
    }
    if (const ConfigSetting* s = section->find("maxMissedCycles")) {
      const double n = section->getNumbers("maxMissedCycles").at(0);
      if (n < 1 || n > 1e6) throw section->errorAt(*s, "setting 'maxMissedCycles' must be 1 .. 1000000");
      maxMissedCycles_ = static_cast<int>(n);
    }
    if (section->has("updateRate")) updateRate_ = section->getNumbers("updateRate").at(0);
  }
  addCommandWithResult("Bias", [this] { return commandResult(bias(), "the current load is zero now"); },
                       "take the current load as zero");
  // The library drives update(): a thread of the sensor's own, started by the most-derived
  // constructor's startControlLoop() (RoboticObject's additional threads).
  if (updateRate_ > 0) addPeriodicThread("ft-update", 1.0 / updateRate_, [this] { update(); });
}

ForceTorqueSensor::~ForceTorqueSensor() = default;

void ForceTorqueSensor::declareSettings(SettingSchema& schema) {
  PhysicalObject::declareSettings(schema);
  schema.addNumbers("payload", 1, "kg", "simulated payload mass", 0, std::numeric_limits<double>::max());
  schema.addNumbers("payloadCenter", 3, "mm", "simulated payload centre of mass in the sensor frame");
  schema.addInteger("maxMissedCycles", "servo cycles without a new reading before the sensor is in error", 1, 1000000);
  schema.setDefault("payload", "0");
  schema.setDefault("payloadCenter", "0 0 0");
  schema.setDefault("maxMissedCycles", "50");
  schema.addNumbers("updateRate", 1, "Hz",
                    "rate of the sensor's update thread, which calls update(); 0: the program calls it", 0, 20000);
  schema.setDefault("updateRate", "1000");
}

void ForceTorqueSensor::setSimulatedWrench(const Vector<3>& force, const Vector<3>& torque) {
  std::lock_guard lock(simMutex_);
  simForce_ = force;
  simTorque_ = torque;
}

void ForceTorqueSensor::setSimulatedPayload(double mass, const Vector<3>& centerOfMass) {
  std::lock_guard lock(simMutex_);
  payloadMass_ = mass < 0 ? 0 : mass;
  payloadCenter_ = centerOfMass;
}

void ForceTorqueSensor::simulatedReading(Vector<3>& force, Vector<3>& torque) const {
  // Weight of the payload in the sensor frame: R^T (0, 0, -m g), torque c x F.
  const Matrix<3, 3> R = getRotation(Gripper::worldTransform(*this));
  std::lock_guard lock(simMutex_);
  Vector<3> gravityWorld;
  gravityWorld << 0.0, 0.0, -payloadMass_ * kGravity;
  const Vector<3> weight = R.transpose() * gravityWorld;
  force = weight + simForce_ - biasForce_;
  torque = payloadCenter_.cross(weight) + simTorque_ - biasTorque_;
}

void ForceTorqueSensor::publish(const Vector<3>& force, const Vector<3>& torque) noexcept {
  Published p{{force[0], force[1], force[2], torque[0], torque[1], torque[2]}, ++count_};
  published_.write(p);
}

void ForceTorqueSensor::fail(const char* what) noexcept {
  char message[256];
  std::snprintf(message, sizeof message, "%s", what);
  setError(1, message);
}

bool ForceTorqueSensor::read(Vector<3>& force, Vector<3>& torque) {
  std::lock_guard sensor(sensorMutex_);
  if (isSimulationModeOn()) {
    simulatedReading(force, torque);
  } else {
    const IoStatus s = hardwareRead(force, torque, readTimeoutMs());
    if (s != IoStatus::kOk && s != IoStatus::kDataLoss) {
      fail(hardwareError());
      return false;
    }
  }
  publish(force, torque);
  missedCycles_ = 0;
  if (getErrorCode() != 0 && !shutdownRequested_.load()) clearError();
  return true;
}

bool ForceTorqueSensor::bias() {
  std::lock_guard sensor(sensorMutex_);
  if (isSimulationModeOn()) {
    Vector<3> f, t;
    {
      std::lock_guard lock(simMutex_);
      biasForce_.setZero();
      biasTorque_.setZero();
    }
    simulatedReading(f, t);
    std::lock_guard lock(simMutex_);
    biasForce_ = f;
    biasTorque_ = t;
    return true;
  }
  if (hardwareBias() != IoStatus::kOk) {
    fail(hardwareError());
    return false;
  }
  return true;
}

bool ForceTorqueSensor::update() noexcept {
  if (shutdownRequested_.load()) return false;
  std::unique_lock sensor(sensorMutex_, std::try_to_lock);
  if (!sensor.owns_lock()) return true;  // read() or bias() has the sensor: skip, never wait
  Vector<3> force, torque;
  if (isSimulationModeOn()) {
    // Simulation reads only fixed-size values (the lock is uncontended in practice).
    simulatedReading(force, torque);
    publish(force, torque);
    return true;
  }
  const IoStatus s = hardwareRead(force, torque, 0);
  if (s == IoStatus::kOk || s == IoStatus::kDataLoss) {
    publish(force, torque);
    missedCycles_ = 0;
    return true;
  }
  // Until the first reading the stream may take a while to start: up to 2 s of the update thread.
  const int limit = count_ == 0 ? std::max(maxMissedCycles_, static_cast<int>(2.0 * updateRate_)) : maxMissedCycles_;
  const bool tolerated = (s == IoStatus::kTimeout || s == IoStatus::kProtocolError) && ++missedCycles_ < limit;
  if (tolerated) return true;
  char message[256];
  std::snprintf(message, sizeof message, "%s (after %d cycles without a reading)", hardwareError(), missedCycles_);
  setError(1, message);
  shutdownRequested_.store(true);
  // The shutdown's reason (stderr, the pages, the exit line) gives the cause, which names the
  // sensor's device; it said only "force/torque sensor failed". (No allocation: no getName().)
  char reason[256];
  std::snprintf(reason, sizeof reason, "force/torque sensor failed: %.200s", message);
  requestSystemShutdown(reason);
  return false;
}

ForceTorqueReading ForceTorqueSensor::getLastReading() const {
  Published p{};
  ForceTorqueReading r;
  if (!published_.read(p)) return r;
  r.force << p.values[0], p.values[1], p.values[2];
  r.torque << p.values[3], p.values[4], p.values[5];
  r.count = p.count;
  return r;
}

ControlPanel ForceTorqueSensor::getControlPanel() const {
  ControlPanel panel = PhysicalObject::getControlPanel();
  auto vector3 = [](std::string name, std::string label, std::string unit, int stateIndex) {
    return ControlPanelField{.name = std::move(name), .label = std::move(label), .kind = FieldKind::Vector,
                             .size = 3, .unit = std::move(unit), .min = 0, .max = 0, .tunable = false,
                             .stateIndex = stateIndex, .choices = {}};
  };
  panel.fields.push_back(vector3("force", "Force", "N", 0));
  panel.fields.push_back(vector3("torque", "Torque", "N m", 3));
  return panel;
}

bool ForceTorqueSensor::getStateSnapshot(StateSnapshot& snapshot) const {
  const ForceTorqueReading r = getLastReading();
  snapshot.size = 6;
  for (int i = 0; i < 3; ++i) {
    snapshot.values[i] = r.force[i];
    snapshot.values[3 + i] = r.torque[i];
  }
  snapshot.cycle = r.count;
  return true;
}

bool ForceTorqueSensor::handleMessage(const std::string& type, const std::string& payload, std::string& reply) {
  if (type != "read") return PhysicalObject::handleMessage(type, payload, reply);
  Vector<3> f, t;
  if (!read(f, t)) {
    reply = "{\"error\": ";
    reply.append(internal::jsonString(getErrorStatus().message));
    reply.push_back('}');
    return true;
  }
  std::ostringstream out;
  out.precision(9);
  out << "{\"force\": [" << f[0] << ", " << f[1] << ", " << f[2] << "], \"torque\": [" << t[0] << ", " << t[1]
      << ", " << t[2] << "]}";
  reply = out.str();
  return true;
}

}  // namespace rp
