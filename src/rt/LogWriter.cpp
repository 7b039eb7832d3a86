// LogWriter: drains the programs' ring buffers in a non-real-time thread and writes one CSV file.
#include "rp/rt/LogWriter.hpp"

#include <pthread.h>
#include <signal.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <map>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

#include "LogChannel.hpp"
#include "LogFile.hpp"

namespace rp {

namespace {

struct Row {
  std::vector<double> values;
  std::vector<char> present;
};

struct Line {
  std::size_t end;  // offset after its '\n' in the text written
  bool row;         // a row (else a header line)
};

using internal::appendNumber;

}  // namespace

struct LogWriter::Impl {
  explicit Impl(const std::string& name) : fileName(name), file(name) {}

  std::string fileName;
  internal::LogFile file;  // touched only by the writer thread once it runs
  std::mutex mutex;        // channels, staging, the writer's state below
  std::condition_variable cv;
  std::vector<std::shared_ptr<Channel>> channels;
  std::size_t totalColumns = 0;
  std::map<double, Row> staging;
  std::thread thread;
  std::thread::id threadId;
  bool stopping = false;
  std::mutex closeMutex;
  std::atomic<bool> closed{false};
  std::atomic<std::uint64_t> rows{0};
  bool logging = true;          // with `mutex`: samples drained while false are not written to the file
  std::size_t headerWidth = 0;  // with `mutex`: columns of the last header line given to the file (0: none)
  bool headerGrew = false;      // with `mutex`: a wider header followed rows (the file needs rewriting)
  std::atomic<bool> failed{false};
  std::string error;                                    // with `mutex`: why, once `failed`
  std::function<void(const std::string&)> onFailure;  // with `mutex`
  // The newest samples of each channel (index as `channels`), each 1 + width doubles; kept only
  // from the first getRecentSamples() call on (a log nobody plots costs nothing more).
  struct History {
    std::vector<double> samples;  // kRecentSamples slots of 1 + width doubles, allocated once
    std::size_t count = 0;        // samples stored so far; the newest is at (count - 1) % kRecentSamples
    const double* at(std::size_t j, std::size_t stride) const {  // j-th oldest kept sample
      const std::size_t first = count > LogWriter::kRecentSamples ? count - LogWriter::kRecentSamples : 0;
      return &samples[((first + j) % LogWriter::kRecentSamples) * stride];
    }
    std::size_t size() const { return std::min(count, LogWriter::kRecentSamples); }
  };
  std::vector<History> recent;
  bool keepRecent = false;

  // With `mutex` held: moves every available sample into `staging` (or, while not logging or
  // after a failed write, only into the plot history).
  void collect() {
    const bool toFile = logging && !failed.load();
    for (std::size_t k = 0; k < channels.size(); ++k) {
      auto& c = channels[k];
      while (const double* s = c->front()) {
        if (keepRecent) {
          History& history = recent[k];
          const std::size_t stride = c->width + 1;
          if (history.samples.empty()) history.samples.resize(LogWriter::kRecentSamples * stride);
          std::copy(s, s + stride, &history.samples[(history.count++ % LogWriter::kRecentSamples) * stride]);
        }
        if (toFile) {
          Row& row = staging[s[0]];
          if (row.values.size() < totalColumns) {
            row.values.resize(totalColumns, 0.0);
            row.present.resize(totalColumns, 0);
          }
          for (std::size_t i = 0; i < c->width; ++i) {
            row.values[c->firstColumn + i] = s[i + 1];
            row.present[c->firstColumn + i] = 1;
          }
        }
        c->lastTime = s[0];
        c->any = true;
        c->pop();
      }
    }
  }

  // With `mutex` held: appends to `out` the header line with every column so far.
  void appendHeader(std::string& out, std::vector<Line>& lines) {
    if (headerWidth > 0) headerGrew = true;
    out += 't';
    for (auto& c : channels)
      for (auto& column : c->columns) {
        out += ',';
        out += column;
      }
    out += '\n';
    headerWidth = totalColumns + 1;
    lines.push_back({out.size(), false});
  }

  // With `mutex` held: appends to `out` the rows no program can add to any more (all times up to
  // the slowest running program's last sample; every row when `all`), each after a header line
  // naming its columns.
  void appendRows(bool all, std::string& out, std::vector<Line>& lines) {
    double watermark = std::numeric_limits<double>::infinity();
    if (!all)
      for (auto& c : channels)
        if (c->any && !c->finished.load()) watermark = std::min(watermark, c->lastTime);
    while (!staging.empty() && staging.begin()->first <= watermark) {
      auto node = staging.extract(staging.begin());
      if (headerWidth != totalColumns + 1) appendHeader(out, lines);
      appendNumber(out, node.key());
      const Row& row = node.mapped();
      for (std::size_t i = 0; i + 1 < headerWidth; ++i) {
        out += ',';
        if (i < row.values.size() && row.present[i]) appendNumber(out, row.values[i]);
      }
      out += '\n';
      lines.push_back({out.size(), true});
    }
  }

  // The writer thread, without `mutex`: writes `out` and counts what reached the file; on the
  // first failure says so at once and writes nothing more.
  void write(const std::string& out, const std::vector<Line>& lines) {
    if (out.empty()) return;
    std::size_t kept = 0;
    const int e = file.write(out, kept);
    std::uint64_t written = 0;
    for (const Line& line : lines)
      if (line.end <= kept && line.row) ++written;
    rows.fetch_add(written);
    if (e != 0) fail(std::string("write failed: ") + std::strerror(e));
  }

  // Records the first failure, tells stderr at once and calls the failure handler.
  void fail(const std::string& what) {
    std::function<void(const std::string&)> handler;
    std::string message;
    {
      std::lock_guard<std::mutex> lock(mutex);
      if (failed.load()) return;
      message = what + "; " + std::to_string(rows.load()) + " complete rows kept";
      error = message;
      failed = true;
      staging.clear();
      handler = onFailure;
    }
    std::fprintf(stderr, "rp: log %s: %s\n", fileName.c_str(), message.c_str());
    std::fflush(stderr);
    if (handler) handler(message);
  }

  void run() {
    // A reader that went away (SIGPIPE) or a file size limit (SIGXFSZ) fails the write instead of
    // ending the process: the rows written so far are kept and the run ends normally.
    sigset_t signals;
    sigemptyset(&signals);
    sigaddset(&signals, SIGPIPE);
    sigaddset(&signals, SIGXFSZ);
    pthread_sigmask(SIG_BLOCK, &signals, nullptr);
    std::string out;
    std::vector<Line> lines;
    bool last = false, rewrite = false;
    while (!last) {
      out.clear();
      lines.clear();
      {
        std::unique_lock<std::mutex> lock(mutex);
        if (!stopping) cv.wait_for(lock, std::chrono::milliseconds(20));
        last = stopping;
        collect();
        if (!failed.load()) {
          appendRows(last, out, lines);
          // The complete log has a header with every column, even without rows.
          if (last && headerWidth != totalColumns + 1) appendHeader(out, lines);
        }
        rewrite = headerGrew;
      }
      write(out, lines);
    }
    const std::string error = file.finish(rewrite && !file.isDirect());
    if (!error.empty() && failed.load())
      std::fprintf(stderr, "rp: log %s: %s\n", fileName.c_str(), error.c_str());
    else if (!error.empty())
      fail(error);
    else if (failed.load() && !file.isDirect())
      std::fprintf(stderr, "rp: log %s: incomplete: its %llu complete rows are in %s\n", fileName.c_str(),
                   static_cast<unsigned long long>(rows.load()), fileName.c_str());
  }
};

LogWriter::LogWriter(const std::string& fileName) : impl_(std::make_unique<Impl>(fileName)) {
  impl_->thread = std::thread([this] { impl_->run(); });
  impl_->threadId = impl_->thread.get_id();
}

LogWriter::~LogWriter() { close(); }

void LogWriter::addChannel(const std::shared_ptr<Channel>& channel) {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  if (impl_->stopping) return;
  // Column names must be unique: a second program of the same name becomes name_2, name_3, ...
  auto taken = [&](const std::string& name) {
    for (auto& c : impl_->channels)
      if (c->program == name) return true;
    return false;
  };
  if (taken(channel->program)) {
    std::string unique;
    for (int k = 2; taken(unique = channel->program + "_" + std::to_string(k)); ++k) {
    }
    std::fprintf(stderr, "rp: log %s: a second program is called '%s'; its columns are '%s.*'\n",
                 impl_->fileName.c_str(), channel->program.c_str(), unique.c_str());
    for (auto& column : channel->columns) column = unique + column.substr(channel->program.size());
    channel->program = unique;
  }
  channel->firstColumn = impl_->totalColumns;
  impl_->totalColumns += channel->width;
  impl_->channels.push_back(channel);
  impl_->recent.emplace_back();
}

void LogWriter::stopLogging() {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  if (impl_->closed.load() || !impl_->logging) return;
  impl_->collect();  // what was taken before this call goes to the file
  impl_->logging = false;
}

void LogWriter::startLogging() {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  if (impl_->closed.load() || impl_->logging) return;
  impl_->collect();  // what was taken while stopped stays out of the file
  impl_->logging = true;
}

bool LogWriter::isLogging() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->logging;
}

std::vector<std::string> LogWriter::getColumns() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  std::vector<std::string> out;
  for (auto& c : impl_->channels) out.insert(out.end(), c->columns.begin(), c->columns.end());
  return out;
}

std::vector<LogSeries> LogWriter::getRecentSamples(const std::vector<std::string>& columns, double afterTime,
                                                   std::size_t maxSamples) const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->keepRecent = true;
  if (!impl_->closed.load()) impl_->collect();  // include what the programs took since the last pass
  std::vector<LogSeries> out;
  for (const std::string& name : columns) {
    LogSeries series;
    series.column = name;
    bool found = false;
    for (std::size_t k = 0; k < impl_->channels.size() && !found; ++k) {
      const auto& c = impl_->channels[k];
      for (std::size_t i = 0; i < c->width && !found; ++i) {
        if (c->columns[i] != name) continue;
        found = true;
        const auto& history = impl_->recent[k];
        const std::size_t stride = c->width + 1, kept = history.size();
        // Newest samples after `afterTime`, oldest first.
        std::size_t first = kept;
        while (first > 0 && history.at(first - 1, stride)[0] > afterTime && kept - first < maxSamples) --first;
        for (std::size_t j = first; j < kept; ++j) {
          series.time.push_back(history.at(j, stride)[0]);
          series.value.push_back(history.at(j, stride)[i + 1]);
        }
      }
    }
    if (!found) throw std::invalid_argument("LogWriter " + impl_->fileName + ": no log column '" + name + "'");
    out.push_back(std::move(series));
  }
  return out;
}

void LogWriter::notify() { impl_->cv.notify_all(); }

void LogWriter::close() {
  if (std::this_thread::get_id() == impl_->threadId) return;  // from the failure handler: the writer ends itself
  std::lock_guard<std::mutex> closeLock(impl_->closeMutex);
  if (impl_->closed.load()) return;
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    impl_->stopping = true;
  }
  impl_->cv.notify_all();
  impl_->thread.join();  // the thread writes the last rows and completes the file
  std::uint64_t lost = 0;
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    for (auto& c : impl_->channels) lost += c->lost.load();
  }
  impl_->closed = true;
  if (lost > 0)
    std::fprintf(stderr, "rp: log %s: %llu samples lost because a ring buffer was full (raise logBufferSize)\n",
                 impl_->fileName.c_str(), static_cast<unsigned long long>(lost));
}

bool LogWriter::hasFailed() const { return impl_->failed.load(); }

std::string LogWriter::getError() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->error;
}

void LogWriter::setFailureHandler(std::function<void(const std::string& message)> handler) {
  std::string error;
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    impl_->onFailure = handler;
    if (!impl_->failed.load()) return;
    error = impl_->error;
  }
  if (handler) handler(error);  // it failed already
}

bool LogWriter::isClosed() const { return impl_->closed.load(); }
const std::string& LogWriter::fileName() const { return impl_->fileName; }
std::uint64_t LogWriter::getRowCount() const { return impl_->rows.load(); }

std::uint64_t LogWriter::getLostSamples() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  std::uint64_t lost = 0;
  for (auto& c : impl_->channels) lost += c->lost.load();
  return lost;
}

namespace {
std::mutex& platformMutex() {
  static auto* m = new std::mutex;
  return *m;
}
LogWriter*& platformWriter() {
  static LogWriter* w = nullptr;  // never deleted: programs may still hold the pointer
  return w;
}
}  // namespace

LogWriter* LogWriter::getPlatformWriter() {
  std::lock_guard<std::mutex> lock(platformMutex());
  return platformWriter();
}

void LogWriter::openPlatformWriter(const std::string& fileName) {
  std::lock_guard<std::mutex> lock(platformMutex());
  if (platformWriter() && !platformWriter()->isClosed())
    throw std::logic_error("LogWriter: the platform log is already open");
  platformWriter() = new LogWriter(fileName);
}

void LogWriter::closePlatformWriter() {
  LogWriter* w = getPlatformWriter();
  if (w) w->close();
}

bool LogWriter::hasPlatformWriterFailed() {
  LogWriter* w = getPlatformWriter();
  return w && w->hasFailed();
}

}  // namespace rp
