#pragma once
/// @file
/// The ATI force/torque sensor over the Net F/T RDT UDP protocol (paper section 3.4).

#include <memory>
#include <string>

#include "rp/effector/ForceTorqueSensor.hpp"
#include "rp/io/NetFtClient.hpp"

namespace rp {

/// An ATI force/torque sensor (the paper's Gamma 30/100) behind a Net F/T box, read through the
/// RDT protocol (`NetFtClient`): high-speed streaming starts on first use, each reading is the
/// newest record, lost and reordered records are counted (not errors), the `Bias` command sends
/// the sensor's software-bias request.
///
/// rp.cfg settings (besides ForceTorqueSensor's):
/// | setting | meaning |
/// |---|---|
/// | `address A` | sensor IPv4 address (default 127.0.0.1) |
/// | `port P` | RDT UDP port (default 49152) |
/// | `countsPerForce C`, `countsPerTorque C` | the sensor's calibration (cfgcpf, cfgcpt; default 1000000) |
/// | `timeout MS` | how long read() waits for a record (default 100) |
class AtiFTSensor : public ForceTorqueSensor {
 public:
  /// Creates the sensor (the network is used on the first reading, in hardware mode).
  /// @param[in] name  object name (rp.cfg section); empty for an automatic name
  /// @throws ConfigError if a setting is invalid
  /// Real-time safe: no.
  explicit AtiFTSensor(const std::string& name = "");
  ~AtiFTSensor() override;

  /// Declares the network and scaling settings.
  /// @param[out] schema  schema to add to
  static void declareSettings(SettingSchema& schema);

  /// Records lost in the stream so far (see NetFtClient::lostRecords()). Real-time safe: yes.
  std::uint64_t lostRecords() const noexcept;
  /// Records that arrived out of order so far. Real-time safe: yes.
  std::uint64_t outOfOrderRecords() const noexcept;

 protected:
  IoStatus hardwareRead(Vector<3>& force, Vector<3>& torque, int timeoutMs) noexcept override;
  IoStatus hardwareBias() noexcept override;
  const char* hardwareError() const noexcept override;
  int readTimeoutMs() const noexcept override { return timeoutMs_; }

 private:
  IoStatus ensureStreaming() noexcept;

  std::unique_ptr<NetFtClient> client_;
  bool streaming_ = false;
  int timeoutMs_ = 100;
};

}  // namespace rp
