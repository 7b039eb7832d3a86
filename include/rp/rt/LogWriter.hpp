#pragma once
/// @file
/// LogWriter: writes the log samples of control programs to one CSV file from a
/// non-real-time thread.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace rp {

class ControlProgram;

/// Recent samples of one log column (see LogWriter::getRecentSamples()).
struct LogSeries {
  std::string column;         ///< column name, e.g. `puma.q[0]`
  std::vector<double> time;   ///< sample times on the program's clock [s], increasing
  std::vector<double> value;  ///< one value per time
};

/// Collects the log samples of any number of control programs and writes them to one CSV file.
///
/// Format: a header `t,program.variable,program.vector[0],...` and one row per sample time;
/// samples of different programs taken at the same clock time share a row, other cells are
/// empty. Values are written with the shortest text that reads back to the same double.
/// While running, rows go to `FILE.part` (created exclusively: a second run with the same FILE is
/// refused); close() (called by stop, system shutdown, SIGINT, SIGTERM and normal exit) drains
/// every ring buffer and renames it to `FILE`. A FILE that is not a regular file (a FIFO,
/// `/dev/null`, a terminal, a symbolic link) is written in place and never replaced; a directory, and a file
/// not empty and not a log (`-log rp.cfg`), are refused. Every write is checked: on a failure (a full disk, a
/// reader gone) the writer says so on stderr at once, cuts the file back to its last complete row,
/// writes nothing more and hasFailed() turns true; close() still completes FILE with the rows
/// kept. After a kill, recoverLog() (`rp-log recover FILE.part`) makes a log of `FILE.part`.
/// No sample is lost unless a program's ring buffer overflows; losses are counted
/// (ControlStatistics::lostLogSamples, getLostSamples()) and reported on close.
class LogWriter {
 public:
  /// Opens the log and starts the writer thread.
  /// @param[in] fileName  CSV file to write
  /// @throws std::runtime_error naming FILE if it is a directory (or a block device, a dangling
  ///         link, a FIFO nobody reads), if `FILE.part` exists (another run, or a killed one) or
  ///         cannot be created
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

  /// @name Failures
  /// @{

  /// Whether a write, sync, close or the completion of FILE failed: the log is incomplete (it
  /// holds the complete rows written before the failure). A program should end with a non-zero
  /// status then.
  bool hasFailed() const;
  /// What failed, e.g. `write failed: No space left on device; 1200 complete rows kept`, or "".
  std::string getError() const;
  /// Calls `handler` once, with getError(), on the first failure (from the writer's thread, at once;
  /// it must not block; close() called there returns at once, the writer ends by itself), or right
  /// away if the log has failed already. E.g. request a system shutdown there to end the run.
  /// @param[in] handler  called with the message; an empty function removes the handler
  void setFailureHandler(std::function<void(const std::string& message)> handler);
  /// @}

  /// @name Starting and stopping (QMotor's start/stop logging)
  /// @{

  /// Stops writing samples to the file: every sample taken before the call is still written,
  /// samples taken after it are left out of the file (they still reach getRecentSamples()).
  /// Samples are taken by the real-time loops as before; only the writer leaves them out.
  /// Does nothing if already stopped. Real-time safe: no (drains the ring buffers first).
  void stopLogging();
  /// Starts writing samples to the file again (samples taken after the call); the rows of the
  /// stopped interval are missing from the file. Real-time safe: no.
  void startLogging();
  /// Whether samples are being written to the file (true from construction until stopLogging()).
  bool isLogging() const;
  /// @}

  /// @name Reading the samples (live plots)
  /// @{

  /// The column names (`program.variable` or `program.vector[i]`) in file order, without `t`.
  /// Real-time safe: no.
  std::vector<std::string> getColumns() const;
  /// The samples of each column taken after `afterTime`, at most the newest `maxSamples`. From the
  /// first call on, the writer keeps the last kRecentSamples of every program, whether logging to
  /// the file or not (before it, none: a log nobody reads this way costs nothing more).
  /// @param[in] columns     column names
  /// @param[in] afterTime   only samples with a later time [s]
  /// @param[in] maxSamples  at most this many per column (the newest)
  /// @return one series per column, in the order asked
  /// @throws std::invalid_argument naming a column that is not in the log
  /// Real-time safe: no.
  std::vector<LogSeries> getRecentSamples(const std::vector<std::string>& columns, double afterTime,
                                          std::size_t maxSamples = 4096) const;
  /// How many of each program's newest samples getRecentSamples() can return.
  static constexpr std::size_t kRecentSamples = 8192;
  /// @}

  /// The platform's writer (from `-log FILE`), or nullptr.
  static LogWriter* getPlatformWriter();
  /// Creates the platform's writer (RoboticPlatform::init does this for `-log`).
  /// @param[in] fileName  CSV file
  /// @throws std::runtime_error as LogWriter()
  static void openPlatformWriter(const std::string& fileName);
  /// Closes the platform's writer, completing its file.
  static void closePlatformWriter();
  /// Whether the platform's writer exists and hasFailed() (the program should end with a non-zero status).
  static bool hasPlatformWriterFailed();

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
