// The settings reference of rp-objects --settings (see SettingsReference.hpp).
#include "SettingsReference.hpp"

#include <climits>
#include <cstdio>
#include <limits>
#include <vector>

#include "rp/core/TypeDatabase.hpp"

namespace rp::apps {

namespace {

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.15g", v);
  return buf;
}

std::string plural(int n, const std::string& word) { return n == 1 ? word : word + "s"; }

// "number", "3 numbers", "1 to 64 words", "integer", "choice".
std::string typeOf(const SettingSpec& s) {
  std::string word;
  switch (s.kind) {
    case SettingKind::Number: word = "number"; break;
    case SettingKind::Integer: word = "integer"; break;
    case SettingKind::Word: word = "word"; break;
    case SettingKind::Choice: word = "choice"; break;
  }
  if (s.minValues == s.maxValues) return s.minValues == 1 ? word : std::to_string(s.minValues) + " " + plural(2, word);
  return std::to_string(s.minValues) + " to " + std::to_string(s.maxValues) + " " + plural(2, word);
}

// The values allowed: a range for numbers ("any" when unbounded), the words for a choice.
std::string rangeOf(const SettingSpec& s) {
  if (s.kind == SettingKind::Choice) {
    std::string r;
    for (const auto& c : s.choices) r += (r.empty() ? "" : ", ") + ("`" + c + "`");
    return r;
  }
  if (s.kind == SettingKind::Word) return "";
  const bool noMin = s.minValue <= std::numeric_limits<double>::lowest() ||
                     (s.kind == SettingKind::Integer && s.minValue <= INT_MIN);
  const bool noMax = s.maxValue >= std::numeric_limits<double>::max() ||
                     (s.kind == SettingKind::Integer && s.maxValue >= INT_MAX);
  if (noMin && noMax) return "any";
  if (noMax) return ">= " + number(s.minValue);
  if (noMin) return "<= " + number(s.maxValue);
  return number(s.minValue) + " .. " + number(s.maxValue);
}

// A table cell: '|' would end the cell.
std::string cell(const std::string& text) {
  std::string out;
  for (char c : text) out += c == '|' ? std::string("\\|") : std::string(1, c);
  return out;
}

void printClass(std::ostream& out, const TypeInfo& type) {
  out << "### " << type.name << "\n\n";
  const auto& settings = type.schema.settings();
  if (settings.empty()) {
    out << "No settings besides `class` and `qmotorConfig`.\n\n";
    return;
  }
  out << "| setting | type | unit | range | default | meaning |\n";
  out << "|---|---|---|---|---|---|\n";
  for (const SettingSpec& s : settings)
    out << "| `" << s.name << "` | " << typeOf(s) << " | " << cell(s.unit) << " | " << rangeOf(s) << " | "
        << cell(s.defaultValue) << " | " << cell(s.description) << " |\n";
  out << "\n";
}

}  // namespace

bool printSettingsReference(std::ostream& out, const std::string& className) {
  const TypeDatabase& db = TypeDatabase::instance();
  if (!className.empty()) {
    const TypeInfo* type = db.find(className);
    if (type == nullptr) return false;
    printClass(out, *type);
    return true;
  }
  for (const std::string& name : db.classNames()) printClass(out, *db.find(name));
  return true;
}

}  // namespace rp::apps
