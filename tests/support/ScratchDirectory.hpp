#pragma once
// A test's own directory in the temporary folder (TMPDIR, which CTest sets to an empty folder of
// the build tree; tests/CMakeLists.txt checks that nothing is left in it), removed with everything
// in it when the object goes out of scope: at the end of the test, also when an assertion fails
// (ASSERT_* returns from the test body) or an exception leaves it.
#include <unistd.h>

#include <filesystem>
#include <string>
#include <system_error>
#include <utility>

namespace rp::test {

class ScratchDirectory {
 public:
  /// Creates (empty) `$TMPDIR/<prefix><name>_<pid>`, or without `_<pid>` when `perProcess` is
  /// false: for a death test, whose child (run again from the start of the test in gtest's
  /// "threadsafe" style) then makes the same folder and exits without removing it, leaving that
  /// to the parent's object.
  ScratchDirectory(const std::string& prefix, const std::string& name, bool perProcess = true) {
    std::string leaf = prefix;
    leaf += name;
    if (perProcess) {
      leaf += '_';
      leaf += std::to_string(::getpid());
    }
    path_ = std::filesystem::temp_directory_path() / leaf;
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~ScratchDirectory() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  ScratchDirectory(const ScratchDirectory&) = delete;
  ScratchDirectory& operator=(const ScratchDirectory&) = delete;

  const std::filesystem::path& path() const { return path_; }
  operator const std::filesystem::path&() const { return path_; }  // NOLINT: used as the path it is
  std::string string() const { return path_.string(); }
  const char* c_str() const { return path_.c_str(); }
  template <typename T>
  std::filesystem::path operator/(T&& part) const {
    return path_ / std::forward<T>(part);
  }

 private:
  std::filesystem::path path_;
};

}  // namespace rp::test

namespace rp::test {

/// A file `$TMPDIR/<name>` a test writes, removed when the object goes out of scope (also when an
/// assertion fails). Converts to its path as a std::string.
class ScratchFile {
 public:
  explicit ScratchFile(const std::string& name) : path_((std::filesystem::temp_directory_path() / name).string()) {}
  ~ScratchFile() {
    std::error_code ignored;
    std::filesystem::remove(path_, ignored);
  }
  ScratchFile(const ScratchFile&) = delete;
  ScratchFile& operator=(const ScratchFile&) = delete;

  const std::string& path() const { return path_; }
  operator const std::string&() const { return path_; }  // NOLINT: used as the path it is

 private:
  std::string path_;
};

}  // namespace rp::test
