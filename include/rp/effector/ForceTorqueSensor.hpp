#pragma once
/// @file
/// The generic force/torque sensor interface (paper section 3.4).

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>

#include "rp/core/PhysicalObject.hpp"
#include "rp/io/IoStatus.hpp"
#include "rp/math/Matrix.hpp"
#include "rp/rt/TripleBuffer.hpp"

namespace rp {

/// One force/torque reading in the sensor frame.
struct ForceTorqueReading {
  Vector<3> force = Vector<3>::Zero();   ///< force [N]
  Vector<3> torque = Vector<3>::Zero();  ///< torque [N m]
  std::uint64_t count = 0;               ///< readings taken so far (0: none yet)
};

/// Generic interface of a force/torque sensor (paper section 3.4): read forces and torques,
/// and bias (tare) the sensor.
///
/// Registers the interactive command `Bias`, describes a control panel with the last reading,
/// and answers the message `read` with `{"force": [fx, fy, fz], "torque": [tx, ty, tz]}`.
///
/// In simulation mode the sensor reports the weight of a simulated payload (mass and centre of
/// mass in the sensor frame; gravity is -z of the world, rotated by the sensor's pose) plus a
/// simulated external wrench, minus the bias.
///
/// The library drives update(): the sensor asks for an additional periodic thread
/// (RoboticObject::addPeriodicThread()) that calls it `updateRate` times a second (default
/// 1000), from the most-derived constructor's startControlLoop() until its destructor. update()
/// never blocks or allocates; when the sensor fails (closed, garbled, or no new reading for
/// `maxMissedCycles` cycles in a row; before the first reading, for up to 2 s of the update
/// thread's cycles) it sets the error status and asks the ObjectManager for a
/// system shutdown, so the arm is brought to rest. getLastReading() gives the newest reading
/// without waiting (also in a servo loop). With `updateRate 0` no thread is started and the
/// program's own loop calls update() every cycle.
///
/// rp.cfg settings (besides PhysicalObject's): `payload MASS` [kg],
/// `payloadCenter X Y Z` [mm], `maxMissedCycles N` (default 50), `updateRate HZ` (default 1000).
class ForceTorqueSensor : public PhysicalObject {
 public:
  /// Creates the sensor and registers its command.
  /// @param[in] name  object name (rp.cfg section); empty for an automatic name
  /// @throws ConfigError if a setting is invalid
  /// Real-time safe: no.
  explicit ForceTorqueSensor(const std::string& name = "");
  ~ForceTorqueSensor() override;

  /// Declares `payload`, `payloadCenter`, `maxMissedCycles` and `updateRate`.
  /// @param[out] schema  schema to add to
  static void declareSettings(SettingSchema& schema);

  /// Takes a reading, waiting for the sensor if needed (bounded by the sensor's timeout).
  /// @param[out] force  force in the sensor frame [N]
  /// @param[out] torque  torque in the sensor frame [N m]
  /// @return true on success; false on a sensor failure (see getErrorStatus())
  /// Real-time safe: no. May be called while the library's thread runs update() (the two take
  /// turns at the sensor).
  bool read(Vector<3>& force, Vector<3>& torque);
  /// Takes the current load as zero (the sensor's own bias command on hardware).
  /// @return true on success; false on a sensor failure
  /// Real-time safe: no.
  bool bias();
  /// One cycle of the sensor's update thread (or of the program's loop with `updateRate 0`):
  /// fetches the newest reading without waiting; on a sensor failure sets the error status and
  /// requests a system shutdown (once). While read() or bias() holds the sensor the cycle is
  /// skipped (it does not wait) and counts as healthy.
  /// @return true if the sensor is healthy (a new reading, or a tolerated gap)
  /// Real-time safe: yes on hardware (a non-blocking receive into fixed buffers, proven
  /// allocation-free by the tests); in simulation it takes two short, uncontended locks to read
  /// the pose and the simulated wrench.
  bool update() noexcept;

  /// The last reading (from read() or update()). Real-time safe: no (readers share a mutex).
  ForceTorqueReading getLastReading() const;
  /// The rate of the update thread [Hz]; 0 when the program calls update() itself.
  double getUpdateRate() const noexcept { return updateRate_; }

  /// Sets the simulated external wrench on the sensor.
  /// @param[in] force  force in the sensor frame [N]
  /// @param[in] torque  torque in the sensor frame [N m]
  /// Real-time safe: no.
  void setSimulatedWrench(const Vector<3>& force, const Vector<3>& torque);
  /// Sets the simulated payload.
  /// @param[in] mass  payload mass [kg], >= 0
  /// @param[in] centerOfMass  centre of mass in the sensor frame [m]
  /// Real-time safe: no.
  void setSimulatedPayload(double mass, const Vector<3>& centerOfMass);

  /// Adds the force and torque to the default panel. Real-time safe: no.
  ControlPanel getControlPanel() const override;
  /// Publishes force (3 values) and torque (3 values).
  /// @param[out] snapshot  receives the values
  /// @return true
  /// Real-time safe: no.
  bool getStateSnapshot(StateSnapshot& snapshot) const override;
  /// Answers `read` with the last reading as JSON (taking a reading first if there is none).
  /// Real-time safe: no.
  bool handleMessage(const std::string& type, const std::string& payload, std::string& reply) override;

 protected:
  /// Fetches the newest hardware reading.
  /// @param[out] force  [N]
  /// @param[out] torque  [N m]
  /// @param[in] timeoutMs  longest wait [ms]; 0 = do not wait (must then be real-time safe)
  /// @return `kOk`, `kDataLoss` (a reading, with a gap before it), `kTimeout` (nothing new), or a
  ///         failure; on failure `hardwareError()` says why
  virtual IoStatus hardwareRead(Vector<3>& force, Vector<3>& torque, int timeoutMs) noexcept = 0;
  /// Biases the hardware. @return `kOk` or a failure
  virtual IoStatus hardwareBias() noexcept = 0;
  /// The message of the last hardware failure.
  virtual const char* hardwareError() const noexcept = 0;
  /// The timeout read() gives hardwareRead() [ms].
  virtual int readTimeoutMs() const noexcept { return 100; }

 private:
  void simulatedReading(Vector<3>& force, Vector<3>& torque) const;
  void fail(const char* what) noexcept;
  void publish(const Vector<3>& force, const Vector<3>& torque) noexcept;

  std::mutex sensorMutex_;  // read(), bias() and update() take turns at the sensor (update(): try_lock)
  double updateRate_ = 1000;
  mutable std::mutex simMutex_;
  Vector<3> simForce_ = Vector<3>::Zero(), simTorque_ = Vector<3>::Zero();
  double payloadMass_ = 0.0;
  Vector<3> payloadCenter_ = Vector<3>::Zero();
  Vector<3> biasForce_ = Vector<3>::Zero(), biasTorque_ = Vector<3>::Zero();  // simulation only
  int maxMissedCycles_ = 50;
  int missedCycles_ = 0;
  std::atomic<bool> shutdownRequested_{false};
  struct Published {  // trivially copyable form of a reading for the TripleBuffer
    double values[6];
    std::uint64_t count;
  };
  std::uint64_t count_ = 0;  // owned by the reading thread
  TripleBuffer<Published> published_;
};

}  // namespace rp
