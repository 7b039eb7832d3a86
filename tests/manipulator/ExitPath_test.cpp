// However a program ends, the exit status says how, a shutdown in progress is completed first,
// and the log of it is on stderr: a real program (exit_child) with a moving Puma, ended by a
// return, a fault, an exception in calculate(), SIGINT, SIGTERM and an uncaught exception.
#include <gtest/gtest.h>

#include <signal.h>

#include <string>
#include <vector>

#include "ChildProcess.hpp"
#include "rp/core/RoboticPlatform.hpp"

namespace rp {
namespace {

struct ChildRun {
  int status = -1;
  std::string output;
};

// Runs exit_child in `mode` (signalling it with `sig` once ready, if sig != 0) and collects its
// output until it ends.
ChildRun runChild(const std::string& mode, int sig = 0, const std::vector<std::string>& extra = {}) {
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

TEST(ExitPath, AFaultEndsWithStatus3AfterTheShutdownCompleted) {
  const ChildRun r = runChild("fault");
  EXPECT_EQ(r.status, RoboticPlatform::kExitAfterShutdown) << r.output;
  EXPECT_TRUE(has(r, "rp: system shutdown: puma: joint 1 velocity")) << r.output;
  EXPECT_TRUE(has(r, "rp: system shutdown complete")) << r.output;
  EXPECT_TRUE(has(r, "exit_child: stopped by a system shutdown")) << r.output;
  EXPECT_FALSE(has(r, "exit_child: done")) << r.output;
}

TEST(ExitPath, AnExceptionInCalculateEndsWithStatus3AndItsMessage) {
  const ChildRun r = runChild("throw");
  EXPECT_EQ(r.status, RoboticPlatform::kExitAfterShutdown) << r.output;
  EXPECT_TRUE(has(r, "rp: system shutdown: puma: the servo control threw: encoder cable cut")) << r.output;
  EXPECT_TRUE(has(r, "rp: system shutdown complete")) << r.output;
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

TEST(ExitPath, AnUncaughtExceptionEndsWithStatus1AndItsMessage) {
  const ChildRun r = runChild("uncaught");
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_TRUE(has(r, "error: the work piece is not where it should be")) << r.output;
}

}  // namespace
}  // namespace rp
