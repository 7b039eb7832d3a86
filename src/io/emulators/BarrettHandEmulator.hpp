#pragma once
// BarrettHand emulator on a pseudo-terminal: answers the supervisory command protocol of
// refdata/07 (echo, reply text, ERR codes, "=> " prompt). For tests and `rp-emulate barretthand`.

#include <array>
#include <atomic>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace rp::emulator {

class BarrettHandEmulator {
 public:
  struct Config {
    int moveTimeMs = 0;          // time a motion command (HI, C, O, M, HOME) takes before the prompt
    int fingerClosed = 17500;    // finger position after C with nothing in the hand [counts]
    int objectAt = -1;           // if >= 0, fingers stop here when closing (an object in the hand)
    bool requireInit = true;     // motor commands before HI answer ERR 4 (motor not initialized)
  };
  // Silent: read commands, answer nothing. Garbled: answer bytes that are not the echo.
  // Truncated: echo and part of the reply, no prompt. Error: answer every command with ERR errorCode.
  // WrongText: echo and prompt as the hand's, with setWrongText()'s text between them whatever
  // the command (a reply that is not the protocol's).
  enum class Fault { kNone, kSilent, kGarbled, kTruncated, kError, kWrongText };

  explicit BarrettHandEmulator(const Config& config);
  BarrettHandEmulator();
  ~BarrettHandEmulator();
  BarrettHandEmulator(const BarrettHandEmulator&) = delete;
  BarrettHandEmulator& operator=(const BarrettHandEmulator&) = delete;

  // Opens the pseudo-terminal and starts answering; throws std::runtime_error on failure.
  void start();
  // Closes the pseudo-terminal (as if the cable were pulled): the driver sees a hang-up.
  void stop();
  // Path of the serial port to open, e.g. /dev/pts/5.
  const std::string& devicePath() const { return path_; }

  void setFault(Fault fault, int errorCode = 32) {
    errorCode_.store(errorCode);
    fault_.store(fault);
  }
  void setWrongText(const std::string& text) {
    std::lock_guard lock(mutex_);
    wrongText_ = text;
  }
  bool initialized() const { return initialized_.load(); }
  std::array<int, 4> positions() const;
  std::vector<std::string> commands() const;  // every command line received, in order

 private:
  void serve();
  std::string execute(const std::string& line);  // reply text, "" or "ERR n"
  void send(const std::string& bytes);

  Config config_;
  int master_ = -1;
  int slave_ = -1;  // kept open so the master never sees a hang-up between driver sessions
  std::string path_;
  std::atomic<bool> stopRequested_{false};
  std::atomic<Fault> fault_{Fault::kNone};
  std::atomic<int> errorCode_{32};
  std::atomic<bool> initialized_{false};
  mutable std::mutex mutex_;
  std::array<int, 4> positions_{};
  std::vector<std::string> commands_;
  std::string wrongText_;  // under mutex_
  std::thread thread_;
};

}  // namespace rp::emulator
