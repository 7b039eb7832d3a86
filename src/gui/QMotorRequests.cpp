// QMotor's requests from the page: checked on the server thread, run in the worker thread.
#include "QMotorRequests.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <system_error>
#include <vector>

#include "rp/core/Configuration.hpp"
#include "rp/core/RoboticObject.hpp"
#include "rp/core/RoboticPlatform.hpp"

namespace rp::internal {

namespace {

using nlohmann::json;

const char* const kActions[] = {"status", "start", "stop", "restart", "save", "load", "capture", "clearCapture", "csv"};

std::string fieldString(const json& msg, const char* key, std::size_t maxSize) {
  auto it = msg.find(key);
  if (it == msg.end() || !it->is_string())
    throw std::invalid_argument(std::string("'") + key + "' must be a string");
  std::string s = it->get<std::string>();
  if (s.empty() || s.size() > maxSize)
    throw std::invalid_argument(std::string("'") + key + "' must have 1 to " + std::to_string(maxSize) + " characters");
  return s;
}

// An integer field in [low, high]; `fallback` when absent.
long long fieldInteger(const json& msg, const char* key, long long low, long long high, long long fallback) {
  auto it = msg.find(key);
  if (it == msg.end()) return fallback;
  // A JSON number such as 1e30 or 2.5 is not an integer; a huge integer is out of range.
  if (!it->is_number_integer() || (it->is_number_unsigned() && it->get<unsigned long long>() > 1ULL << 62) ||
      it->get<long long>() < low || it->get<long long>() > high)
    throw std::invalid_argument(std::string("'") + key + "' must be an integer in " + std::to_string(low) + ".." +
                                std::to_string(high));
  return it->get<long long>();
}

json statusOf(RoboticObject& object) {
  json s = {{"object", object.getName()}, {"className", object.getClassName()}};
  ControlProgram* p = object.getControlProgram();
  s["hasProgram"] = p != nullptr;
  s["configFile"] = object.getQMotorConfigFile();
  const std::string folder = object.getQMotorConfigFolder();
  s["folder"] = folder;
  json files = json::array();
  if (!folder.empty()) {
    std::error_code ec;
    std::vector<std::string> names;
    for (std::filesystem::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
      const std::string name = it->path().filename().string();
      if (name.size() > 4 && name.compare(name.size() - 4, 4, ".cfg") == 0 && it->is_regular_file(ec) &&
          !it->is_symlink(ec))
        names.push_back(name);
      if (names.size() >= kMaxQMotorFilesListed) break;
    }
    std::sort(names.begin(), names.end());
    files = names;
  }
  s["files"] = files;
  if (p == nullptr) return s;
  s["program"] = p->getProgramName();
  s["running"] = p->isRunning();
  s["cycles"] = p->getCycleCount();
  s["rate"] = p->getRate();
  s["time"] = p->getTime();
  // Timing (docs/realtime.md, Executors): the program's own computation time per cycle, and the
  // wake-up latency and overruns of the executor that steps it.
  const ControlStatistics t = p->getStatistics();
  json timing = {{"computationP50", t.computationTime.p50}, {"computationP99", t.computationTime.p99},
                 {"computationMax", t.computationTime.max}, {"wakeupP99", t.wakeupLatency.p99},
                 {"overruns", t.overruns},                  {"ownThread", t.ownThread},
                 {"executorPrograms", t.executorPrograms},  {"lastOverrunProgram", ""}};
  for (const ExecutorStatistics& e : ControlProgram::getExecutorStatistics())
    if (std::find(e.programs.begin(), e.programs.end(), p->getProgramName()) != e.programs.end()) {
      timing["executorPrograms"] = e.programs.size();
      timing["lastOverrunProgram"] = e.lastOverrunProgram;
    }
  s["timing"] = timing;
  json variables = json::array();
  for (const LogVariableInfo& v : p->getLogVariables())
    variables.push_back({{"name", v.name}, {"size", v.size}, {"vector", v.vector}, {"unit", v.unit}});
  s["variables"] = variables;
  const LogCaptureStatus c = p->getLogCaptureStatus();
  s["capture"] = {{"armed", c.armed},     {"triggered", c.triggered}, {"triggerTime", c.triggerTime},
                  {"rows", c.rows},       {"capacity", c.capacity},   {"every", c.every},
                  {"columns", c.columns}, {"trigger", c.triggerColumn.empty()
                                                          ? json(nullptr)
                                                          : json{{"column", c.triggerColumn},
                                                                 {"level", c.triggerLevel},
                                                                 {"edge", c.triggerRising ? "rising" : "falling"}}}};
  return s;
}

ControlProgram& programOf(RoboticObject& object) {
  ControlProgram* p = object.getControlProgram();
  if (p == nullptr) throw std::invalid_argument(object.getName() + " (" + object.getClassName() + ") runs no control program");
  return *p;
}

std::string reply(RoboticObject& object, const std::string& message) {
  return json{{"message", message}, {"status", statusOf(object)}}.dump();
}

std::string folderOf(RoboticObject& object) {
  const std::string folder = object.getQMotorConfigFolder();
  if (folder.empty())
    throw std::invalid_argument("'file': " + object.getName() +
                                " has no rp.cfg section, so no control-program folder (give it one with qmotorConfig)");
  return folder;
}

}  // namespace

std::filesystem::path qmotorFileIn(const std::string& folder, const std::string& name) {
  namespace fs = std::filesystem;
  const bool shape = !name.empty() && name.size() <= kMaxQMotorFileName && name[0] != '.' && name.size() > 4 &&
                     name.compare(name.size() - 4, 4, ".cfg") == 0 &&
                     std::all_of(name.begin(), name.end(), [](char c) {
                       return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
                              c == '_' || c == '-';
                     });
  if (!shape)
    throw std::invalid_argument("'file' must be a file name ending in .cfg (letters, digits, . _ -, at most " +
                                std::to_string(kMaxQMotorFileName) + " characters, not starting with .), not a path");
  const fs::path path = fs::path(folder) / name;
  std::error_code ec;
  const fs::file_status st = fs::symlink_status(path, ec);
  if (!ec && fs::exists(st) && !fs::is_regular_file(st))
    throw std::invalid_argument("'file': " + path.string() + " is not a regular file");
  return path;
}

QMotorRequest parseQMotorRequest(const json& msg) {
  QMotorRequest r;
  r.action = fieldString(msg, "action", 32);
  if (std::find(std::begin(kActions), std::end(kActions), r.action) == std::end(kActions))
    throw std::invalid_argument("'action' must be one of status, start, stop, restart, save, load, capture, "
                                "clearCapture, csv (got '" + r.action.substr(0, 32) + "')");
  if (r.action == "load" || (r.action == "save" && msg.contains("file")))
    r.file = fieldString(msg, "file", kMaxQMotorFileName);
  if (r.action != "capture") return r;
  LogCaptureSettings& c = r.capture;
  if (auto v = msg.find("variables"); v != msg.end()) {
    if (!v->is_array() || v->size() > kMaxQMotorLogVariables)
      throw std::invalid_argument("'variables' must be an array of at most " + std::to_string(kMaxQMotorLogVariables) +
                                  " names");
    for (const json& name : *v) {
      if (!name.is_string() || name.get<std::string>().empty() || name.get<std::string>().size() > 256)
        throw std::invalid_argument("'variables' must hold names of 1 to 256 characters");
      c.variables.push_back(name.get<std::string>());
    }
  }
  c.every = static_cast<unsigned>(fieldInteger(msg, "every", 1, ControlProgram::kMaxLogEvery, 1));
  c.samples = static_cast<std::size_t>(
      fieldInteger(msg, "samples", 1, static_cast<long long>(ControlProgram::kMaxLogCaptureValues / 2), 10000));
  if (auto t = msg.find("trigger"); t != msg.end() && !t->is_null()) {
    if (!t->is_object()) throw std::invalid_argument("'trigger' must be an object {column, level, edge} or null");
    c.triggerColumn = fieldString(*t, "column", 256);
    auto level = t->find("level");
    if (level == t->end() || !level->is_number() || !std::isfinite(level->get<double>()))
      throw std::invalid_argument("'trigger.level' must be a finite number");
    c.triggerLevel = level->get<double>();
    const std::string edge = fieldString(*t, "edge", 16);
    if (edge != "rising" && edge != "falling") throw std::invalid_argument("'trigger.edge' must be rising or falling");
    c.triggerRising = edge == "rising";
  }
  return r;
}

std::string runQMotorRequest(RoboticObject& object, const QMotorRequest& request) {
  const std::string& a = request.action;
  if (a == "status") return reply(object, "");
  if (a == "start") return reply(object, object.startControlProgram());
  if (a == "stop") return reply(object, object.stopControlProgram());
  if (a == "restart") return reply(object, object.restartControlProgram());
  ControlProgram& p = programOf(object);
  if (a == "save") {
    std::filesystem::path path;
    if (request.file.empty()) {
      path = object.getQMotorConfigFile();
      if (path.empty())
        throw std::invalid_argument("'file': " + object.getName() +
                                    " has no qmotorConfig file in rp.cfg; give a file name to save to");
    } else {
      path = qmotorFileIn(folderOf(object), request.file);
    }
    // Never over the configuration file itself (rp.cfg may be in the same folder).
    std::error_code ec;
    const ConfigSection* section = object.configSection();
    for (const std::string& cfg : {section ? section->fileName() : std::string(), RoboticPlatform::getConfigurationFileName()})
      if (!cfg.empty() && std::filesystem::equivalent(path, cfg, ec) && !ec)
        throw std::invalid_argument("'file': " + path.string() + " is the configuration file, not a control-program file");
    p.saveQMotorConfig(path.string());
    return reply(object, "saved the parameters of " + p.getProgramName() + " to " + path.string());
  }
  if (a == "load") {
    const std::filesystem::path path = qmotorFileIn(folderOf(object), request.file);
    p.applyQMotorConfig(ParameterFile::read(path.string()));  // a ConfigError names FILE:LINE
    return reply(object, "loaded " + path.string() + " into " + p.getProgramName());
  }
  if (a == "capture") {
    p.setLogCapture(request.capture);
    const LogCaptureStatus s = p.getLogCaptureStatus();
    return reply(object, "QMotor log set: " + std::to_string(s.columns.size()) + " columns, every " +
                             std::to_string(s.every) + " cycles, " + std::to_string(s.capacity) + " rows" +
                             (s.triggerColumn.empty() ? ", from now" : ", from the trigger"));
  }
  if (a == "clearCapture") {
    p.clearLogCapture();
    return reply(object, "QMotor log removed");
  }
  // csv
  const LogCaptureStatus s = p.getLogCaptureStatus();
  return json{{"csv", p.getLogCaptureCsv()}, {"rows", s.rows}, {"file", p.getProgramName() + "-qmotor-log.csv"}}.dump();
}

}  // namespace rp::internal
