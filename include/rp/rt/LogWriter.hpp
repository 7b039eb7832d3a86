#pragma once
/// @file
/// LogWriter: writes the log samples of control programs to one CSV file from a
/// non-real-time thread.

#include <cstdint>
#include <memory>
#include <string>

namespace rp {

class ControlProgram;

/// Collects the log samples of any number of control programs and writes them to one CSV file.
///
/// Format: a header `t,program.variable,program.vector[0],...` and one row per sample time;
/// samples of different programs taken at the same clock time share a row, other cells are
/// empty. Values are written with the shortest text that reads back to the same double.
/// While running, rows go to `FILE.part`; close() (called by stop, system shutdown, SIGINT,
/// SIGTERM and normal exit) drains every ring buffer and writes the complete `FILE`.
/// No sample is lost unless a program's ring buffer overflows; losses are counted
/// (ControlStatistics::lostLogSamples, getLostSamples()) and reported on close.
class LogWriter {
 public:
  /// Opens the log and starts the writer thread.
  /// @param[in] fileName  CSV file to write
  /// @throws std::runtime_error if `FILE.part` cannot be created
  explicit LogWriter(const std::string& fileName);
  /// Closes the log (see close()).
  ~LogWriter();
  LogWriter(const LogWriter&) = delete;             ///< not copyable
  LogWriter& operator=(const LogWriter&) = delete;  ///< not copyable

  /// Drains every program, writes the complete CSV file and stops the thread; idempotent.
  /// Programs still running stop being logged. Real-time safe: no.
  void close();
  /// Whether close() has run.
  bool isClosed() const;
  /// The CSV file name.
  const std::string& fileName() const;
  /// Rows written so far.
  std::uint64_t getRowCount() const;
  /// Samples lost to ring-buffer overflow, summed over programs.
  std::uint64_t getLostSamples() const;

  /// The platform's writer (from `-log FILE`), or nullptr.
  static LogWriter* getPlatformWriter();
  /// Creates the platform's writer (RoboticPlatform::init does this for `-log`).
  /// @param[in] fileName  CSV file
  static void openPlatformWriter(const std::string& fileName);
  /// Closes the platform's writer, completing its file.
  static void closePlatformWriter();

  /// @cond INTERNAL
  struct Channel;
  void addChannel(const std::shared_ptr<Channel>& channel);
  void notify();
  /// @endcond

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rp
