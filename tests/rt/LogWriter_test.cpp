// The log file is never lost: LogWriter refuses a directory and a second run of the same file,
// writes FIFOs, devices and links in place without replacing them, keeps every complete row when a
// write fails (file size limit, full tmpfs, reader gone) and leaves after a kill a FILE.part that
// recoverLog() makes a log of. Failures are injected in child processes: the test binary run again
// (posix_spawn) in a role named by RP_LOG_TEST_CHILD.
#include "rp/rt/LogWriter.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sched.h>
#include <signal.h>
#include <spawn.h>
#include <sys/mount.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <thread>

#include "rp/rt/Clock.hpp"
#include "rp/rt/ControlProgram.hpp"
#include "rp/rt/LogRecovery.hpp"
#include "ScratchDirectory.hpp"

namespace rp {
namespace {

namespace fs = std::filesystem;

test::ScratchDirectory scratch(const std::string& name) { return test::ScratchDirectory("rp_log_test_", name); }

std::string slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  std::string line;
  while (std::getline(in, line)) out.push_back(line);
  return out;
}

std::size_t fields(const std::string& line) {
  std::size_t n = 1;
  for (char c : line) n += c == ',';
  return n;
}

std::vector<std::string> directory(const fs::path& dir) {
  std::vector<std::string> names;
  for (auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

// Logs x = cycle count and q = (x, 2x, 3x): columns NAME.x, NAME.q[0..2].
class Counter : public ControlProgram {
 public:
  explicit Counter(const std::string& name) : ControlProgram(name) {
    registerLogVariable("x", x, "m");
    registerLogVariable("q", q, "rad");
  }
  ~Counter() override { stop(); }
  double x = 0;
  Vector<3> q;

 protected:
  void control() override {
    x = static_cast<double>(getCycleCount());
    q = x, 2 * x, 3 * x;
  }
};

const std::string kHeader = "t,c.x,c.q[0],c.q[1],c.q[2]";

// Runs a Counter called `name` for `cycles` cycles on `clock`, logging to `writer`.
void logCycles(LogWriter& writer, SimulatedClock& clock, std::uint64_t cycles, const std::string& name = "c") {
  Counter c(name);
  c.setClock(clock);
  c.setLogWriter(&writer);
  c.setLogBufferSize(4096);
  c.setCycleLimit(cycles);
  c.start();
  c.waitUntilStopped();
}

// Every line of a complete log of a Counter "c": the header, then rows 0, 1, 2, ... in order.
void expectCompleteRows(const std::string& text, std::size_t rows) {
  ASSERT_FALSE(text.empty());
  EXPECT_EQ(text.back(), '\n') << "the last row is cut";
  const auto all = lines(text);
  ASSERT_EQ(all.size(), rows + 1);
  EXPECT_EQ(all[0], kHeader);
  for (std::size_t i = 1; i < all.size(); ++i) {
    std::vector<double> cells;
    std::stringstream row(all[i]);
    for (std::string cell; std::getline(row, cell, ',');) cells.push_back(std::stod(cell));
    const double x = static_cast<double>(i - 1);
    ASSERT_EQ(cells.size(), 5u) << "row " << i << ": " << all[i];
    ASSERT_EQ(cells[1], x) << "row " << i << ": " << all[i];
    ASSERT_EQ(cells[3], 2 * x) << "row " << i << ": " << all[i];
    ASSERT_EQ(cells[4], 3 * x) << "row " << i << ": " << all[i];
  }
}

// The roles of a child process; its stderr is DIR/stderr.txt, its exit status the result.
int childMain(const std::string& role, const fs::path& dir) {
  if (role == "fsize") {  // a file size limit of 20 kB, SIGXFSZ left at its default (a core dump)
    const rlimit limit{20000, 20000};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    LogWriter writer((dir / "log.csv").string());
    SimulatedClock clock(1e-3);
    logCycles(writer, clock, 5000);  // about 150 kB of rows
    writer.close();
    return writer.hasFailed() ? 3 : 0;
  }
  if (role == "fulldisk") {  // a 64 kB tmpfs in a private mount namespace
    if (::unshare(CLONE_NEWNS) != 0 || ::mount(nullptr, "/", nullptr, MS_REC | MS_PRIVATE, nullptr) != 0 ||
        ::mount("tmpfs", (dir / "mnt").c_str(), "tmpfs", 0, "size=64k") != 0)
      return 77;
    const auto file = dir / "mnt" / "log.csv";
    bool failed;
    {
      LogWriter writer(file.string());
      SimulatedClock clock(1e-3);
      logCycles(writer, clock, 10000);  // about 300 kB of rows
      writer.close();
      failed = writer.hasFailed();
    }
    // The tmpfs disappears with the child: leave a copy of what it holds.
    fs::copy_file(file, dir / "copy.csv");
    std::ofstream(dir / "listing.txt") << directory(dir / "mnt").size() << "\n";
    return failed ? 3 : 0;
  }
  if (role == "killed") {  // logs until killed
    LogWriter writer((dir / "log.csv").string());
    SimulatedClock clock(1e-3);
    logCycles(writer, clock, 0);
    return 0;
  }
  return 98;
}

// In a child process, runs its role before main() and exits.
const bool kChild = [] {
  const char* spec = std::getenv("RP_LOG_TEST_CHILD");
  if (!spec) return false;
  const std::string role(spec);
  const auto colon = role.find(':');
  int rc = 99;
  try {
    rc = childMain(role.substr(0, colon), role.substr(colon + 1));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "exception: %s\n", e.what());
  }
  std::fflush(nullptr);
  std::_Exit(rc);
}();

// Starts this test binary as a child process in `role` working in `dir`.
pid_t spawnChild(const std::string& role, const fs::path& dir) {
  std::vector<std::string> env{"RP_LOG_TEST_CHILD=" + role + ":" + dir.string()};
  for (char** e = environ; *e; ++e) env.emplace_back(*e);
  std::vector<char*> envp;
  for (auto& e : env) envp.push_back(e.data());
  envp.push_back(nullptr);
  std::string self = "/proc/self/exe";
  char* argv[] = {self.data(), nullptr};
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  const std::string err = (dir / "stderr.txt").string();
  posix_spawn_file_actions_addopen(&actions, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = -1;
  const int e = ::posix_spawn(&pid, self.c_str(), &actions, nullptr, argv, envp.data());
  posix_spawn_file_actions_destroy(&actions);
  EXPECT_EQ(e, 0) << std::strerror(e);
  return pid;
}

// Runs the child in `role` to its end; returns its wait status.
int runChild(const std::string& role, const fs::path& dir) {
  const pid_t pid = spawnChild(role, dir);
  int status = 0;
  ::waitpid(pid, &status, 0);
  return status;
}

// The number N in "...; N complete rows kept" of the writer's message.
std::size_t rowsKept(const std::string& err) {
  const auto end = err.find(" complete rows kept");
  if (end == std::string::npos) return ~std::size_t{0};
  auto begin = err.rfind(' ', end - 1);
  return std::stoul(err.substr(begin + 1, end - begin - 1));
}

TEST(LogWriterFile, ADirectoryIsRefusedAndNothingIsLeft) {
  auto dir = scratch("directory");
  fs::create_directory(dir / "logs");
  try {
    LogWriter writer((dir / "logs").string());
    FAIL() << "a directory was accepted as the log";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("logs' is a directory"), std::string::npos) << e.what();
  }
  EXPECT_EQ(directory(dir), std::vector<std::string>{"logs"});
  EXPECT_TRUE(fs::is_empty(dir / "logs"));
}

TEST(LogWriterFile, ASecondRunOfTheSameFileIsRefused) {
  auto dir = scratch("tworuns");
  const auto file = dir / "log.csv";
  SimulatedClock clock(1e-3);
  LogWriter first(file.string());
  try {
    LogWriter second(file.string());
    FAIL() << "two writers share " << file;
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("log.csv.part' exists: another run is writing this log"), std::string::npos)
        << e.what();
  }
  logCycles(first, clock, 100);
  first.close();
  EXPECT_FALSE(first.hasFailed());
  expectCompleteRows(slurp(file), 100);
  EXPECT_EQ(directory(dir), std::vector<std::string>{"log.csv"});
  // The run is over: the next one may replace the complete log.
  LogWriter third(file.string());
  logCycles(third, clock, 10);
  third.close();
  expectCompleteRows(slurp(file), 10);
}

// `-log rp.cfg` (a slip of the keyboard) used to replace the program's own configuration with
// its log. A file that is not a log - no header line "t,..." - is never replaced or truncated,
// named directly or through a link; an empty file and an older log are.
TEST(LogWriterFile, AFileThatIsNotALogIsNeverReplaced) {
  auto dir = scratch("notalog");
  const std::string config = "[puma]\nclass Puma560\n";
  std::ofstream(dir / "rp.cfg") << config;
  fs::create_symlink("rp.cfg", dir / "link.csv");
  for (const char* name : {"rp.cfg", "link.csv"}) {
    SCOPED_TRACE(name);
    try {
      LogWriter writer((dir / name).string());
      FAIL() << "a configuration file was taken as the log";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("a file that is not a log"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
    EXPECT_EQ(slurp(dir / "rp.cfg"), config);
  }
  EXPECT_EQ(directory(dir), (std::vector<std::string>{"link.csv", "rp.cfg"}));
  // An empty file, and a log of an earlier run, are replaced.
  SimulatedClock clock(1e-3);
  std::ofstream(dir / "empty.csv").flush();
  std::ofstream(dir / "old.csv") << "t,arm.q[0]\n0.001,0.5\n";
  for (const char* name : {"empty.csv", "old.csv"}) {
    SCOPED_TRACE(name);
    LogWriter writer((dir / name).string());
    logCycles(writer, clock, 20);
    writer.close();
    EXPECT_FALSE(writer.hasFailed()) << writer.getError();
    expectCompleteRows(slurp(dir / name), 20);
  }
}

TEST(LogWriterFile, AFifoIsWrittenInPlace) {
  auto dir = scratch("fifo");
  const auto fifo = dir / "log.fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const int reader = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);
  ASSERT_GE(reader, 0);
  std::string received;
  {
    LogWriter writer(fifo.string());
    ::fcntl(reader, F_SETFL, ::fcntl(reader, F_GETFL) & ~O_NONBLOCK);
    std::thread readAll([&] {
      char buf[4096];
      for (ssize_t n; (n = ::read(reader, buf, sizeof buf)) > 0;) received.append(buf, static_cast<std::size_t>(n));
    });
    SimulatedClock clock(1e-3);
    logCycles(writer, clock, 500);
    writer.close();
    readAll.join();
    EXPECT_FALSE(writer.hasFailed()) << writer.getError();
    EXPECT_EQ(writer.getRowCount(), 500u);
  }
  ::close(reader);
  EXPECT_TRUE(fs::is_fifo(fs::symlink_status(fifo)));
  EXPECT_EQ(directory(dir), std::vector<std::string>{"log.fifo"});
  expectCompleteRows(received, 500);
}

TEST(LogWriterFile, AFifoNobodyReadsIsRefused) {
  auto dir = scratch("fifonoreader");
  const auto fifo = dir / "log.fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_THROW(LogWriter writer(fifo.string()), std::runtime_error);
  EXPECT_EQ(directory(dir), std::vector<std::string>{"log.fifo"});
}

TEST(LogWriterFile, ASymbolicLinkIsWrittenThroughAndKept) {
  auto dir = scratch("symlink");
  std::ofstream(dir / "run1.csv") << "t,arm.q[0]\n0.001,0.5\n";  // an older log
  fs::create_symlink("run1.csv", dir / "latest.csv");
  {
    LogWriter writer((dir / "latest.csv").string());
    SimulatedClock clock(1e-3);
    logCycles(writer, clock, 200);
    writer.close();
    EXPECT_FALSE(writer.hasFailed()) << writer.getError();
  }
  ASSERT_TRUE(fs::is_symlink(dir / "latest.csv"));
  EXPECT_EQ(fs::read_symlink(dir / "latest.csv"), "run1.csv");
  expectCompleteRows(slurp(dir / "run1.csv"), 200);
  EXPECT_EQ(directory(dir), (std::vector<std::string>{"latest.csv", "run1.csv"}));
  // A link to a directory or to nothing is refused.
  fs::create_directory(dir / "d");
  fs::create_symlink("d", dir / "todir.csv");
  fs::create_symlink("missing/x.csv", dir / "dangling.csv");
  EXPECT_THROW(LogWriter((dir / "todir.csv").string()), std::runtime_error);
  EXPECT_THROW(LogWriter((dir / "dangling.csv").string()), std::runtime_error);
  EXPECT_TRUE(fs::is_empty(dir / "d"));
}

// A copy of /dev/null and of /dev/full (needs CAP_MKNOD): written in place, never replaced; on the
// full device the first write fails, says so and the writer reports it.
TEST(LogWriterFile, DevicesAreWrittenInPlaceAndAFullOneFails) {
  auto dir = scratch("devices");
  if (::mknod((dir / "null").c_str(), S_IFCHR | 0666, makedev(1, 3)) != 0 ||
      ::mknod((dir / "full").c_str(), S_IFCHR | 0666, makedev(1, 7)) != 0)
    GTEST_SKIP() << "cannot create device nodes here (needs CAP_MKNOD)";
  SimulatedClock clock(1e-3);
  {
    LogWriter writer((dir / "null").string());
    logCycles(writer, clock, 300);
    writer.close();
    EXPECT_FALSE(writer.hasFailed()) << writer.getError();
    EXPECT_EQ(writer.getRowCount(), 300u);
  }
  {
    LogWriter writer((dir / "full").string());
    std::string handled;
    writer.setFailureHandler([&](const std::string& message) { handled = message; });
    logCycles(writer, clock, 300);
    writer.close();
    EXPECT_TRUE(writer.hasFailed());
    EXPECT_EQ(writer.getError(), "write failed: No space left on device; 0 complete rows kept");
    EXPECT_EQ(handled, writer.getError());
  }
  EXPECT_TRUE(fs::is_character_file(fs::symlink_status(dir / "null")));
  EXPECT_TRUE(fs::is_character_file(fs::symlink_status(dir / "full")));
  EXPECT_EQ(directory(dir), (std::vector<std::string>{"full", "null"}));
}

// A file size limit (RLIMIT_FSIZE) makes a write fail after ~20 kB. SIGXFSZ is left at its
// default (a core dump): the writer must not die of it. FILE keeps every complete row, no
// FILE.part is left, stderr says how many rows were kept, and hasFailed() is true.
TEST(LogWriterFile, AFileSizeLimitKeepsEveryCompleteRow) {
  auto dir = scratch("fsize");
  const auto file = dir / "log.csv";
  const int status = runChild("fsize", dir);
  const std::string err = slurp(dir / "stderr.txt");
  ASSERT_TRUE(WIFEXITED(status)) << "the child died of signal " << WTERMSIG(status) << "\n" << err;
  EXPECT_EQ(WEXITSTATUS(status), 3) << "the writer did not report the failure\n" << err;
  EXPECT_NE(err.find("rp: log " + file.string() + ": write failed: File too large; "), std::string::npos) << err;
  const std::string text = slurp(file);
  EXPECT_LE(text.size(), 20000u);
  EXPECT_GT(text.size(), 10000u);
  const std::size_t kept = rowsKept(err);
  expectCompleteRows(text, kept);
  EXPECT_EQ(directory(dir), (std::vector<std::string>{"log.csv", "stderr.txt"}));
}

// A full disk: a 64 kB tmpfs mounted in a private mount namespace of the child (needs
// CAP_SYS_ADMIN; skipped without). The complete rows stay in FILE.
TEST(LogWriterFile, AFullDiskKeepsEveryCompleteRow) {
  auto dir = scratch("fulldisk");
  fs::create_directory(dir / "mnt");
  const int status = runChild("fulldisk", dir);
  if (WIFEXITED(status) && WEXITSTATUS(status) == 77) GTEST_SKIP() << "cannot mount a tmpfs here";
  const std::string err = slurp(dir / "stderr.txt");
  ASSERT_TRUE(WIFEXITED(status)) << err;
  EXPECT_EQ(WEXITSTATUS(status), 3) << err;
  EXPECT_NE(err.find("write failed: No space left on device; "), std::string::npos) << err;
  EXPECT_EQ(slurp(dir / "listing.txt"), "1\n") << "FILE.part (or a temporary file) was left";
  const std::string text = slurp(dir / "copy.csv");
  EXPECT_GT(text.size(), 30000u);
  expectCompleteRows(text, rowsKept(err));
}

// The reader of a FIFO goes away: the write fails (EPIPE) instead of SIGPIPE ending this process.
TEST(LogWriterFile, AReaderGoneFailsTheLogNotTheProcess) {
  auto dir = scratch("readergone");
  const auto fifo = dir / "log.fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const int reader = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);
  ASSERT_GE(reader, 0);
  LogWriter writer(fifo.string());
  ::close(reader);
  SimulatedClock clock(1e-3);
  logCycles(writer, clock, 200);
  writer.close();
  EXPECT_TRUE(writer.hasFailed());
  EXPECT_EQ(writer.getError(), "write failed: Broken pipe; 0 complete rows kept");
}

// A program that starts logging after the first rows were written: the complete file has one
// header with every column and the earlier rows padded (FILE.part had a second, wider header).
TEST(LogWriterFile, AProgramStartedLaterGetsItsColumnsInTheOneHeader) {
  auto dir = scratch("laterprogram");
  const auto file = dir / "log.csv";
  LogWriter writer(file.string());
  SimulatedClock clock(1e-3);
  logCycles(writer, clock, 100, "a");
  for (int i = 0; i < 1000 && writer.getRowCount() < 100; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  ASSERT_EQ(writer.getRowCount(), 100u);
  const auto part = lines(slurp(file.string() + ".part"));
  ASSERT_EQ(part.size(), 101u);
  logCycles(writer, clock, 50, "b");
  writer.close();
  EXPECT_FALSE(writer.hasFailed()) << writer.getError();
  const auto all = lines(slurp(file));
  ASSERT_EQ(all.size(), 151u);
  EXPECT_EQ(all[0], "t,a.x,a.q[0],a.q[1],a.q[2],b.x,b.q[0],b.q[1],b.q[2]");
  EXPECT_EQ(all[1], "0,0,0,0,0,,,,");
  for (std::size_t i = 1; i < all.size(); ++i) EXPECT_EQ(fields(all[i]), 9u) << all[i];
  EXPECT_EQ(all[101].substr(all[101].find(',')), ",,,,,0,0,0,0");
  EXPECT_EQ(directory(dir), std::vector<std::string>{"log.csv"});
}

// SIGKILL: FILE.part stays (the next run with FILE is refused and told what to do), and
// recoverLog() makes a complete log of it, leaving out the row the kill cut.
TEST(LogWriterFile, AKilledRunLeavesAPartThatRecovers) {
  auto dir = scratch("killed");
  const auto file = dir / "log.csv";
  const std::string part = file.string() + ".part";
  const pid_t pid = spawnChild("killed", dir);
  std::error_code ec;
  for (int i = 0; i < 3000 && !(fs::file_size(part, ec) > 20000 && !ec); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  ::kill(pid, SIGKILL);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status));
  ASSERT_GT(fs::file_size(part), 20000u);
  EXPECT_FALSE(fs::exists(file));
  try {
    LogWriter next(file.string());
    FAIL() << "the next run overwrote the killed run's rows";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("`rp-log recover " + part + "`"), std::string::npos) << e.what();
  }
  // The kill cut the last row 5 bytes short of its end.
  fs::resize_file(part, fs::file_size(part) - 5);
  const auto partLines = lines(slurp(part));
  const LogRecovery recovered = recoverLog(part, file.string());
  EXPECT_TRUE(recovered.cutRowDropped);
  EXPECT_EQ(recovered.columns, 5u);
  EXPECT_EQ(recovered.rows, partLines.size() - 2);  // without the header and the cut row
  expectCompleteRows(slurp(file), recovered.rows);
  // The log exists now: recovering again would overwrite it and is refused.
  EXPECT_THROW(recoverLog(part, file.string()), std::runtime_error);
}

void expectRecoveryError(const fs::path& dir, const std::string& text, const std::string& message) {
  const auto in = dir / "in.csv.part";
  std::ofstream(in, std::ios::binary) << text;
  fs::remove(dir / "out.csv");
  try {
    recoverLog(in.string(), (dir / "out.csv").string());
    ADD_FAILURE() << "accepted: " << text;
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(e.what(), in.string() + message);
  }
  EXPECT_FALSE(fs::exists(dir / "out.csv")) << "a partial output was left for: " << text;
}

TEST(LogRecovery, BadInputIsRefusedNamingTheLine) {
  auto dir = scratch("recoverbad");
  expectRecoveryError(dir, "", ": empty (the run ended before the first row was written)");
  expectRecoveryError(dir, "t,a.x", ":1: not a Robotic Platform log (no complete header line)");
  expectRecoveryError(dir, "x,y\n1,2\n", ":1: not a Robotic Platform log (the first line must be the header 't,...')");
  expectRecoveryError(dir, "t,a.x\n0,1\n1,2,3\n", ":3: 3 values, the header has 2");
  expectRecoveryError(dir, "t,a.x\n0,1\n1,one\n", ":3: 'one' is not a number");
  expectRecoveryError(dir, "t,a.x\n0,1\nt,b.x,a.x\n", ":3: a header that does not extend the one before it");
  EXPECT_THROW(recoverLog((dir / "missing.part").string(), (dir / "out.csv").string()), std::runtime_error);
  EXPECT_FALSE(fs::exists(dir / "out.csv"));
  // Only a regular file is read: a FIFO used to wait for a writer forever, /dev/zero to be read
  // into memory without end (6 GB in 20 s), to a file or to stdout alike.
  ASSERT_EQ(::mkfifo((dir / "fifo.part").c_str(), 0600), 0);
  fs::create_symlink("/dev/zero", dir / "zero.part");
  fs::create_directory(dir / "dir.part");
  for (const auto& [name, kind] : std::vector<std::pair<std::string, std::string>>{
           {"fifo.part", "a FIFO"}, {"zero.part", "a character device"}, {"dir.part", "a directory"}}) {
    for (const std::string& out : std::vector<std::string>{(dir / "out.csv").string(), "-"}) {
      SCOPED_TRACE(name + " to " + out);
      try {
        recoverLog((dir / name).string(), out);
        ADD_FAILURE() << "accepted";
      } catch (const std::runtime_error& e) {
        EXPECT_EQ(e.what(), (dir / name).string() + ": is " + kind + ": a log a run left (FILE.part) is a regular file");
      }
      EXPECT_FALSE(fs::exists(dir / "out.csv"));
    }
  }
}

TEST(LogRecovery, TheWidestHeaderAndEveryCompleteRowPadded) {
  auto dir = scratch("recovergrow");
  std::ofstream(dir / "in.part", std::ios::binary) << "t,a.x\n0,1\n0.5,\nt,a.x,b.x,b.y\n1,2,3,4\n2,,5,6\n3,4,5";
  const LogRecovery r = recoverLog((dir / "in.part").string(), (dir / "out.csv").string());
  EXPECT_EQ(r.rows, 4u);
  EXPECT_EQ(r.columns, 4u);
  EXPECT_TRUE(r.cutRowDropped);
  EXPECT_EQ(slurp(dir / "out.csv"), "t,a.x,b.x,b.y\n0,1,,\n0.5,,,\n1,2,3,4\n2,,5,6\n");
}

}  // namespace
}  // namespace rp
