// QMotor's requests from the page (src/gui/QMotorRequests.cpp): every field of a message is checked
// and a refusal names it; files are read and written only in the program's folder; save then load
// round-trips a changed gain, a bad file is refused with FILE:LINE and changes nothing; QMotor's
// log comes back as CSV; a Puma 560 stopped from the page comes to rest braked and starts again
// holding where it is.
#include "QMotorRequests.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <thread>

#include "rp/RoboticPlatform.hpp"

namespace rp {
namespace {

using nlohmann::json;
using internal::parseQMotorRequest;
using internal::qmotorFileIn;
using internal::runQMotorRequest;

std::string refusal(const std::string& text) {
  try {
    parseQMotorRequest(json::parse(text));
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "accepted";
}

TEST(QMotorRequests, EveryFieldIsCheckedAndARefusalNamesIt) {
  EXPECT_EQ(refusal(R"({"type":"qmotor"})"), "'action' must be a string");
  EXPECT_EQ(refusal(R"({"action":7})"), "'action' must be a string");
  EXPECT_EQ(refusal(R"({"action":"format"})").rfind("'action' must be one of status, start", 0), 0u);
  EXPECT_EQ(refusal(R"({"action":"load"})"), "'file' must be a string");
  EXPECT_EQ(refusal(R"({"action":"load","file":""})"), "'file' must have 1 to 128 characters");
  EXPECT_EQ(refusal(R"({"action":"save","file":3})"), "'file' must be a string");
  EXPECT_EQ(refusal(R"({"action":"save"})"), "accepted");
  EXPECT_EQ(refusal(R"({"action":"capture","variables":"q"})"), "'variables' must be an array of at most 64 names");
  EXPECT_EQ(refusal(R"({"action":"capture","variables":[1]})"), "'variables' must hold names of 1 to 256 characters");
  EXPECT_EQ(refusal(R"({"action":"capture","every":0})"), "'every' must be an integer in 1..1000000");
  EXPECT_EQ(refusal(R"({"action":"capture","every":1000001})"), "'every' must be an integer in 1..1000000");
  EXPECT_EQ(refusal(R"({"action":"capture","every":1e300})"), "'every' must be an integer in 1..1000000");
  EXPECT_EQ(refusal(R"({"action":"capture","every":2.5})"), "'every' must be an integer in 1..1000000");
  EXPECT_EQ(refusal(R"({"action":"capture","every":18446744073709551615})"), "'every' must be an integer in 1..1000000");
  EXPECT_EQ(refusal(R"({"action":"capture","every":null})"), "'every' must be an integer in 1..1000000");
  EXPECT_EQ(refusal(R"({"action":"capture","samples":-1})"), "'samples' must be an integer in 1..500000");
  EXPECT_EQ(refusal(R"({"action":"capture","trigger":"x"})"), "'trigger' must be an object {column, level, edge} or null");
  EXPECT_EQ(refusal(R"({"action":"capture","trigger":{"level":1,"edge":"rising"}})"), "'column' must be a string");
  EXPECT_EQ(refusal(R"({"action":"capture","trigger":{"column":"x","edge":"rising"}})"),
            "'trigger.level' must be a finite number");
  EXPECT_EQ(refusal(R"({"action":"capture","trigger":{"column":"x","level":null,"edge":"rising"}})"),
            "'trigger.level' must be a finite number");
  EXPECT_EQ(refusal(R"({"action":"capture","trigger":{"column":"x","level":1,"edge":"up"}})"),
            "'trigger.edge' must be rising or falling");
  EXPECT_EQ(refusal(R"({"action":"capture","variables":["q"],"every":5,"samples":100,)"
                    R"("trigger":{"column":"q[0]","level":0.5,"edge":"falling"}})"),
            "accepted");
  const auto r = parseQMotorRequest(json::parse(R"({"action":"capture","every":5,"trigger":{"column":"q[0]",)"
                                                R"("level":-0.5,"edge":"falling"}})"));
  EXPECT_EQ(r.capture.every, 5u);
  EXPECT_EQ(r.capture.samples, 10000u);
  EXPECT_EQ(r.capture.triggerColumn, "q[0]");
  EXPECT_EQ(r.capture.triggerLevel, -0.5);
  EXPECT_FALSE(r.capture.triggerRising);
}

TEST(QMotorRequests, FilesAreOnlyPlainNamesInTheFolder) {
  const auto dir = std::filesystem::temp_directory_path() / ("rp_qmotor_files_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir / "sub.cfg");
  std::filesystem::create_symlink("/etc/passwd", dir / "link.cfg");
  const std::string folder = dir.string();
  EXPECT_EQ(qmotorFileIn(folder, "tuned-2.cfg"), dir / "tuned-2.cfg");
  for (const char* bad : {"../x.cfg", "/etc/x.cfg", "a/b.cfg", ".hidden.cfg", "x.txt", "x", ".cfg", "..", "x.cfg/",
                          "%2e%2e.cfg", "a b.cfg", "x\\y.cfg"}) {
    try {
      qmotorFileIn(folder, bad);
      ADD_FAILURE() << bad << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()).rfind("'file' must be a file name ending in .cfg", 0), 0u) << bad << ": " << e.what();
    }
  }
  EXPECT_THROW(qmotorFileIn(folder, std::string(125, 'a') + ".cfg"), std::invalid_argument);  // 129 characters
  for (const char* notRegular : {"sub.cfg", "link.cfg"}) {
    try {
      qmotorFileIn(folder, notRegular);
      ADD_FAILURE() << notRegular << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("is not a regular file"), std::string::npos) << e.what();
    }
  }
  std::filesystem::remove_all(dir);
}

// A tunable object with a control program.
class Tunable : public PhysicalObject, public ControlProgram {
 public:
  explicit Tunable(const std::string& name) : PhysicalObject(name), ControlProgram(name) {
    registerParameter("gain", gain, 0, 100, "N/m");
    registerParameter("kp", kp, 0, 1000);
    registerLogVariable("x", x);
    registerLogVariable("q", q);
    setLogWriter(nullptr);
    startControlLoop();
  }
  ~Tunable() override { stopControlLoop(); }
  ControlProgram* getControlProgram() override { return this; }
  double gain = 1, x = 0;
  Vector<2> kp = Vector<2>::Constant(10), q;

 protected:
  void control() override {
    x = static_cast<double>(getCycleCount());
    q = x, -x;
  }
};

class QMotorRequestsOnObjects : public ::testing::Test {
 protected:
  void SetUp() override {
    RoboticPlatform::setSimulationModeOn();
    ObjectManager::resetShutdown();
    dir_ = std::filesystem::temp_directory_path() / ("rp_qmotor_requests_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
    std::ofstream(dir_ / "tuned.cfg") << "gain 2\n";
    std::ofstream(dir_ / "rp.cfg") << "[tune]\nclass PhysicalObject\nqmotorConfig tuned.cfg\n";
    RoboticPlatform::setConfiguration(Configuration::read((dir_ / "rp.cfg").string(), Configuration::Options{true, false, true}));
  }
  void TearDown() override {
    RoboticPlatform::setConfiguration(Configuration());
    std::filesystem::remove_all(dir_);
  }
  json run(RoboticObject& o, const std::string& request) {
    return json::parse(runQMotorRequest(o, parseQMotorRequest(json::parse(request))));
  }
  std::string error(RoboticObject& o, const std::string& request) {
    try {
      run(o, request);
    } catch (const std::exception& e) {
      return e.what();
    }
    return "no error";
  }
  std::filesystem::path dir_;
};

TEST_F(QMotorRequestsOnObjects, SaveThenLoadRoundTripsAChangedGain) {
  Tunable t("tune");
  EXPECT_EQ(t.gain, 2.0) << "its qmotorConfig file";
  json status = run(t, R"({"action":"status"})")["status"];
  EXPECT_EQ(status["configFile"], (dir_ / "tuned.cfg").string());
  EXPECT_EQ(status["folder"], dir_.string());
  EXPECT_EQ(status["files"], json::array({"rp.cfg", "tuned.cfg"}));
  EXPECT_EQ(status["running"], true);
  // Tuned, saved to a new file, tuned again, loaded back (while running).
  t.setParameter("gain", 7.25);
  t.setParameter("kp", 1, 3.5);
  json saved = run(t, R"({"action":"save","file":"best.cfg"})");
  EXPECT_EQ(saved["message"], "saved the parameters of tune to " + (dir_ / "best.cfg").string());
  EXPECT_EQ(saved["status"]["files"], json::array({"best.cfg", "rp.cfg", "tuned.cfg"}));
  t.setParameter("gain", 1);
  t.setParameter("kp", 1, 1);
  json loaded = run(t, R"({"action":"load","file":"best.cfg"})");
  EXPECT_EQ(loaded["message"], "loaded " + (dir_ / "best.cfg").string() + " into tune");
  EXPECT_EQ(t.getParameter("gain"), std::vector<double>{7.25});
  EXPECT_EQ(t.getParameter("kp"), (std::vector<double>{10, 3.5}));
  // Save without a name: to the qmotorConfig file.
  run(t, R"({"action":"save"})");
  EXPECT_EQ(ParameterFile::read((dir_ / "tuned.cfg").string()).entries().back().name, "kp");
  // Never over rp.cfg, never outside the folder.
  EXPECT_EQ(error(t, R"({"action":"save","file":"rp.cfg"})"),
            "'file': " + (dir_ / "rp.cfg").string() + " is the configuration file, not a control-program file");
  EXPECT_EQ(error(t, R"({"action":"load","file":"../rp.cfg"})").rfind("'file' must be a file name ending in .cfg", 0), 0u);
}

// A program that takes 20 periods in every cycle from its 5th on: overruns of its executor, whatever
// the machine, each named after it (the slowest program of the cycle; a late wake-up alone would
// name whichever program happened to take longer).
class Hog : public PhysicalObject, public ControlProgram {
 public:
  explicit Hog(const std::string& name) : PhysicalObject(name), ControlProgram(name) {
    setLogWriter(nullptr);
    startControlLoop();
  }
  ~Hog() override { stopControlLoop(); }
  ControlProgram* getControlProgram() override { return this; }

 protected:
  void control() override {
    if (getCycleCount() < 5) return;
    const auto until = std::chrono::steady_clock::now() + std::chrono::microseconds(static_cast<long>(20e6 / getRate()));
    while (std::chrono::steady_clock::now() < until) {
    }
  }
};

// The status carries the program's timing (docs/realtime.md, Timing) for QMotor's program line:
// its own computation time, its executor's size, wake-up latency, overruns and the program that
// took the time in the last overrun.
TEST_F(QMotorRequestsOnObjects, StatusCarriesTheProgramsTimingAndItsExecutors) {
  Tunable t("tune");
  Hog hog("hog");
  while (t.getCycleCount() < 20 || hog.getCycleCount() < 20) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  const json timing = run(t, R"({"action":"status"})")["status"]["timing"];
  EXPECT_EQ(timing["executorPrograms"], 2) << timing.dump();
  EXPECT_EQ(timing["ownThread"], false);
  EXPECT_GE(timing["overruns"].get<int>(), 1);
  EXPECT_EQ(timing["lastOverrunProgram"], "hog");
  EXPECT_GE(timing["computationP99"].get<double>(), timing["computationP50"].get<double>());
  EXPECT_GE(timing["computationMax"].get<double>(), timing["computationP99"].get<double>());
  EXPECT_GE(timing["wakeupP99"].get<double>(), 0.0);
}

TEST_F(QMotorRequestsOnObjects, ABadFileIsRefusedWithFileAndLineAndChangesNothing) {
  Tunable t("tune");
  std::ofstream(dir_ / "bad.cfg") << "gain 9\nkp 1 2\ngian 3\n";
  EXPECT_EQ(error(t, R"({"action":"load","file":"bad.cfg"})"),
            (dir_ / "bad.cfg").string() +
                ":3: 'gian' is not a parameter of tune (known: rate, priority, logEvery, logBufferSize, log, gain, kp)");
  EXPECT_EQ(t.getParameter("gain"), std::vector<double>{2}) << "line 1 was not applied";
  std::ofstream(dir_ / "rate.cfg") << "gain 9\nrate 500\n";
  EXPECT_EQ(error(t, R"({"action":"load","file":"rate.cfg"})"),
            (dir_ / "rate.cfg").string() + ":2: 'rate' cannot change while tune runs (stop the program, then load the file again)");
  EXPECT_EQ(error(t, R"({"action":"load","file":"none.cfg"})").rfind((dir_ / "none.cfg").string() + ": ", 0), 0u);
  // Stopped, the rate may change.
  run(t, R"({"action":"stop"})");
  run(t, R"({"action":"load","file":"rate.cfg"})");
  EXPECT_EQ(t.getRate(), 500.0);
  EXPECT_EQ(t.gain, 9.0);
}

TEST_F(QMotorRequestsOnObjects, StartStopRestartAndTheirRefusals) {
  Tunable t("tune");
  EXPECT_EQ(error(t, R"({"action":"start"})"), "tune: the control program is running already");
  json r = run(t, R"({"action":"stop"})");
  EXPECT_EQ(r["message"].get<std::string>().rfind("tune: control program stopped after ", 0), 0u) << r;
  EXPECT_EQ(r["status"]["running"], false);
  EXPECT_FALSE(t.isRunning());
  EXPECT_EQ(error(t, R"({"action":"stop"})"), "tune: the control program is not running");
  r = run(t, R"({"action":"start"})");
  EXPECT_EQ(r["message"], "tune: control program started at 1000 Hz");
  EXPECT_TRUE(t.isRunning());
  r = run(t, R"({"action":"restart"})");
  EXPECT_EQ(r["message"].get<std::string>().find("; tune: control program started at 1000 Hz") != std::string::npos, true)
      << r;
  EXPECT_TRUE(t.isRunning());
  PhysicalObject plain("plain");
  EXPECT_EQ(error(plain, R"({"action":"start"})"), "plain (PhysicalObject) runs no control program");
  EXPECT_EQ(error(plain, R"({"action":"csv"})"), "plain (PhysicalObject) runs no control program");
  // A system shutdown stops every control program (in the manager's thread); Start is refused.
  ObjectManager::requestSystemShutdown("test shutdown");
  ASSERT_TRUE(ObjectManager::waitForShutdown(10));
  EXPECT_FALSE(t.isRunning());
  EXPECT_EQ(error(t, R"({"action":"start"})"), "tune: the system is shutting down (test shutdown)");
  ObjectManager::resetShutdown();
}

TEST_F(QMotorRequestsOnObjects, TheLogComesBackAsCsvWithTheChosenColumns) {
  Tunable t("tune");
  EXPECT_EQ(error(t, R"({"action":"csv"})"), "ControlProgram tune: no QMotor log is set (setLogCapture())");
  EXPECT_EQ(error(t, R"({"action":"capture","variables":["y"]})"),
            "'variables': 'y' is not a log variable of tune (known: x, q)");
  json r = run(t, R"({"action":"capture","variables":["q"],"every":10,"samples":5})");
  EXPECT_EQ(r["message"], "QMotor log set: 2 columns, every 10 cycles, 5 rows, from now");
  for (int i = 0; i < 200 && run(t, R"({"action":"status"})")["status"]["capture"]["rows"] != 5; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  json csv = run(t, R"({"action":"csv"})");
  EXPECT_EQ(csv["rows"], 5);
  EXPECT_EQ(csv["file"], "tune-qmotor-log.csv");
  const std::string text = csv["csv"];
  EXPECT_EQ(text.substr(0, text.find('\n')), "t,tune.q[0],tune.q[1]");
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 6);
}

// The Puma 560 on the simulated clock: Stop brings the arm to rest and brakes it; Start holds it
// where it came to rest (no jump), powered as before.
TEST_F(QMotorRequestsOnObjects, APumaStoppedComesToRestBrakedAndStartsAgainWhereItIs) {
  RoboticPlatform::setConfiguration(Configuration());
  RoboticPlatform::useSimulatedClock();
  Puma560 puma("arm");
  puma.setGravityCompensationOn();
  puma.enableArmPower();
  ASSERT_TRUE(puma.waitForCycles(200));
  ASSERT_TRUE(puma.isArmPowerOn());
  const JointVector before = puma.getJointPosition();
  json r = run(puma, R"({"action":"stop"})");
  const std::string message = r["message"];
  EXPECT_NE(message.find("the arm came to rest, is braked and powered off at q = ["), std::string::npos) << message;
  EXPECT_FALSE(puma.isRunning());
  EXPECT_FALSE(puma.isArmPowerOn());
  const JointVector stopped = puma.getJointPosition();
  EXPECT_LT((stopped - before).cwiseAbs().maxCoeff(), 1e-3) << "it was holding: it stops where it was";
  EXPECT_LT(puma.getJointVelocity().cwiseAbs().maxCoeff(), 1e-3) << "at rest";
  r = run(puma, R"({"action":"start"})");
  EXPECT_EQ(r["message"], "arm: control program started at 1000 Hz; the arm holds where it is (power on)");
  ASSERT_TRUE(puma.waitForCycles(500));
  EXPECT_TRUE(puma.isArmPowerOn());
  EXPECT_LT((puma.getJointPosition() - stopped).cwiseAbs().maxCoeff(), 1e-3) << "bumpless: held where it stopped";
  EXPECT_EQ(puma.getErrorCode(), 0) << puma.getErrorStatus().message;
  // Restart, then the same again.
  r = run(puma, R"({"action":"restart"})");
  EXPECT_NE(r["message"].get<std::string>().find("stopped after"), std::string::npos) << r;
  ASSERT_TRUE(puma.waitForCycles(200));
  EXPECT_TRUE(puma.isArmPowerOn());
  EXPECT_LT((puma.getJointPosition() - stopped).cwiseAbs().maxCoeff(), 1e-3);
}

}  // namespace
}  // namespace rp
