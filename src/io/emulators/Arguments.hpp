#pragma once
// Command-line helpers shared by rp-emulate, rp-hwserver and rp-device: numbers and lists that
// say which option was wrong.
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace rp::emulator {

// A bad command line (the programs print it with their usage and exit with status 2).
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A finite number (nan and inf are no durations, rates or forces).
inline double toDouble(const std::string& option, const std::string& text) {
  try {
    std::size_t used = 0;
    const double v = std::stod(text, &used);
    if (used == text.size() && std::isfinite(v)) return v;
  } catch (const std::exception&) {
  }
  throw UsageError(option + ": '" + text + "' is not a finite number");
}

inline int toInt(const std::string& option, const std::string& text) {
  try {
    std::size_t used = 0;
    const int v = std::stoi(text, &used);
    if (used == text.size()) return v;
  } catch (const std::exception&) {
  }
  throw UsageError(option + ": '" + text + "' is not an integer");
}

// "0,1,2" -> {0, 1, 2}
inline std::vector<int> toIntList(const std::string& option, const std::string& text) {
  std::vector<int> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) out.push_back(toInt(option, item));
  return out;
}

}  // namespace rp::emulator
