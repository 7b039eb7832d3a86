#pragma once
// An I/O board wired to an emulated manipulator (the Puma 560 behind rp-hwserver -board puma560):
// encoder counts in (joint angle x countsPerRadian), motor torque out as DAC volts through an
// amplifier gain [N m/V]; the arm's dynamics (the model's forward dynamics with gravity, motor
// inertia and friction) are integrated between I/O operations. Digital output 0 is the amplifier
// enable: while it is off the brakes hold the arm. Part of rp_emulators, not the library.

#include <chrono>
#include <memory>
#include <mutex>

#include "rp/io/IoBoard.hpp"
#include "rp/model/Dynamics.hpp"
#include "rp/model/ManipulatorModel.hpp"

namespace rp::emulator {

class ArmIoBoard : public IoBoard {
 public:
  struct Config {
    double countsPerRadian = 20000.0;  // encoder resolution at the joint [counts/rad]
    JointVector amplifierGain;         // [N m/V] per joint; empty: torque limit / 10 V (or 10 N m/V)
    double dacRange = 10.0;            // DAC output range +-[V]
    double stepSeconds = 0.0005;       // integration step [s]
    bool realTime = true;              // reads advance the simulation to the current time
    JointVector initialPosition;       // [rad]; empty: the model's home position
  };

  // `model` must outlive the board. The arm starts at rest (at the home position by default).
  ArmIoBoard(const ManipulatorModel& model, const Config& config);
  ArmIoBoard(const ManipulatorModel& model);

  int numDigitalInputs() const noexcept override { return 0; }
  int numDigitalOutputs() const noexcept override { return 1; }
  int numAnalogInputs() const noexcept override { return 0; }
  int numAnalogOutputs() const noexcept override { return n_; }
  int numEncoders() const noexcept override { return n_; }

  IoStatus readDigitalInput(int line, bool& value) noexcept override;
  IoStatus writeDigitalOutput(int line, bool value) noexcept override;
  IoStatus readDigitalOutput(int line, bool& value) noexcept override;
  IoStatus readAnalogInput(int channel, double& volts) noexcept override;
  IoStatus writeAnalogOutput(int channel, double volts) noexcept override;
  IoStatus readEncoder(int encoder, std::int64_t& counts) noexcept override;

  // Integrates the dynamics for `seconds` (in steps of stepSeconds; at most 1 s at a time).
  void advance(double seconds) noexcept;
  JointVector position() const;
  JointVector velocity() const;
  double amplifierGain(int joint) const { return gain_[joint]; }

 private:
  void catchUp() noexcept;

  const ManipulatorModel& model_;
  Config config_;
  int n_;
  mutable std::mutex mutex_;  // the server thread and a test may both look
  std::unique_ptr<ManipulatorData> data_;
  JointVector q_, qd_, volts_, gain_, tau_;
  bool enabled_ = false;
  std::chrono::steady_clock::time_point last_;
};

}  // namespace rp::emulator
