// However a program ends, the exit status says how, a shutdown in progress is completed first,
// and the log of it is on stderr: a real program (exit_child) with a moving Puma, ended by a
// return, a fault, an exception in calculate(), SIGINT, SIGTERM and an uncaught exception. Then
// the same exits with the Puma behind a hardware server (rp-hwserver -board puma560): after each
// the server's applied outputs are read as another client would: the amplifiers off and 0 V on
// every joint, switched off by the program itself (the server's watchdog did not have to), except
// after SIGKILL, where the watchdog does it.
#include <gtest/gtest.h>

#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "ChildProcess.hpp"
#include "rp/core/RoboticPlatform.hpp"
#include "rp/io/HwServerIoBoard.hpp"

namespace rp {
namespace {

struct ChildRun {
  int status = -1;
  std::string output;
};

// Runs exit_child in `mode` (signalling it with `sig` once ready, if sig != 0; `times` > 1: again
// as soon as it says its shutdown began, times - 1 times) and collects its output until it ends.
ChildRun runChild(const std::string& mode, int sig = 0, const std::vector<std::string>& extra = {}, int times = 1) {
  std::vector<std::string> argv{RP_EXIT_CHILD, mode, "-nogui"};
  argv.insert(argv.end(), extra.begin(), extra.end());
  test::ChildProcess child(argv);
  ChildRun run;
  bool ready = false;
  while (auto line = child.readLine(30000)) {
    run.output += *line + "\n";
    if (*line == "ready") {
      ready = true;
      if (sig != 0) child.signal(sig);
    }
    if (line->rfind("rp: system shutdown: ", 0) == 0 && ready) {
      for (int k = 1; sig != 0 && k < times; ++k) child.signal(sig);
    }
  }
  EXPECT_TRUE(ready) << run.output;
  if (auto status = child.wait(30000)) run.status = *status;
  return run;
}

bool has(const ChildRun& r, const std::string& text) { return r.output.find(text) != std::string::npos; }

TEST(ExitPath, AReturnWhileTheArmMovesExitsWithTheProgramsStatus) {
  const ChildRun r = runChild("return");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(has(r, "exit_child: done")) << r.output;
  EXPECT_FALSE(has(r, "system shutdown")) << r.output;
}

// A run ended by a system shutdown with `reason`: status 3, the shutdown completed, and the
// program said so instead of "done".
void expectShutdownExit(const std::string& mode, const std::string& reason) {
  const ChildRun r = runChild(mode);
  EXPECT_EQ(r.status, RoboticPlatform::kExitAfterShutdown) << r.output;
  EXPECT_TRUE(has(r, "rp: system shutdown: puma: " + reason)) << r.output;
  EXPECT_TRUE(has(r, "rp: system shutdown complete")) << r.output;
  EXPECT_TRUE(has(r, "exit_child: stopped by a system shutdown")) << r.output;
  EXPECT_FALSE(has(r, "exit_child: done")) << r.output;
}

TEST(ExitPath, AFaultEndsWithStatus3AfterTheShutdownCompleted) { expectShutdownExit("fault", "joint 1 velocity"); }

TEST(ExitPath, AnExceptionInCalculateEndsWithStatus3AndItsMessage) {
  expectShutdownExit("throw", "the servo control threw: encoder cable cut");
}

TEST(ExitPath, SigintAndSigtermAlwaysCompleteTheShutdownAndExit128PlusTheSignal) {
  // The exit status was a race before (0 in 5 of 10 runs): run each signal several times.
  for (int sig : {SIGINT, SIGTERM, SIGINT, SIGTERM, SIGINT, SIGTERM}) {
    const ChildRun r = runChild("signal", sig);
    EXPECT_EQ(r.status, 128 + sig) << r.output;
    EXPECT_TRUE(has(r, "rp: system shutdown complete")) << r.output;
    EXPECT_FALSE(has(r, "exit_child: done")) << r.output;
  }
}

// A signal again while the shutdown runs (`timeout` sends its signal to the program and then to
// its process group; an impatient Ctrl-C) does not cut the shutdown short: it used to end the
// process at once (SIG_DFL), with no hold, no "complete" and the log left as FILE.part.
TEST(ExitPath, ASecondSignalDuringTheShutdownDoesNotCutItShort) {
  for (int sig : {SIGINT, SIGTERM}) {
    const ChildRun r = runChild("signal", sig, {}, 3);
    EXPECT_EQ(r.status, 128 + sig) << r.output;
    EXPECT_TRUE(has(r, "rp: system shutdown complete")) << r.output;
  }
}

TEST(ExitPath, AnUncaughtExceptionEndsWithStatus1AndItsMessage) {
  const ChildRun r = runChild("uncaught");
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_TRUE(has(r, "error: the work piece is not where it should be")) << r.output;
}

// The Puma behind `rp-hwserver -board puma560`, for each way a program ends.
class HardwareExitPath : public ::testing::Test {
 protected:
  void SetUp() override {
    name_ = "exit-" + std::to_string(::getpid());
    dir_ = std::filesystem::temp_directory_path() / ("rp-" + name_);
    std::filesystem::create_directories(dir_);
    std::ofstream(dir_ / "rp.cfg") << "[puma]\nclass Puma560\nsimulationMode off\nhwserver " << name_ << "\n";
    server_ = std::make_unique<test::ChildProcess>(
        std::vector<std::string>{RP_HWSERVER_PATH, "-name", name_, "-rate", "1000", "-board", "puma560", "-watchdog", "1000"});
    ASSERT_TRUE(server_->readLine(30000).has_value()) << "the server did not start";
    monitor_ = std::make_unique<HwServerIoBoard>(name_);
  }
  void TearDown() override {
    monitor_.reset();
    server_.reset();
    std::filesystem::remove_all(dir_);
  }

  bool outputsOff() {
    bool enable = true;
    if (monitor_->readAppliedDigitalOutput(0, enable) != IoStatus::kOk || enable) return false;
    for (int j = 0; j < 6; ++j) {
      double volts = 1;
      if (monitor_->readAppliedAnalogOutput(j, volts) != IoStatus::kOk || volts != 0.0) return false;
    }
    return true;
  }
  // Waits (generously: the machine may be loaded) until the outputs are off. The server's
  // watchdog is 1 s here, so outputs off well before that were switched off by the program.
  bool waitUntilOff() {
    for (int i = 0; i < 10000; ++i) {
      if (outputsOff()) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    return false;
  }

  // Runs exit_child in `mode` against the server; `sig` is sent once it is ready. Checks that the
  // amplifiers were on while it ran, its exit status, and the outputs after it.
  void run(const std::string& mode, int sig, int status, int times = 1) {
    const std::uint64_t tripsBefore = monitor_->watchdogTrips();
    ChildRun r = runChild(mode, sig, {"-nosim", "-config", (dir_ / "rp.cfg").string()}, times);
    EXPECT_EQ(r.status, status) << mode << ":\n" << r.output;
    EXPECT_TRUE(waitUntilOff()) << mode << ": the amplifiers or a DAC are still on after the program ended";
    if (sig == SIGKILL) {
      EXPECT_EQ(monitor_->watchdogTrips(), tripsBefore + 1) << "the server's watchdog switched the outputs off";
    } else {
      EXPECT_EQ(monitor_->watchdogTrips(), tripsBefore) << mode << ": the program left its outputs on for the watchdog";
    }
  }

  std::string name_;
  std::filesystem::path dir_;
  std::unique_ptr<test::ChildProcess> server_;
  std::unique_ptr<HwServerIoBoard> monitor_;
};

TEST_F(HardwareExitPath, Return) { run("return", 0, 0); }
TEST_F(HardwareExitPath, LimitShutdown) { run("fault", 0, RoboticPlatform::kExitAfterShutdown); }
TEST_F(HardwareExitPath, ExceptionInCalculate) { run("throw", 0, RoboticPlatform::kExitAfterShutdown); }
TEST_F(HardwareExitPath, Sigint) { run("signal", SIGINT, 128 + SIGINT); }
TEST_F(HardwareExitPath, Sigterm) { run("signal", SIGTERM, 128 + SIGTERM); }
TEST_F(HardwareExitPath, Sigkill) { run("signal", SIGKILL, 128 + SIGKILL); }
TEST_F(HardwareExitPath, SigintThreeTimes) { run("signal", SIGINT, 128 + SIGINT, 3); }
TEST_F(HardwareExitPath, UncaughtException) { run("uncaught", 0, 1); }

}  // namespace
}  // namespace rp
