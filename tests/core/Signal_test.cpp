// The CSV log is complete after SIGINT and SIGTERM: a child process logs, is signalled, and the
// parent reads the file.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "TestClasses.hpp"

namespace rp {
namespace {

std::vector<std::vector<std::string>> readCsv(const std::filesystem::path& path) {
  std::vector<std::vector<std::string>> rows;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::string> fields;
    std::stringstream ss(line);
    std::string f;
    while (std::getline(ss, f, ',')) fields.push_back(f);
    if (!line.empty() && line.back() == ',') fields.push_back("");
    rows.push_back(fields);
  }
  return rows;
}

void runAndSignal(int sig) {
  auto dir = test::scratchDirectory("signal" + std::to_string(sig));
  const auto log = dir / "log.csv";
  const auto part = dir / "log.csv.part";
  std::string a0 = RP_LOG_CHILD, a1 = "-log", a2 = log.string(), a3 = "-nogui";
  // An empty rp.cfg in the child's folder: nothing configured.
  pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    if (chdir(dir.c_str()) != 0) _exit(3);
    char* argv[] = {a0.data(), a1.data(), a2.data(), a3.data(), nullptr};
    execv(argv[0], argv);
    _exit(4);
  }
  // Wait (bounded) until rows reach the file, then signal.
  for (int i = 0; i < 2000; ++i) {
    std::error_code ec;
    if (std::filesystem::exists(part, ec) && std::filesystem::file_size(part, ec) > 2000) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_EQ(kill(pid, sig), 0);
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 128 + sig);
  EXPECT_FALSE(std::filesystem::exists(part));
  auto rows = readCsv(log);
  ASSERT_GE(rows.size(), 2u);
  EXPECT_EQ(rows[0], (std::vector<std::string>{"t", "child.count", "child.v[0]", "child.v[1]"}));
  // Every cycle is there, in order, complete: count runs 0, 1, 2, ... and t advances one period.
  for (std::size_t r = 1; r < rows.size(); ++r) {
    ASSERT_EQ(rows[r].size(), 4u) << "row " << r;
    const double count = std::stod(rows[r][1]);
    EXPECT_EQ(count, static_cast<double>(r - 1));
    EXPECT_EQ(std::stod(rows[r][2]), 2 * count);
    EXPECT_EQ(std::stod(rows[r][3]), -count);
    if (r > 1) {  // one period, or a whole number of periods after an overrun on a busy machine
      const double periods = (std::stod(rows[r][0]) - std::stod(rows[r - 1][0])) / 0.001;
      EXPECT_GE(periods, 1 - 1e-6);
      EXPECT_NEAR(periods, std::round(periods), 1e-6);
    }
  }
}

TEST(SignalThreads, LogIsCompleteAfterSigint) { runAndSignal(SIGINT); }
TEST(SignalThreads, LogIsCompleteAfterSigterm) { runAndSignal(SIGTERM); }

}  // namespace
}  // namespace rp
