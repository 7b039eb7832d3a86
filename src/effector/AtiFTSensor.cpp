#include "rp/effector/AtiFTSensor.hpp"

#include "rp/core/TypeDatabase.hpp"
#include "rp/io/IoException.hpp"

namespace rp {

AtiFTSensor::AtiFTSensor(const std::string& name) : ForceTorqueSensor(ClassSection(name, "AtiFTSensor")) {
  NetFtClient::Config config;
  if (const ConfigSection* section = configSection()) {
    if (section->has("address")) config.address = section->getWord("address");
    if (const ConfigSetting* s = section->find("port")) {
      const double port = section->getNumbers("port").at(0);
      if (port < 1 || port > 65535) throw section->errorAt(*s, "setting 'port' must be 1 .. 65535");
      config.port = static_cast<int>(port);
    }
    if (section->has("countsPerForce")) config.countsPerForce = section->getNumbers("countsPerForce").at(0);
    if (section->has("countsPerTorque")) config.countsPerTorque = section->getNumbers("countsPerTorque").at(0);
    if (const ConfigSetting* s = section->find("timeout")) {
      const double ms = section->getNumbers("timeout").at(0);
      if (ms < 1 || ms > 60000) throw section->errorAt(*s, "setting 'timeout' must be 1 .. 60000 ms");
      timeoutMs_ = static_cast<int>(ms);
    }
    try {
      client_ = std::make_unique<NetFtClient>(config);
    } catch (const IoException& e) {
      const ConfigSetting* at = section->find("address");
      if (!at) at = section->find("countsPerForce");
      if (!at) at = section->find("countsPerTorque");
      if (at) throw section->errorAt(*at, e.what());
      throw ConfigError(section->fileName(), section->line(), e.what());
    }
  } else {
    client_ = std::make_unique<NetFtClient>(config);
  }
  startControlLoop();  // complete: the update thread starts, other threads (the Scene Viewer) may use it
}

AtiFTSensor::~AtiFTSensor() {
  stopControlLoop();  // first: other threads keep off from here on, the update thread ends
  if (streaming_) client_->stopStreaming();
}

void AtiFTSensor::declareSettings(SettingSchema& schema) {
  ForceTorqueSensor::declareSettings(schema);
  schema.addWord("address", "Net F/T IPv4 address");
  schema.addInteger("port", "RDT UDP port", 1, 65535);
  schema.addNumbers("countsPerForce", 1, "counts/N", "force calibration (the sensor's cfgcpf), positive");
  schema.addNumbers("countsPerTorque", 1, "counts/(N m)", "torque calibration (the sensor's cfgcpt), positive");
  schema.addInteger("timeout", "how long a reading waits for a record [ms]", 1, 60000);
  schema.setDefault("address", "127.0.0.1");
  schema.setDefault("port", "49152");
  schema.setDefault("countsPerForce", "1000000");
  schema.setDefault("countsPerTorque", "1000000");
  schema.setDefault("timeout", "100");
}

IoStatus AtiFTSensor::ensureStreaming() noexcept {
  if (streaming_) return IoStatus::kOk;
  if (!client_->isOpen())
    if (IoStatus s = client_->open(); s != IoStatus::kOk) return s;
  if (IoStatus s = client_->startStreaming(); s != IoStatus::kOk) return s;
  streaming_ = true;
  return IoStatus::kOk;
}

IoStatus AtiFTSensor::hardwareRead(Vector<3>& force, Vector<3>& torque, int timeoutMs) noexcept {
  if (IoStatus s = ensureStreaming(); s != IoStatus::kOk) return s;
  NetFtRecord record;
  const IoStatus s = client_->receive(record, timeoutMs);
  if (s == IoStatus::kOk || s == IoStatus::kDataLoss) {
    force = record.force;
    torque = record.torque;
  } else if (s == IoStatus::kNotConnected) {
    streaming_ = false;  // the next reading starts the stream again
  }
  return s;
}

IoStatus AtiFTSensor::hardwareBias() noexcept {
  if (IoStatus s = ensureStreaming(); s != IoStatus::kOk) return s;
  return client_->bias();
}

const char* AtiFTSensor::hardwareError() const noexcept { return client_->lastError(); }

std::uint64_t AtiFTSensor::lostRecords() const noexcept { return client_->lostRecords(); }
std::uint64_t AtiFTSensor::outOfOrderRecords() const noexcept { return client_->outOfOrderRecords(); }

}  // namespace rp

RP_REGISTER_CLASS_AS(rp::AtiFTSensor, "AtiFTSensor");
