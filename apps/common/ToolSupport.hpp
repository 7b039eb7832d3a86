// What the command-line tools that print JSON share (rp-model, rp-plan and the Python tests'
// C++ reference): the usage error, comma-separated numbers, matrices and vectors as JSON, and a
// main() that reports an error as "TOOL: what" with exit status 2.
#pragma once

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "rp/model/ManipulatorModel.hpp"

namespace rp::tool {

/// A bad command-line argument (exit status 2, as every other error of these tools).
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// The finite numbers of a comma-separated list given to `option`.
/// @throws UsageError naming the option and the item that is not a finite number
inline std::vector<double> numbers(const std::string& option, const std::string& text) {
  std::vector<double> v;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    char* end = nullptr;
    const double x = std::strtod(item.c_str(), &end);
    if (item.empty() || end == item.c_str() || *end != '\0') throw UsageError(option + ": '" + item + "' is not a number");
    if (!std::isfinite(x)) throw UsageError(option + ": '" + item + "' is not a finite number");
    v.push_back(x);
  }
  return v;
}

/// A matrix as a JSON array of rows.
template <typename M>
nlohmann::json matrixJson(const M& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    nlohmann::json row = nlohmann::json::array();
    for (Eigen::Index c = 0; c < m.cols(); ++c) row.push_back(m(r, c));
    rows.push_back(row);
  }
  return rows;
}

/// A joint vector as a JSON array.
inline nlohmann::json vectorJson(const JointVector& v) {
  nlohmann::json a = nlohmann::json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(v(i));
  return a;
}

/// Runs a tool's `run(argc, argv)`; an exception is printed as "TOOL: what" on stderr, exit 2.
template <typename Run>
int runTool(const char* tool, Run run, int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << tool << ": " << e.what() << std::endl;
    return 2;
  }
}

}  // namespace rp::tool
