// rp.cfg and control-program (qmotorConfig) file parsing; every error names FILE:LINE.
#include "rp/core/Configuration.hpp"

#include <dlfcn.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>

#include "rp/core/TypeDatabase.hpp"

namespace rp {

namespace internal {

std::string joinWords(const std::vector<std::string>& words, const char* separator) {
  std::string out;
  for (const auto& w : words) {
    if (!out.empty()) out += separator;
    out += w;
  }
  return out;
}

// Parses a whole token as a finite double ("+1", "-2.5e3"); false if it is not one.
bool parseNumber(const std::string& token, double& value) {
  const char* begin = token.data();
  const char* end = token.data() + token.size();
  if (begin != end && *begin == '+') ++begin;
  // One sign only: from_chars takes a '-' of its own, so "+-5" would be -5.
  if (begin == end || (begin != token.data() && *begin == '-')) return false;
  auto [ptr, ec] = std::from_chars(begin, end, value);
  return ec == std::errc() && ptr == end;
}

// Reads a regular file of at most ConfigLimits::kMaxFileBytes. Devices, FIFOs and sockets are
// refused before they are opened (opening a FIFO blocks, /dev/zero never ends).
std::string readTextFile(const std::string& fileName) {
  auto fail = [&](const std::string& why) { return ConfigError(fileName, 0, "cannot read the file: " + why); };
  struct stat st {};
  if (::stat(fileName.c_str(), &st) != 0) throw fail(std::strerror(errno));
  if (S_ISDIR(st.st_mode)) throw fail("it is a directory");
  if (!S_ISREG(st.st_mode)) throw fail("it is not a regular file");
  // O_NONBLOCK: should the path be replaced by a FIFO after stat(), open() does not wait.
  const int fd = ::open(fileName.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) throw fail(std::strerror(errno));
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  if (::fstat(fd, &st) != 0) throw fail(std::strerror(errno));
  if (!S_ISREG(st.st_mode)) throw fail("it is not a regular file");
  const std::size_t cap = ConfigLimits::kMaxFileBytes;
  auto tooLarge = [&] {
    return fail("it is larger than " + std::to_string(cap) + " bytes (" + std::to_string(cap >> 20) + " MiB)");
  };
  if (st.st_size > static_cast<off_t>(cap)) throw tooLarge();
  std::string text;
  char buffer[65536];
  for (;;) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw fail(std::strerror(errno));
    }
    if (n == 0) break;
    if (text.size() + static_cast<std::size_t>(n) > cap) throw tooLarge();  // grew after fstat()
    text.append(buffer, static_cast<std::size_t>(n));
  }
  return text;
}

namespace {

// One line split into words with comments removed; `line` counts from 1.
struct Line {
  int number;
  std::string trimmed;
  std::vector<std::string> words;
};

bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

std::vector<Line> splitLines(const std::string& text, const std::string& fileName) {
  std::vector<Line> lines;
  int number = 1;
  // A UTF-8 byte-order mark (as some Windows editors write) is not part of the first line.
  std::size_t start = text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;
  while (start <= text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string raw = text.substr(start, end - start);
    for (std::size_t i = 0; i < raw.size(); ++i) {
      const auto c = static_cast<unsigned char>(raw[i]);
      if ((c < 0x20 && !isSpace(static_cast<char>(c))) || c == 0x7f) {
        char buf[96];
        std::snprintf(buf, sizeof buf, "the file is not a text file (byte 0x%02x in column %zu)", c, i + 1);
        throw ConfigError(fileName, number, buf);
      }
    }
    // A comment starts at '#' at the start of the line or after white space.
    for (std::size_t i = 0; i < raw.size(); ++i) {
      if (raw[i] == '#' && (i == 0 || isSpace(raw[i - 1]))) {
        raw.resize(i);
        break;
      }
    }
    Line line{number, {}, {}};
    std::size_t b = 0, e = raw.size();
    while (b < e && isSpace(raw[b])) ++b;
    while (e > b && isSpace(raw[e - 1])) --e;
    line.trimmed = raw.substr(b, e - b);
    std::size_t i = 0;
    while (i < line.trimmed.size()) {
      while (i < line.trimmed.size() && isSpace(line.trimmed[i])) ++i;
      std::size_t j = i;
      while (j < line.trimmed.size() && !isSpace(line.trimmed[j])) ++j;
      if (j > i) line.words.push_back(line.trimmed.substr(i, j - i));
      i = j;
    }
    if (!line.words.empty()) lines.push_back(std::move(line));
    if (end == text.size()) break;
    start = end + 1;
    ++number;
  }
  return lines;
}

std::string ex(const std::string& text) { return ConfigError::excerpt(text); }

bool isIdentifier(const std::string& s, bool allowDash) {
  if (s.empty()) return false;
  if (!(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
  return std::all_of(s.begin(), s.end(), [&](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || (allowDash && c == '-');
  });
}

std::string describeCount(const SettingSpec& spec) {
  std::string n = spec.minValues == spec.maxValues
                      ? std::to_string(spec.minValues)
                      : std::to_string(spec.minValues) + " to " + std::to_string(spec.maxValues);
  std::string what = n + (spec.maxValues == 1 ? " value" : " values");
  std::string detail = spec.kind == SettingKind::Choice ? joinWords(spec.choices, ", ") : spec.description;
  if (!spec.unit.empty()) detail += (detail.empty() ? "" : " ") + std::string("[") + spec.unit + "]";
  if (!detail.empty()) what += " (" + detail + ")";
  return what;
}

// `MIN..MAX [unit]` for messages.
std::string describeRange(const SettingSpec& spec) {
  auto fmt = [](double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.15g", v);
    return std::string(buf);
  };
  return fmt(spec.minValue) + ".." + fmt(spec.maxValue) + (spec.unit.empty() ? "" : " [" + spec.unit + "]");
}

std::string resolvePath(const std::string& configFile, const std::string& path) {
  std::filesystem::path p(path);
  if (p.is_absolute()) return path;
  std::filesystem::path dir = std::filesystem::path(configFile).parent_path();
  return dir.empty() ? path : (dir / p).string();
}

}  // namespace

// Checks one setting against its declaration; throws at the setting's line.
void checkSetting(const SettingSpec& spec, const ConfigSetting& s, const std::string& file) {
  const int n = static_cast<int>(s.values.size());
  if (n < spec.minValues || n > spec.maxValues)
    throw ConfigError(file, s.line,
                      "setting '" + ex(s.name) + "' needs " + describeCount(spec) + ", got " + std::to_string(n));
  for (const auto& v : s.values) {
    switch (spec.kind) {
      case SettingKind::Number: {
        double d;
        if (!parseNumber(v, d)) {
          std::string reason = "is not a number";
          const char* b = v.data() + (!v.empty() && v[0] == '+' ? 1 : 0);
          const auto r = std::from_chars(b, v.data() + v.size(), d);
          if (r.ec == std::errc::result_out_of_range && r.ptr == v.data() + v.size())
            reason = "is out of the range of numbers";
          else if (r.ec == std::errc() && !std::isfinite(d))
            reason = "is not a finite number";
          throw ConfigError(file, s.line, "setting '" + ex(s.name) + "': '" + ex(v) + "' " + reason);
        }
        if (!std::isfinite(d)) throw ConfigError(file, s.line, "setting '" + ex(s.name) + "': '" + ex(v) + "' is not a finite number");
        if (d < spec.minValue || d > spec.maxValue)
          throw ConfigError(file, s.line, "setting '" + ex(s.name) + "': '" + ex(v) + "' is outside " + describeRange(spec));
        break;
      }
      case SettingKind::Integer: {
        long long x = 0;
        const char* b = v.data();
        if (!v.empty() && v[0] == '+') ++b;
        auto [ptr, ec] = std::from_chars(b, v.data() + v.size(), x);
        // (One sign only: "+-5" is no integer.)
        const bool whole = ptr == v.data() + v.size() && b != v.data() + v.size() && !(b != v.data() && *b == '-');
        if (ec == std::errc::result_out_of_range && whole)
          throw ConfigError(file, s.line, "setting '" + ex(s.name) + "': '" + ex(v) + "' is outside " + describeRange(spec));
        if (ec != std::errc() || !whole)
          throw ConfigError(file, s.line, "setting '" + ex(s.name) + "': '" + ex(v) + "' is not an integer");
        if (static_cast<double>(x) < spec.minValue || static_cast<double>(x) > spec.maxValue)
          throw ConfigError(file, s.line, "setting '" + ex(s.name) + "': '" + ex(v) + "' is outside " + describeRange(spec));
        break;
      }
      case SettingKind::Choice:
        if (std::find(spec.choices.begin(), spec.choices.end(), v) == spec.choices.end())
          throw ConfigError(file, s.line,
                            "setting '" + ex(s.name) + "': '" + ex(v) + "' is not one of " + joinWords(spec.choices, ", "));
        break;
      case SettingKind::Word:
        break;
    }
  }
}

}  // namespace internal

using internal::ex;

// ---- ConfigError -----------------------------------------------------------------------------

std::string ConfigError::excerpt(const std::string& text) {
  if (text.size() <= kExcerptBytes) return text;
  std::size_t n = kExcerptBytes - 3;
  // Do not cut a UTF-8 character: back up over continuation bytes (10xxxxxx).
  while (n > 0 && (static_cast<unsigned char>(text[n]) & 0xC0) == 0x80) --n;
  return text.substr(0, n) + "...";
}

ConfigError::ConfigError(const std::string& file, int line, const std::string& message)
    : std::runtime_error(file + (line > 0 ? ":" + std::to_string(line) : std::string()) + ": " + message),
      file_(file),
      line_(line),
      message_(message) {}

// ---- SettingSchema ---------------------------------------------------------------------------

void SettingSchema::add(const SettingSpec& spec) {
  for (auto& s : specs_)
    if (s.name == spec.name) {
      s = spec;
      return;
    }
  specs_.push_back(spec);
}

void SettingSchema::addNumbers(const std::string& name, int count, const std::string& unit,
                               const std::string& description) {
  SettingSpec spec;
  spec.name = name;
  spec.minValues = spec.maxValues = count;
  spec.unit = unit;
  spec.description = description;
  add(spec);
}

void SettingSchema::addNumbers(const std::string& name, int count, const std::string& unit,
                               const std::string& description, double minValue, double maxValue) {
  SettingSpec spec;
  spec.name = name;
  spec.minValues = spec.maxValues = count;
  spec.unit = unit;
  spec.description = description;
  spec.minValue = minValue;
  spec.maxValue = maxValue;
  add(spec);
}

void SettingSchema::addInteger(const std::string& name, const std::string& description) {
  addInteger(name, description, INT_MIN, INT_MAX);
}

void SettingSchema::addInteger(const std::string& name, const std::string& description, long long minValue,
                               long long maxValue) {
  SettingSpec spec;
  spec.name = name;
  spec.kind = SettingKind::Integer;
  spec.description = description;
  spec.minValue = static_cast<double>(minValue);
  spec.maxValue = static_cast<double>(maxValue);
  add(spec);
}

void SettingSchema::addWord(const std::string& name, const std::string& description) { addWords(name, 1, 1, description); }

void SettingSchema::addWords(const std::string& name, int minCount, int maxCount, const std::string& description,
                             const std::string& unit) {
  SettingSpec spec;
  spec.name = name;
  spec.kind = SettingKind::Word;
  spec.minValues = minCount;
  spec.maxValues = maxCount;
  spec.unit = unit;
  spec.description = description;
  add(spec);
}

void SettingSchema::addChoice(const std::string& name, const std::vector<std::string>& choices,
                              const std::string& description) {
  SettingSpec spec;
  spec.name = name;
  spec.kind = SettingKind::Choice;
  spec.choices = choices;
  spec.description = description;
  add(spec);
}

void SettingSchema::setDefault(const std::string& name, const std::string& value) {
  for (auto& s : specs_)
    if (s.name == name) {
      s.defaultValue = value;
      return;
    }
  throw std::logic_error("SettingSchema::setDefault: setting '" + name + "' is not declared");
}

const SettingSpec* SettingSchema::find(const std::string& name) const {
  for (const auto& s : specs_)
    if (s.name == name) return &s;
  return nullptr;
}

std::string SettingSchema::knownNames() const {
  std::vector<std::string> names{"cpu", "qmotorConfig", "thread"};
  for (const auto& s : specs_) names.push_back(s.name);
  std::sort(names.begin(), names.end());
  names.erase(std::unique(names.begin(), names.end()), names.end());
  return internal::joinWords(names, ", ");
}

// ---- ParameterFile ---------------------------------------------------------------------------

ParameterFile ParameterFile::read(const std::string& fileName) {
  return parse(internal::readTextFile(fileName), fileName);
}

ParameterFile ParameterFile::parse(const std::string& text, const std::string& fileName) {
  ParameterFile file;
  file.fileName_ = fileName;
  std::map<std::string, int> seen;
  for (auto& line : internal::splitLines(text, fileName)) {
    if (line.trimmed[0] == '[')
      throw ConfigError(fileName, line.number, "sections ('[...]') are not allowed in a control-program file");
    const std::string& name = line.words[0];
    if (!internal::isIdentifier(name, false))
      throw ConfigError(fileName, line.number, "'" + ex(name) + "' is not a valid parameter name");
    if (line.words.size() < 2) throw ConfigError(fileName, line.number, "'" + ex(name) + "' has no value");
    if (auto it = seen.find(name); it != seen.end())
      throw ConfigError(fileName, line.number,
                        "'" + ex(name) + "' is given twice (first at line " + std::to_string(it->second) + ")");
    seen[name] = line.number;
    ConfigSetting entry{name, {line.words.begin() + 1, line.words.end()}, line.number};
    if (name != "log") {
      for (const auto& v : entry.values) {
        double d;
        if (!internal::parseNumber(v, d) || !std::isfinite(d))
          throw ConfigError(fileName, line.number, "'" + ex(name) + "': '" + ex(v) + "' is not a number");
      }
    }
    file.entries_.push_back(std::move(entry));
  }
  return file;
}

ConfigError ParameterFile::errorAt(const ConfigSetting& entry, const std::string& message) const {
  return ConfigError(fileName_, entry.line, message);
}

// ---- ConfigSection ---------------------------------------------------------------------------

const ConfigSetting* ConfigSection::find(const std::string& name) const {
  for (const auto& s : settings_)
    if (s.name == name) return &s;
  return nullptr;
}

std::vector<double> ConfigSection::getNumbers(const std::string& name) const {
  const ConfigSetting* s = find(name);
  if (!s) throw ConfigError(fileName_, line_, "section [" + ex(name_) + "] has no setting '" + ex(name) + "'");
  std::vector<double> out;
  for (const auto& v : s->values) {
    double d;
    if (!internal::parseNumber(v, d) || !std::isfinite(d))
      throw errorAt(*s, "setting '" + ex(name) + "': '" + ex(v) + "' is not a number");
    out.push_back(d);
  }
  return out;
}

std::string ConfigSection::getWord(const std::string& name) const {
  const ConfigSetting* s = find(name);
  if (!s) throw ConfigError(fileName_, line_, "section [" + ex(name_) + "] has no setting '" + ex(name) + "'");
  if (s->values.empty()) throw errorAt(*s, "setting '" + ex(name) + "' has no value");
  return s->values[0];
}

ConfigError ConfigSection::errorAt(const ConfigSetting& setting, const std::string& message) const {
  return ConfigError(fileName_, setting.line, message);
}

// ---- Configuration ---------------------------------------------------------------------------

Configuration Configuration::read(const std::string& fileName, const Options& options) {
  return parse(internal::readTextFile(fileName), fileName, options);
}

namespace {
// The paper's vector form (Table 1: `position <x,y,z>`): `<300, 0, 0>` gives the values 300, 0, 0.
std::vector<std::string> angleBracketValues(const std::string& text, const std::string& name, const std::string& fileName,
                                            int line) {
  const std::size_t open = text.find('<');
  const std::size_t close = text.rfind('>');
  if (close == std::string::npos || close < open)
    throw ConfigError(fileName, line, "setting '" + ex(name) + "': '<' without a closing '>'");
  if (text.find_first_not_of(" \t\r\f\v", close + 1) != std::string::npos)
    throw ConfigError(fileName, line, "setting '" + ex(name) + "': unexpected text after '>'");
  std::vector<std::string> values;
  std::size_t start = open + 1;
  while (true) {
    const std::size_t comma = std::min(text.find(',', start), close);
    std::string value = text.substr(start, comma - start);
    const std::size_t b = value.find_first_not_of(" \t\r\f\v");
    const std::size_t e = value.find_last_not_of(" \t\r\f\v");
    value = b == std::string::npos ? std::string() : value.substr(b, e - b + 1);
    if (value.empty() || value.find_first_of(" \t<>") != std::string::npos)
      throw ConfigError(fileName, line, "setting '" + ex(name) + "': '" + ex(text.substr(open, close - open + 1)) +
                                            "' is not a list of values like <x,y,z>");
    values.push_back(value);
    if (comma == close) break;
    start = comma + 1;
  }
  return values;
}
}  // namespace

Configuration Configuration::parse(const std::string& text, const std::string& fileName, const Options& options) {
  Configuration cfg;
  cfg.fileName_ = fileName;
  ConfigSection* current = nullptr;
  std::map<std::string, int> sectionLines;
  std::map<std::string, int> settingLines;  // of the current section

  auto finishSection = [&] {
    if (current && current->className_.empty())
      throw ConfigError(fileName, current->line_, "section [" + ex(current->name_) + "] has no 'class' setting");
  };

  for (auto& line : internal::splitLines(text, fileName)) {
    if (line.trimmed[0] == '[') {
      std::size_t close = line.trimmed.find(']');
      if (close == std::string::npos)
        throw ConfigError(fileName, line.number, "section header '" + ex(line.trimmed) + "' is missing ']'");
      std::string rest = line.trimmed.substr(close + 1);
      rest.erase(0, rest.find_first_not_of(" \t\r\f\v") == std::string::npos ? rest.size()
                                                                            : rest.find_first_not_of(" \t\r\f\v"));
      std::string name = line.trimmed.substr(1, close - 1);
      auto notSpace = [](char c) { return !internal::isSpace(c); };
      name.erase(name.begin(), std::find_if(name.begin(), name.end(), notSpace));
      name.erase(std::find_if(name.rbegin(), name.rend(), notSpace).base(), name.end());
      if (!rest.empty())
        throw ConfigError(fileName, line.number, "unexpected text '" + ex(rest) + "' after section header [" + ex(name) + "]");
      if (name.empty()) throw ConfigError(fileName, line.number, "empty section name '[]'");
      if (!internal::isIdentifier(name, true))
        throw ConfigError(fileName, line.number,
                          "section name '" + ex(name) +
                              "' must start with a letter or '_' and contain only letters, digits, '_' and '-'");
      finishSection();
      if (auto it = sectionLines.find(name); it != sectionLines.end())
        throw ConfigError(fileName, line.number,
                          "duplicate section [" + ex(name) + "] (first at line " + std::to_string(it->second) + ")");
      if (cfg.sections_.size() >= ConfigLimits::kMaxSections)
        throw ConfigError(fileName, line.number,
                          "too many sections: a file may configure at most " +
                              std::to_string(ConfigLimits::kMaxSections) + " objects");
      sectionLines[name] = line.number;
      settingLines.clear();
      cfg.sections_.emplace_back();
      current = &cfg.sections_.back();
      current->name_ = name;
      current->fileName_ = fileName;
      current->line_ = line.number;
      continue;
    }
    const std::string& name = line.words[0];
    ConfigSetting setting{name, {line.words.begin() + 1, line.words.end()}, line.number};
    if (!setting.values.empty() && setting.values.front().front() == '<')
      setting.values = angleBracketValues(line.trimmed.substr(name.size()), name, fileName, line.number);
    if (!current) {
      if (name == "plugin") {
        if (setting.values.size() != 1)
          throw ConfigError(fileName, line.number,
                            "setting 'plugin' needs 1 value (a shared library path), got " +
                                std::to_string(setting.values.size()));
        if (setting.values[0].size() > ConfigLimits::kMaxPathBytes)
          throw ConfigError(fileName, line.number,
                            "setting 'plugin': the path is longer than " +
                                std::to_string(ConfigLimits::kMaxPathBytes) + " bytes");
        if (cfg.plugins_.size() >= ConfigLimits::kMaxPlugins)
          throw ConfigError(fileName, line.number,
                            "too many 'plugin' lines (at most " + std::to_string(ConfigLimits::kMaxPlugins) + ")");
        setting.values[0] = internal::resolvePath(fileName, setting.values[0]);
        cfg.plugins_.push_back(std::move(setting));
        continue;
      }
      throw ConfigError(fileName, line.number,
                        "setting '" + ex(name) + "' is outside a section (start one with a [name] line)");
    }
    if (!internal::isIdentifier(name, false))
      throw ConfigError(fileName, line.number, "'" + ex(name) + "' is not a valid setting name");
    if (auto it = settingLines.find(name); it != settingLines.end())
      throw ConfigError(fileName, line.number,
                        "setting '" + ex(name) + "' is given twice in [" + ex(current->name_) + "] (first at line " +
                            std::to_string(it->second) + ")");
    settingLines[name] = line.number;
    if (name == "class") {
      if (setting.values.size() != 1)
        throw ConfigError(fileName, line.number,
                          "setting 'class' needs 1 value (a class name), got " + std::to_string(setting.values.size()));
      current->className_ = setting.values[0];
      current->classLine_ = line.number;
      continue;
    }
    if (name == "thread") {
      // The control program's executor (docs/realtime.md, Executors): shared or its own thread.
      if (setting.values.size() != 1 || (setting.values[0] != "own" && setting.values[0] != "shared"))
        throw ConfigError(fileName, line.number,
                          "setting 'thread' needs 1 value (own, shared), got " +
                              (setting.values.size() == 1 ? "'" + ex(setting.values[0]) + "'"
                                                          : std::to_string(setting.values.size()) + " values"));
    }
    if (name == "cpu") {
      // The CPU the control program's thread is pinned to.
      double v = 0;
      if (setting.values.size() != 1 || !internal::parseNumber(setting.values[0], v) || v != std::floor(v) || v < 0 ||
          v > 1023)
        throw ConfigError(fileName, line.number,
                          "setting 'cpu' needs 1 value, a CPU number in 0..1023, got " +
                              (setting.values.size() == 1 ? "'" + ex(setting.values[0]) + "'"
                                                          : std::to_string(setting.values.size()) + " values"));
    }
    if (name == "qmotorConfig") {
      if (setting.values.size() != 1)
        throw ConfigError(fileName, line.number,
                          "setting 'qmotorConfig' needs 1 value (a file name), got " +
                              std::to_string(setting.values.size()));
      if (setting.values[0].size() > ConfigLimits::kMaxPathBytes)
        throw ConfigError(fileName, line.number,
                          "setting 'qmotorConfig': the path is longer than " +
                              std::to_string(ConfigLimits::kMaxPathBytes) + " bytes");
      if (options.readQMotorFiles) {
        const std::string path = internal::resolvePath(fileName, setting.values[0]);
        std::string text;
        try {
          text = internal::readTextFile(path);
        } catch (const ConfigError& e) {
          throw ConfigError(fileName, line.number,
                            "qmotorConfig file '" + ex(setting.values[0]) + "' " +
                                (e.message().rfind("cannot read the file: ", 0) == 0
                                     ? "cannot be read: " + e.message().substr(22)
                                     : e.message()));
        }
        current->qmotor_ = std::make_shared<const ParameterFile>(ParameterFile::parse(text, path));
      }
    }
    current->settings_.push_back(std::move(setting));
  }
  finishSection();

  if (options.loadPlugins) {
    for (const auto& p : cfg.plugins_) {
      if (!dlopen(p.values[0].c_str(), RTLD_NOW | RTLD_GLOBAL)) {
        const char* err = dlerror();
        // dlerror() repeats the path: quote only an excerpt of it there too.
        std::string why = err ? err : "unknown error";
        if (why.rfind(p.values[0], 0) == 0) why = ex(p.values[0]) + why.substr(p.values[0].size());
        throw ConfigError(fileName, p.line, "plugin '" + ex(p.values[0]) + "' cannot be loaded: " + why);
      }
    }
  }
  if (options.checkClasses) {
    const TypeDatabase& db = TypeDatabase::instance();
    for (const auto& section : cfg.sections_) {
      const TypeInfo* type = db.find(section.className_);
      if (!type)
        throw ConfigError(fileName, section.classLine_,
                          "class '" + ex(section.className_) + "' is not known (known: " + db.knownNames() + ")");
      if (section.name_ != section.className_ && db.contains(section.name_))
        throw ConfigError(fileName, section.classLine_,
                          "section [" + section.name_ + "] is named after a class: it configures the " + section.name_ +
                              " objects without a section of their own, so its class must be " + section.name_ +
                              ", not " + ex(section.className_));
      for (const auto& s : section.settings_) {
        if (s.name == "qmotorConfig" || s.name == "thread" || s.name == "cpu") continue;
        const SettingSpec* spec = type->schema.find(s.name);
        if (!spec)
          throw ConfigError(fileName, s.line,
                            "setting '" + ex(s.name) + "' is not known for class " + section.className_ +
                                " (known: " + type->schema.knownNames() + ")");
        internal::checkSetting(*spec, s, fileName);
      }
    }
  }
  return cfg;
}

const ConfigSection* Configuration::findSection(const std::string& name) const {
  for (const auto& s : sections_)
    if (s.name() == name) return &s;
  return nullptr;
}

const ConfigSection* Configuration::findClassSection(const std::string& className) const {
  const ConfigSection* section = findSection(className);
  return section != nullptr && section->isClassSection() ? section : nullptr;
}

std::string Configuration::sectionNames() const {
  std::vector<std::string> names;
  for (const auto& s : sections_) names.push_back(s.name());
  return names.empty() ? std::string("none") : internal::joinWords(names, ", ");
}

}  // namespace rp
