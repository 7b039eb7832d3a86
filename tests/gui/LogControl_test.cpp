// Starting and stopping the log file and reading recent log samples (LogWriter::stopLogging,
// startLogging, getColumns, getRecentSamples): what the QMotor window uses. On a simulated clock
// the program itself stops and starts the log at known cycles, so the file's rows are exact.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "rp/rt/Clock.hpp"
#include "rp/rt/ControlProgram.hpp"
#include "rp/rt/LogWriter.hpp"

namespace {

class Counter : public rp::ControlProgram {
 public:
  Counter(rp::LogWriter& writer) : rp::ControlProgram("p"), writer_(writer) {
    registerLogVariable("x", x, "m");
    registerLogVariable("q", q.data(), 2, "rad");
  }
  ~Counter() override { stop(); }
  double x = 0;
  std::vector<double> q = {0, 0};

 protected:
  void control() override {
    const auto k = getCycleCount();
    x = static_cast<double>(k);
    q[0] = 2.0 * x;
    q[1] = -x;
    // The sample of this cycle is taken after control(): stopping here leaves cycle 300 out,
    // starting here puts cycle 600 in. (Not real-time safe: a test of the writer only.)
    if (k == 300) writer_.stopLogging();
    if (k == 600) writer_.startLogging();
  }

 private:
  rp::LogWriter& writer_;
};

TEST(LogControl, StopAndStartChangeWhatTheFileHolds) {
  const auto dir = std::filesystem::temp_directory_path() / ("rp_log_control_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto file = dir / "log.csv";
  {
    rp::LogWriter writer(file.string());
    EXPECT_TRUE(writer.isLogging());
    rp::SimulatedClock clock(1e-3, true);
    Counter p(writer);
    p.setClock(clock);
    p.setLogWriter(&writer);
    p.setLogBufferSize(2048);
    p.setCycleLimit(1000);
    EXPECT_TRUE(writer.getRecentSamples({}, 0.0).empty());  // from this first call on it keeps samples
    p.start();
    EXPECT_EQ(writer.getColumns(), (std::vector<std::string>{"p.x", "p.q[0]", "p.q[1]"}));
    clock.resume();
    p.waitUntilStopped();
    EXPECT_TRUE(writer.isLogging());
    // Every sample reaches the plots, logged to the file or not.
    auto recent = writer.getRecentSamples({"p.q[0]", "p.x"}, -1.0);
    ASSERT_EQ(recent.size(), 2u);
    EXPECT_EQ(recent[0].column, "p.q[0]");
    ASSERT_EQ(recent[0].time.size(), 1000u);
    EXPECT_DOUBLE_EQ(recent[0].value[450], 900.0);
    EXPECT_DOUBLE_EQ(recent[1].value[999], 999.0);
    // Only samples after a time, and at most the newest n.
    auto after = writer.getRecentSamples({"p.x"}, 0.9995, 4096);
    ASSERT_EQ(after[0].time.size(), 0u);
    after = writer.getRecentSamples({"p.x"}, 0.9945, 3);
    ASSERT_EQ(after[0].value.size(), 3u);
    EXPECT_DOUBLE_EQ(after[0].value[0], 997.0);
    try {
      writer.getRecentSamples({"p.y"}, 0);
      FAIL() << "an unknown column was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("'p.y'"), std::string::npos) << e.what();
    }
    writer.close();
    writer.stopLogging();  // after close: nothing happens
  }
  std::ifstream in(file);
  std::string line;
  std::vector<double> times;
  std::getline(in, line);
  EXPECT_EQ(line, "t,p.x,p.q[0],p.q[1]");
  while (std::getline(in, line)) times.push_back(std::stod(line.substr(line.find(',') + 1)));  // p.x = cycle
  ASSERT_EQ(times.size(), 700u);  // cycles 0..299 and 600..999
  EXPECT_EQ(times[299], 299.0);
  EXPECT_EQ(times[300], 600.0);
  EXPECT_EQ(times.back(), 999.0);
  std::filesystem::remove_all(dir);
}

}  // namespace
