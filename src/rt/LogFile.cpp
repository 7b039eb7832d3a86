// LogFile: claims the log file without ever replacing what is not a regular file, checks every
// write (cutting the file back to its last complete line on failure) and completes the log.
#include "LogFile.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <vector>

namespace rp::internal {

namespace {

std::string quoted(const std::string& name) { return "'" + name + "'"; }

std::string errorText(int e) { return std::strerror(e); }

// Whether the regular file `name` may be replaced by a log: it is empty, or a log itself (its
// header line starts with the time column, "t," or "t" alone). Anything else - the program's
// rp.cfg, a URDF, a log of another tool - is someone's data.
bool replaceableByALog(const std::string& name) {
  const int fd = ::open(name.c_str(), O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK);
  if (fd < 0) return errno == ENOENT;  // gone since: nothing to lose; unreadable: not known to be a log
  char head[2] = {0, 0};
  ssize_t got = 0;
  do {
    got = ::read(fd, head, sizeof head);
  } while (got < 0 && errno == EINTR);
  ::close(fd);
  return got <= 0 || (head[0] == 't' && (got == 1 || head[1] == ',' || head[1] == '\n' || head[1] == '\r'));
}

}  // namespace

LogFile::LogFile(const std::string& fileName) : fileName_(fileName) {
  auto refuse = [&](const std::string& why) { throw std::runtime_error(quoted(fileName) + (why.compare(0, 3, "is ") == 0 ? " " : ": ") + why); };
  if (fileName.empty()) refuse("no file name");
  auto refuseUnlessALog = [&](const std::string& what) {
    if (!replaceableByALog(fileName))
      refuse(what + "a file that is not a log (its first line is no header 't,...', or it cannot be read): a log never "
             "replaces it (name another file, or remove this one)");
  };
  struct stat st {};
  if (::lstat(fileName.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
    // Not a regular file: it is never replaced; a stream (FIFO, terminal, /dev/null, a link) is
    // written in place.
    const bool link = S_ISLNK(st.st_mode);
    struct stat target = st;
    if (link && ::stat(fileName.c_str(), &target) != 0)
      refuse("is a symbolic link to nothing that can be written (" + errorText(errno) + ")");
    const std::string what = link ? "is a symbolic link to " : "is ";
    if (S_ISDIR(target.st_mode)) refuse(what + "a directory (name a file in it, e.g. " + quoted(fileName + "/log.csv") + ")");
    if (S_ISBLK(target.st_mode)) refuse(what + "a block device (a log is never written over a disk)");
    if (link && S_ISREG(target.st_mode)) refuseUnlessALog(what);  // written in place: truncated first
    if (!S_ISFIFO(target.st_mode) && !S_ISCHR(target.st_mode) && !S_ISREG(target.st_mode))
      refuse(what + "neither a regular file, a FIFO nor a character device");
    const bool fifo = S_ISFIFO(target.st_mode);
    fd_ = ::open(fileName.c_str(), O_WRONLY | O_CLOEXEC | O_NOCTTY | (fifo ? O_NONBLOCK : 0));
    if (fd_ < 0) {
      const int e = errno;
      refuse(fifo && e == ENXIO ? "is a FIFO nobody reads (start its reader first)" : "cannot open: " + errorText(e));
    }
    if (fifo) ::fcntl(fd_, F_SETFL, ::fcntl(fd_, F_GETFL) & ~O_NONBLOCK);  // writes wait for the reader
    struct stat opened {};
    ::fstat(fd_, &opened);
    regular_ = S_ISREG(opened.st_mode);
    if (regular_) {  // a regular file behind a link: written in place, by one run at a time
      if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
        ::close(fd_);
        fd_ = -1;
        refuse("another run is writing it (it is locked)");
      }
      if (::ftruncate(fd_, 0) != 0) {
        const int e = errno;
        ::close(fd_);
        fd_ = -1;
        refuse("cannot truncate: " + errorText(e));
      }
    }
    direct_ = true;
    writingTo_ = fileName;
    return;
  }
  // Absent or a regular file: the rows go to FILE.part, which only this run may write.
  if (S_ISREG(st.st_mode)) refuseUnlessALog("is ");
  writingTo_ = fileName + ".part";
  fd_ = ::open(writingTo_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC | O_NOFOLLOW, 0666);
  if (fd_ < 0) {
    const int e = errno;
    if (e == EEXIST)
      refuse(quoted(writingTo_) + " exists: another run is writing this log, or one was killed (`rp-log recover " +
             writingTo_ + "` makes it a log; or remove it)");
    refuse("cannot create " + quoted(writingTo_) + ": " + errorText(e));
  }
}

LogFile::~LogFile() {
  if (fd_ >= 0) ::close(fd_);
}

int LogFile::write(const std::string& text, std::size_t& kept) {
  kept = 0;
  if (failed_ || fd_ < 0) return EBADF;
  std::size_t written = 0;
  const int e = writeAll(fd_, text.data(), text.size(), written);
  if (e == 0) {
    size_ += text.size();
    kept = text.size();
    return 0;
  }
  failed_ = true;
  std::size_t complete = written;
  while (complete > 0 && text[complete - 1] != '\n') --complete;
  kept = complete;
  size_ += complete;
  // Cutting a file back needs no room on the disk; a stream keeps what its reader has seen.
  if (regular_ && written > complete) {
    while (::ftruncate(fd_, static_cast<off_t>(size_)) != 0 && errno == EINTR) {
    }
  }
  return e;
}

std::string LogFile::finish(bool rewrite) {
  if (fd_ < 0) return "";
  std::string error;
  if (regular_ && ::fsync(fd_) != 0) error = "sync failed: " + errorText(errno);
  mode_t mode = 0644;
  struct stat st {};
  if (::fstat(fd_, &st) == 0) mode = st.st_mode & 07777;
  if (::close(fd_) != 0 && error.empty()) error = "close failed: " + errorText(errno);
  fd_ = -1;
  if (direct_) return error;
  const std::string kept = "every complete row is in " + quoted(writingTo_) + " (`rp-log recover " + writingTo_ +
                           "` makes it a log)";
  std::string source = writingTo_;
  if (rewrite) {  // a program started logging after the first rows: one header, every row padded
    std::vector<char> name(fileName_.begin(), fileName_.end());
    for (char c : std::string(".XXXXXX")) name.push_back(c);
    name.push_back('\0');
    const int fd = ::mkstemp(name.data());
    if (fd < 0) return "cannot complete: " + errorText(errno) + "; " + kept;
    source = name.data();
    std::string failure;
    try {
      writeCompleteLog(writingTo_, fd, source);
      ::fchmod(fd, mode);
      if (::fsync(fd) != 0) failure = "sync failed: " + errorText(errno);
    } catch (const std::exception& e) {
      failure = e.what();
    }
    if (::close(fd) != 0 && failure.empty()) failure = "close failed: " + errorText(errno);
    if (!failure.empty()) {
      ::unlink(source.c_str());
      return "cannot complete: " + failure + "; " + kept;
    }
  }
  // Only a regular file (or nothing) is ever replaced by the log.
  struct stat target {};
  if (::lstat(fileName_.c_str(), &target) == 0 && !S_ISREG(target.st_mode)) {
    if (rewrite) ::unlink(source.c_str());
    return quoted(fileName_) + " is no longer a regular file: it is left alone; " + kept;
  }
  if (std::rename(source.c_str(), fileName_.c_str()) != 0) {
    const int e = errno;
    if (rewrite) ::unlink(source.c_str());
    return "cannot rename to " + quoted(fileName_) + ": " + errorText(e) + "; " + kept;
  }
  if (rewrite) ::unlink(writingTo_.c_str());
  return error;
}

}  // namespace rp::internal
