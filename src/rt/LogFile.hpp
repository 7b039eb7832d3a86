// The file a LogWriter writes to: which file it may write, how each write is checked, and how the
// log is completed (see docs/realtime.md, "The log file").
#pragma once
#include <cstddef>
#include <string>

#include "rp/rt/LogRecovery.hpp"

namespace rp::internal {

// Writes all of `size` bytes to `fd`, resuming after short writes and EINTR. Returns 0 or the errno
// of the failed write; `written` bytes reached the file either way.
int writeAll(int fd, const char* data, std::size_t size, std::size_t& written);

// recoverLog()'s work: reads the log being written `partFile` and writes the complete log to `fd`
// (named `outName` in errors). Throws std::runtime_error naming the file and line.
LogRecovery writeCompleteLog(const std::string& partFile, int fd, const std::string& outName);

class LogFile {
 public:
  // Claims the log FILE (throws std::runtime_error naming the file and the reason):
  // - FILE absent, empty or a log (first line 't,...'): writes to FILE.part, created exclusively (a
  //   second run with the same FILE, or the leftover of a killed one, is refused); finish() renames it.
  // - FILE a FIFO, a character device (/dev/null, a terminal) or a symbolic link to one of these
  //   or to an empty file or a log: writes to FILE itself (locked while written), never replacing it.
  // - a directory, a block device, a socket, a dangling link, a file that is not a log: refused.
  explicit LogFile(const std::string& fileName);
  ~LogFile();
  LogFile(const LogFile&) = delete;
  LogFile& operator=(const LogFile&) = delete;

  // Whether the log goes to FILE itself (no FILE.part, no rename).
  bool isDirect() const { return direct_; }
  // Where the rows are being written (FILE.part, or FILE when direct).
  const std::string& writingTo() const { return writingTo_; }

  // Writes `text`, which ends with a complete line. Returns 0, or the errno of the first failed
  // write; then the file is cut back to the end of the last complete line that reached it, and
  // `kept` is how many bytes of `text` that is. Nothing is written after a failure.
  int write(const std::string& text, std::size_t& kept);

  // Syncs and closes the file; with FILE.part, renames it to FILE, first rewritten as a complete log
  // (LogRecovery) when `rewrite`. Returns "" or what went wrong (the rows then stay in FILE.part).
  std::string finish(bool rewrite);

 private:
  std::string fileName_, writingTo_;
  int fd_ = -1;
  bool direct_ = false;
  bool regular_ = true;  // the file written is a regular file (it can be cut back and synced)
  bool failed_ = false;
  std::size_t size_ = 0;  // bytes in the file, all of them complete lines
};

}  // namespace rp::internal
