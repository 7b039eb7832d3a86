// The pool of result buffers of the batched calls (ResultBuffers.hpp).
#include "ResultBuffers.hpp"

#include <cstdlib>
#include <deque>
#include <mutex>
#include <new>

namespace rp::python {

namespace {

constexpr std::size_t kSmallestKept = std::size_t{1} << 20;

struct Buffer {
  void* data;
  std::size_t capacity;
};

// Freed buffers, oldest first. Never destroyed: an array can outlive the module's teardown at exit.
struct Pool {
  std::mutex mutex;
  std::deque<Buffer> kept;
  std::size_t bytes = 0;
};

Pool& pool() {
  static Pool* const p = new Pool;
  return *p;
}

// A kept buffer of `bytes` to at most twice that, else a new one.
Buffer take(std::size_t bytes) {
  {
    Pool& p = pool();
    const std::scoped_lock lock(p.mutex);
    auto best = p.kept.end();
    for (auto it = p.kept.begin(); it != p.kept.end(); ++it) {
      if (it->capacity >= bytes && it->capacity / 2 <= bytes && (best == p.kept.end() || it->capacity < best->capacity))
        best = it;
    }
    if (best != p.kept.end()) {
      const Buffer b = *best;
      p.kept.erase(best);
      p.bytes -= b.capacity;
      return b;
    }
  }
  void* data = std::malloc(bytes);
  if (data == nullptr) throw std::bad_alloc();
  return {data, bytes};
}

void give(Buffer b) {
  Pool& p = pool();
  const std::scoped_lock lock(p.mutex);
  if (b.capacity > kKeptResultBytes) {
    std::free(b.data);
    return;
  }
  while (p.bytes + b.capacity > kKeptResultBytes) {
    std::free(p.kept.front().data);
    p.bytes -= p.kept.front().capacity;
    p.kept.pop_front();
  }
  p.kept.push_back(b);
  p.bytes += b.capacity;
}

}  // namespace

py::array_t<double> newResultArray(const std::vector<py::ssize_t>& shape) {
  std::size_t bytes = sizeof(double);
  for (py::ssize_t extent : shape) bytes *= static_cast<std::size_t>(extent);
  if (bytes < kSmallestKept) return py::array_t<double>(shape);
  auto* owner = new Buffer(take(bytes));
  py::capsule base(owner, [](void* p) {
    auto* b = static_cast<Buffer*>(p);
    give(*b);
    delete b;
  });
  return py::array_t<double>(shape, static_cast<double*>(owner->data), base);
}

std::size_t keptResultBytes() {
  Pool& p = pool();
  const std::scoped_lock lock(p.mutex);
  return p.bytes;
}

}  // namespace rp::python
