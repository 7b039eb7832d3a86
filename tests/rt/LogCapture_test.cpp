// QMotor's log (ControlProgram::setLogCapture()): the chosen columns at the chosen decimation, the
// trigger (rising, falling), a full buffer, the CSV in the log file's format, every refusal
// naming its field, and setting it up again while the loop runs.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "rp/rt/Clock.hpp"
#include "rp/rt/ControlProgram.hpp"

namespace rp {
namespace {

// x = the cycle number, q = (x, -x, 2x), wave = sin(x / 10).
class Ramp : public ControlProgram {
 public:
  explicit Ramp(const std::string& name = "ramp") : ControlProgram(name) {
    registerLogVariable("x", x, "1");
    registerLogVariable("q", q, "rad");
    registerLogVariable("wave", wave);
    setLogWriter(nullptr);
  }
  ~Ramp() override { stop(); }
  double x = 0, wave = 0;
  Vector<3> q;

 protected:
  void control() override {
    x = static_cast<double>(getCycleCount());
    q = x, -x, 2 * x;
    wave = std::sin(x / 10);
  }
};

std::vector<std::vector<std::string>> csvRows(const std::string& csv) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(csv);
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::istringstream l(line);
    std::string cell;
    while (std::getline(l, cell, ',')) cells.push_back(cell);
    rows.push_back(cells);
  }
  return rows;
}

LogCaptureSettings triggered(std::vector<std::string> variables, std::size_t samples, unsigned every,
                             const std::string& column, double level, bool rising) {
  LogCaptureSettings s;
  s.variables = std::move(variables);
  s.samples = samples;
  s.every = every;
  s.triggerColumn = column;
  s.triggerLevel = level;
  s.triggerRising = rising;
  return s;
}

void run(Ramp& r, SimulatedClock& clock, std::uint64_t cycles) {
  r.setClock(clock);
  r.setCycleLimit(cycles);
  r.start();
  r.waitUntilStopped();
}

TEST(LogCapture, ChosenColumnsAtTheChosenDecimationUntilFull) {
  SimulatedClock clock(1e-3);
  Ramp r;
  LogCaptureSettings s;
  s.variables = {"q", "x"};  // columns in registration order: x, then q
  s.every = 4;
  s.samples = 10;
  r.setLogCapture(s);
  run(r, clock, 100);
  const LogCaptureStatus st = r.getLogCaptureStatus();
  EXPECT_TRUE(st.armed);
  EXPECT_TRUE(st.triggered);
  EXPECT_EQ(st.rows, 10u);
  EXPECT_EQ(st.capacity, 10u);
  EXPECT_EQ(st.columns, (std::vector<std::string>{"ramp.x", "ramp.q[0]", "ramp.q[1]", "ramp.q[2]"}));
  const auto rows = csvRows(r.getLogCaptureCsv());
  ASSERT_EQ(rows.size(), 11u);
  EXPECT_EQ(rows[0], (std::vector<std::string>{"t", "ramp.x", "ramp.q[0]", "ramp.q[1]", "ramp.q[2]"}));
  for (std::size_t i = 1; i < rows.size(); ++i) {
    ASSERT_EQ(rows[i].size(), 5u);
    const double x = std::stod(rows[i][1]);
    EXPECT_EQ(x, 4.0 * static_cast<double>(i - 1)) << "row " << i;  // cycles 0, 4, 8, ...
    EXPECT_NEAR(std::stod(rows[i][0]), 1e-3 * x, 1e-12);              // 1 ms per cycle
    EXPECT_EQ(std::stod(rows[i][4]), 2 * x);
  }
}

TEST(LogCapture, RisingTriggerStartsTheLogInTheCycleOfTheCrossing) {
  SimulatedClock clock(1e-3);
  Ramp r;
  LogCaptureSettings s = triggered({"x"}, 5, 2, "q[2]", 51, true);  // 2x crosses 51 between x = 25 and x = 26
  r.setLogCapture(s);
  run(r, clock, 200);
  const LogCaptureStatus st = r.getLogCaptureStatus();
  EXPECT_TRUE(st.triggered);
  EXPECT_NEAR(st.triggerTime, 0.026, 1e-12);
  const auto rows = csvRows(r.getLogCaptureCsv());
  ASSERT_EQ(rows.size(), 6u);
  for (std::size_t i = 1; i < rows.size(); ++i) EXPECT_EQ(std::stod(rows[i][1]), 26.0 + 2.0 * static_cast<double>(i - 1));

  // A value that reaches the level exactly has crossed it (x = 26 = the level: the row of cycle 26).
  Ramp r2("ramp2");
  s.triggerColumn = "x";
  s.triggerLevel = 26;
  r2.setLogCapture(s);
  SimulatedClock clock2(1e-3);
  run(r2, clock2, 100);
  EXPECT_NEAR(r2.getLogCaptureStatus().triggerTime, 0.026, 1e-12);
}

TEST(LogCapture, FallingTriggerAndATriggerThatNeverFires) {
  SimulatedClock clock(1e-3);
  Ramp r;
  LogCaptureSettings s = triggered({"wave"}, 3, 1, "wave", 0, false);  // sin(x/10) falls through 0 at x = 10 pi
  r.setLogCapture(s);
  run(r, clock, 100);
  auto rows = csvRows(r.getLogCaptureCsv());
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_LE(std::stod(rows[1][1]), 0.0);
  EXPECT_NEAR(std::stod(rows[1][0]), 0.032, 1e-12);  // the first cycle at or below 0

  // q[1] = -x never rises through 1: armed, nothing logged.
  Ramp r2("ramp2");
  s.variables = {};
  s.triggerColumn = "q[1]";
  s.triggerLevel = 1;
  s.triggerRising = true;
  r2.setLogCapture(s);
  SimulatedClock clock2(1e-3);
  run(r2, clock2, 100);
  const LogCaptureStatus st = r2.getLogCaptureStatus();
  EXPECT_TRUE(st.armed);
  EXPECT_FALSE(st.triggered);
  EXPECT_EQ(st.rows, 0u);
  EXPECT_EQ(st.columns.size(), 5u);  // no variables chosen: all of them
  EXPECT_EQ(csvRows(r2.getLogCaptureCsv()).size(), 1u);  // the header only
}

TEST(LogCapture, EveryRefusalNamesItsField) {
  Ramp r;
  auto message = [&](LogCaptureSettings s) {
    try {
      r.setLogCapture(s);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  LogCaptureSettings s;
  s.variables = {"x", "nope"};
  EXPECT_EQ(message(s), "'variables': 'nope' is not a log variable of ramp (known: x, q, wave)");
  s.variables = {"x", "x"};
  EXPECT_EQ(message(s), "'variables': 'x' is given twice");
  s.variables = {"x"};
  s.every = 0;
  EXPECT_EQ(message(s), "'every' must be an integer in 1..1000000, got 0");
  s.every = 4000000000u;
  EXPECT_EQ(message(s), "'every' must be an integer in 1..1000000, got 4000000000");
  s.every = 1;
  s.samples = 0;
  EXPECT_EQ(message(s), "'samples' must be in 1..500000 for 1 columns, got 0");
  s.samples = 500001;
  EXPECT_EQ(message(s), "'samples' must be in 1..500000 for 1 columns, got 500001");
  s.samples = 10;
  s.triggerColumn = "q[3]";
  EXPECT_EQ(message(s),
            "'trigger': 'q[3]' is not a log value of ramp (a scalar's name or a vector's name[i]; variables: x, q, wave)");
  s.triggerColumn = "q";
  EXPECT_NE(message(s), "no error");
  s.triggerColumn = "q[0]";
  s.triggerLevel = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(message(s), "'level' must be a finite number");
  s.triggerLevel = std::numeric_limits<double>::infinity();
  EXPECT_EQ(message(s), "'level' must be a finite number");
  EXPECT_FALSE(r.getLogCaptureStatus().armed);  // nothing was set
  EXPECT_THROW(r.getLogCaptureCsv(), std::logic_error);
  s.triggerLevel = 1;
  EXPECT_EQ(message(s), "no error");
  r.clearLogCapture();
  EXPECT_FALSE(r.getLogCaptureStatus().armed);
}

// Set up again and read while the loop runs at 5 kHz on the real clock: the loop never sees a
// freed buffer (ThreadSanitizer and AddressSanitizer runs check it), and every row it wrote is whole.
TEST(LogCaptureThreads, SetUpAgainAndReadWhileRunning) {
  Ramp r;
  r.setClock(RealClock::instance());
  r.setRate(5000);
  r.start();
  LogCaptureSettings s;
  s.variables = {"x", "q"};
  s.samples = 200;
  for (int i = 0; i < 200; ++i) {
    s.every = 1 + static_cast<unsigned>(i % 3);
    r.setLogCapture(s);
    std::this_thread::sleep_for(std::chrono::microseconds(300));
    for (const auto& row : csvRows(r.getLogCaptureCsv())) {
      ASSERT_EQ(row.size(), 5u);
      if (row[0] == "t") continue;
      const double x = std::stod(row[1]);
      ASSERT_EQ(std::stod(row[2]), x);
      ASSERT_EQ(std::stod(row[4]), 2 * x);
    }
  }
  r.stop();
  EXPECT_GT(r.getCycleCount(), 0u);
}

}  // namespace
}  // namespace rp
