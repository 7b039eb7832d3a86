// recoverLog(): the complete log (widest header, complete rows padded to its width) held in a log
// being written, FILE.part.
#include "rp/rt/LogRecovery.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string_view>

#include "LogFile.hpp"

namespace rp {

namespace internal {

namespace {

bool isHeader(std::string_view line) { return line == "t" || line.substr(0, 2) == "t,"; }

std::size_t fieldCount(std::string_view line) {
  std::size_t n = 1;
  for (char c : line) n += c == ',';
  return n;
}

bool isNumber(std::string_view cell) {
  double v;
  auto [ptr, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), v);
  return ec == std::errc() && ptr == cell.data() + cell.size();
}

// Reads the lines of `name` one by one; a last line without an end of line is reported as cut.
class LineReader {
 public:
  explicit LineReader(const std::string& name) : name_(name), in_(name, std::ios::binary) {
    if (!in_) throw std::runtime_error(name + ": cannot open: " + std::strerror(errno));
  }
  // The next complete line (without its end of line); false at the end. `cut` tells whether the
  // file ended in a line without an end of line.
  bool next(std::string& line, bool& cut) {
    cut = false;
    if (!std::getline(in_, line)) {
      if (in_.bad()) throw std::runtime_error(name_ + ": read error");
      return false;
    }
    ++number_;
    if (in_.eof()) {  // no '\n' after the line: the run ended while writing it
      cut = true;
      return false;
    }
    return true;
  }
  std::size_t number() const { return number_; }

 private:
  std::string name_;
  std::ifstream in_;
  std::size_t number_ = 0;
};

}  // namespace

int writeAll(int fd, const char* data, std::size_t size, std::size_t& written) {
  written = 0;
  while (written < size) {
    const ssize_t n = ::write(fd, data + written, size - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    if (n == 0) return EIO;
    written += static_cast<std::size_t>(n);
  }
  return 0;
}

LogRecovery writeCompleteLog(const std::string& partFile, int fd, const std::string& outName) {
  LogRecovery result;
  std::string line, header;
  bool cut = false;
  {  // First pass: check every complete line and find the widest header.
    LineReader in(partFile);
    std::size_t width = 0;
    while (in.next(line, cut)) {
      const std::string where = partFile + ":" + std::to_string(in.number()) + ": ";
      if (isHeader(line)) {
        if (!header.empty() && line.compare(0, header.size() + 1, header + ",") != 0)
          throw std::runtime_error(where + "a header that does not extend the one before it");
        header = line;
        width = fieldCount(line);
        continue;
      }
      if (header.empty())
        throw std::runtime_error(where + "not a Robotic Platform log (the first line must be the header 't,...')");
      const std::size_t fields = fieldCount(line);
      if (fields != width)
        throw std::runtime_error(where + std::to_string(fields) + " values, the header has " + std::to_string(width));
      std::string_view rest(line);
      for (std::size_t i = 0; i < fields; ++i) {
        const std::size_t comma = std::min(rest.find(','), rest.size());
        const std::string_view cell = rest.substr(0, comma);
        if ((i == 0 || !cell.empty()) && !isNumber(cell))
          throw std::runtime_error(where + "'" + std::string(cell) + "' is not a number");
        rest.remove_prefix(std::min(comma + 1, rest.size()));
      }
      ++result.rows;
    }
    if (header.empty())
      throw std::runtime_error(partFile + (in.number() == 0 ? ": empty (the run ended before the first row was written)"
                                                           : ":1: not a Robotic Platform log (no complete header line)"));
    result.cutRowDropped = cut;
  }
  result.columns = fieldCount(header);
  // Second pass: the widest header, then the rows padded to its width.
  LineReader in(partFile);
  std::string out = header + "\n";
  out.reserve(1 << 16);
  std::uint64_t rows = 0;
  auto flush = [&] {
    std::size_t written;
    if (const int e = writeAll(fd, out.data(), out.size(), written))
      throw std::runtime_error(outName + ": write failed: " + std::strerror(e));
    out.clear();
  };
  while (rows < result.rows && in.next(line, cut)) {
    if (isHeader(line)) continue;
    out += line;
    out.append(result.columns - fieldCount(line), ',');
    out += '\n';
    ++rows;
    if (out.size() >= (1 << 16)) flush();
  }
  flush();
  return result;
}

}  // namespace internal

LogRecovery recoverLog(const std::string& partFile, const std::string& outFile) {
  // The input is a file a run left: a regular file (a FIFO would wait for a writer forever, a
  // device such as /dev/zero would be read without end). Checked before the output is created.
  struct stat st {};
  if (::stat(partFile.c_str(), &st) != 0) {
    const int e = errno;
    throw std::runtime_error(partFile + ": cannot open: " + std::strerror(e));
  }
  if (!S_ISREG(st.st_mode))
    throw std::runtime_error(partFile + ": is " +
                             (S_ISDIR(st.st_mode)    ? "a directory"
                              : S_ISFIFO(st.st_mode) ? "a FIFO"
                              : S_ISCHR(st.st_mode)  ? "a character device"
                                                     : "not a regular file") +
                             ": a log a run left (FILE.part) is a regular file");
  if (outFile == "-") return internal::writeCompleteLog(partFile, STDOUT_FILENO, "stdout");
  {  // Check the input before creating the output.
    std::ifstream probe(partFile, std::ios::binary);
    if (!probe) {
      const int e = errno;
      throw std::runtime_error(partFile + ": cannot open: " + std::strerror(e));
    }
  }
  const int fd = ::open(outFile.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) {
    const int e = errno;
    throw std::runtime_error(outFile + ": cannot create: " + std::strerror(e) +
                             (e == EEXIST ? " (a log is never overwritten: remove it or name another)" : ""));
  }
  LogRecovery result;
  std::string error;
  try {
    result = internal::writeCompleteLog(partFile, fd, outFile);
    if (::fsync(fd) != 0 && errno != EINVAL) error = outFile + ": sync failed: " + std::strerror(errno);
  } catch (const std::exception& e) {
    error = e.what();
  }
  if (::close(fd) != 0 && error.empty()) error = outFile + ": close failed: " + std::strerror(errno);
  if (!error.empty()) {
    ::unlink(outFile.c_str());
    throw std::runtime_error(error);
  }
  return result;
}

}  // namespace rp
