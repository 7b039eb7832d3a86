// LogWriter: drains the programs' ring buffers in a non-real-time thread and writes one CSV file.
#include "rp/rt/LogWriter.hpp"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

#include "LogChannel.hpp"

namespace rp {

namespace {

struct Row {
  std::vector<double> values;
  std::vector<char> present;
};

void appendNumber(std::string& out, double v) {
  char buf[32];
  auto [ptr, ec] = std::to_chars(buf, buf + sizeof buf, v);  // shortest text that reads back exactly
  out.append(buf, ec == std::errc() ? ptr : buf);
}

}  // namespace

struct LogWriter::Impl {
  std::string fileName, partName;
  std::FILE* part = nullptr;
  std::mutex mutex;  // channels, staging, file
  std::condition_variable cv;
  std::vector<std::shared_ptr<Channel>> channels;
  std::size_t totalColumns = 0;
  std::map<double, Row> staging;
  std::thread thread;
  bool stopping = false;
  std::mutex closeMutex;
  std::atomic<bool> closed{false};
  std::atomic<std::uint64_t> rows{0};
  bool logging = true;  // with `mutex`: samples drained while false are not written to the file
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

  // With `mutex` held: moves every available sample into `staging`, then writes the rows no
  // program can add to any more (all times up to the slowest running program's last sample).
  void drain(bool all) {
    for (std::size_t k = 0; k < channels.size(); ++k) {
      auto& c = channels[k];
      while (const double* s = c->front()) {
        if (keepRecent) {
          History& history = recent[k];
          const std::size_t stride = c->width + 1;
          if (history.samples.empty()) history.samples.resize(LogWriter::kRecentSamples * stride);
          std::copy(s, s + stride, &history.samples[(history.count++ % LogWriter::kRecentSamples) * stride]);
        }
        if (!logging) {  // stopped: the sample is only kept for the plots
          c->lastTime = s[0];
          c->any = true;
          c->pop();
          continue;
        }
        Row& row = staging[s[0]];
        if (row.values.size() < totalColumns) {
          row.values.resize(totalColumns, 0.0);
          row.present.resize(totalColumns, 0);
        }
        for (std::size_t i = 0; i < c->width; ++i) {
          row.values[c->firstColumn + i] = s[i + 1];
          row.present[c->firstColumn + i] = 1;
        }
        c->lastTime = s[0];
        c->any = true;
        c->pop();
      }
    }
    double watermark = std::numeric_limits<double>::infinity();
    if (!all)
      for (auto& c : channels)
        if (c->any && !c->finished.load()) watermark = std::min(watermark, c->lastTime);
    std::string line;
    while (!staging.empty() && staging.begin()->first <= watermark) {
      auto node = staging.extract(staging.begin());
      line.clear();
      appendNumber(line, node.key());
      const Row& row = node.mapped();
      for (std::size_t i = 0; i < row.values.size(); ++i) {
        line += ',';
        if (row.present[i]) appendNumber(line, row.values[i]);
      }
      line += '\n';
      std::fwrite(line.data(), 1, line.size(), part);
      rows.fetch_add(1);
    }
  }

  void run() {
    std::unique_lock<std::mutex> lock(mutex);
    while (!stopping) {
      cv.wait_for(lock, std::chrono::milliseconds(20));
      drain(false);
    }
  }
};

LogWriter::LogWriter(const std::string& fileName) : impl_(std::make_unique<Impl>()) {
  impl_->fileName = fileName;
  impl_->partName = fileName + ".part";
  impl_->part = std::fopen(impl_->partName.c_str(), "w");
  if (!impl_->part) throw std::runtime_error("LogWriter: cannot create '" + impl_->partName + "'");
  impl_->thread = std::thread([this] { impl_->run(); });
}

LogWriter::~LogWriter() { close(); }

void LogWriter::addChannel(const std::shared_ptr<Channel>& channel) {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  if (impl_->closed.load()) return;
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
  impl_->drain(false);  // what was taken before this call goes to the file
  impl_->logging = false;
}

void LogWriter::startLogging() {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  if (impl_->closed.load() || impl_->logging) return;
  impl_->drain(false);  // what was taken while stopped stays out of the file
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
  if (!impl_->closed.load()) impl_->drain(false);  // include what the programs took since the last pass
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
  std::lock_guard<std::mutex> closeLock(impl_->closeMutex);
  if (impl_->closed.load()) return;
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    impl_->stopping = true;
  }
  impl_->cv.notify_all();
  impl_->thread.join();
  std::vector<std::string> header{"t"};
  std::uint64_t lost = 0;
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    impl_->drain(true);
    std::fclose(impl_->part);
    impl_->part = nullptr;
    for (auto& c : impl_->channels) {
      header.insert(header.end(), c->columns.begin(), c->columns.end());
      lost += c->lost.load();
    }
    impl_->closed = true;
  }
  // The complete file: the header with every column, then the rows padded to full width.
  const std::string tmp = impl_->fileName + ".tmp";
  {
    std::ifstream in(impl_->partName);
    std::ofstream out(tmp);
    std::string line;
    for (std::size_t i = 0; i < header.size(); ++i) line += (i ? "," : "") + header[i];
    out << line << '\n';
    while (std::getline(in, line)) {
      std::size_t fields = 1;
      for (char ch : line) fields += ch == ',';
      if (fields < header.size()) line.append(header.size() - fields, ',');
      out << line << '\n';
    }
    out.flush();
    if (!out) std::fprintf(stderr, "rp: log %s: write error\n", impl_->fileName.c_str());
  }
  std::rename(tmp.c_str(), impl_->fileName.c_str());
  std::remove(impl_->partName.c_str());
  if (lost > 0)
    std::fprintf(stderr, "rp: log %s: %llu samples lost because a ring buffer was full (raise logBufferSize)\n",
                 impl_->fileName.c_str(), static_cast<unsigned long long>(lost));
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

}  // namespace rp
