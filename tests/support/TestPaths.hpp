#pragma once
// Where a test finds the build's programs and the source tree's data at run time: the build tree
// is the folder above the test program that holds CMakeCache.txt, the source tree that cache's
// CMAKE_HOME_DIRECTORY. The macros rp_test_program() and rp_test_source() define (tests/
// CMakeLists.txt) call these, so no absolute path is compiled into a test: ccache then reuses the
// objects of another checkout of the same sources, as CI's fresh clone is.
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <string_view>

namespace rp::test {
namespace detail {

inline const std::filesystem::path& buildDirectory() {
  static const std::filesystem::path dir = [] {
    const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe");
    for (std::filesystem::path p = exe.parent_path(); !p.empty(); p = p.parent_path()) {
      if (std::filesystem::exists(p / "CMakeCache.txt")) return p;
      if (p == p.root_path()) break;
    }
    throw std::runtime_error("tests: no CMakeCache.txt in a folder above " + exe.string() + " (not in a build tree?)");
  }();
  return dir;
}

inline const std::filesystem::path& sourceDirectory() {
  static const std::filesystem::path dir = [] {
    const std::filesystem::path cache = buildDirectory() / "CMakeCache.txt";
    std::ifstream in(cache);
    const std::string key = "CMAKE_HOME_DIRECTORY:INTERNAL=";
    for (std::string line; std::getline(in, line);)
      if (line.compare(0, key.size(), key) == 0) return std::filesystem::path(line.substr(key.size()));
    throw std::runtime_error("tests: " + cache.string() + " names no CMAKE_HOME_DIRECTORY");
  }();
  return dir;
}

}  // namespace detail

/// The absolute path of `relative` in the build tree (a program: "bin/rp-hwserver").
inline std::string buildPath(std::string_view relative) { return (detail::buildDirectory() / relative).string(); }

/// The absolute path of `relative` in the source tree (test data: "tests/model/data").
inline std::string sourcePath(std::string_view relative) { return (detail::sourceDirectory() / relative).string(); }

}  // namespace rp::test
