#pragma once
// Modbus TCP I/O server (libmodbus) on 127.0.0.1 for tests and `rp-emulate modbus`.
// Not part of libroboticplatform: built into the static library rp_emulators.

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace rp::emulator {

class ModbusEmulator {
 public:
  struct Config {
    std::string address = "127.0.0.1";
    int port = 0;  // 0 = an ephemeral port, see port()
    int coils = 64;
    int discreteInputs = 64;
    int holdingRegisters = 64;
    int inputRegisters = 64;
  };
  // Silent: receive requests but never answer. Garbled: answer with a reply whose function code
  // does not match. Truncated: answer with only part of a reply header.
  enum class Fault { kNone, kSilent, kGarbled, kTruncated };

  explicit ModbusEmulator(const Config& config);
  ModbusEmulator();
  ~ModbusEmulator();
  ModbusEmulator(const ModbusEmulator&) = delete;
  ModbusEmulator& operator=(const ModbusEmulator&) = delete;

  // Binds, listens and starts the server thread; throws std::runtime_error on failure.
  void start();
  // Closes the listening socket and every connection (as if the device were switched off).
  void stop();
  bool running() const { return running_.load(); }
  int port() const { return port_; }

  bool coil(int address) const;
  // How many times a request switched the coil from off to on.
  long coilSwitchedOn(int address) const;
  void setCoil(int address, bool value);
  void setDiscreteInput(int address, bool value);
  std::uint16_t holdingRegister(int address) const;
  void setInputRegister(int address, std::uint16_t value);
  void setFault(Fault fault) { fault_.store(fault); }
  long requestsReceived() const { return requests_.load(); }

 private:
  void serve();

  Config config_;
  void* ctx_ = nullptr;      // modbus_t*
  void* mapping_ = nullptr;  // modbus_mapping_t*
  mutable std::mutex mutex_;
  int listenFd_ = -1;
  int port_ = 0;
  std::atomic<bool> running_{false};
  std::atomic<bool> stopRequested_{false};
  std::atomic<Fault> fault_{Fault::kNone};
  std::atomic<long> requests_{0};
  std::vector<long> switchedOn_;  // per coil, under mutex_
  std::thread thread_;
};

}  // namespace rp::emulator
