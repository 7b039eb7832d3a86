#pragma once
/// @file
/// Server: typed request/reply message passing between threads (paper section 3.7).

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <optional>
#include <string>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <thread>

namespace rp {

/// Error of Client/Server message passing.
class CommunicationError : public std::runtime_error {
 public:
  /// What went wrong.
  enum class Kind {
    Timeout,        ///< no room in the queue or no reply in time
    ServerStopped,  ///< the server stopped (or was never started) before replying
    HandlerFailed,  ///< the server's handler threw; the message is its what()
  };
  /// Creates the error.
  /// @param[in] kind     what went wrong
  /// @param[in] message  description
  CommunicationError(Kind kind, const std::string& message) : std::runtime_error(message), kind_(kind) {}
  /// What went wrong.
  Kind kind() const noexcept { return kind_; }

 private:
  Kind kind_;
};

/// The reply to a request sent with Client::send(), available later.
/// @tparam Reply  reply type
template <typename Reply>
class PendingReply {
 public:
  /// @cond INTERNAL
  struct Slot {
    std::mutex mutex;
    std::condition_variable cv;
    bool ready = false;
    std::optional<Reply> value;
    CommunicationError::Kind kind = CommunicationError::Kind::ServerStopped;
    std::string error;
    void setValue(Reply v) {
      {
        std::lock_guard<std::mutex> lock(mutex);
        value.emplace(std::move(v));
        ready = true;
      }
      cv.notify_all();
    }
    void setError(CommunicationError::Kind k, std::string message) {
      {
        std::lock_guard<std::mutex> lock(mutex);
        kind = k;
        error = std::move(message);
        ready = true;
      }
      cv.notify_all();
    }
  };
  explicit PendingReply(std::shared_ptr<Slot> slot) : slot_(std::move(slot)) {}
  /// @endcond

  /// Whether the reply (or an error) has arrived.
  bool isReady() const {
    std::lock_guard<std::mutex> lock(slot_->mutex);
    return slot_->ready;
  }
  /// Waits for the reply until `deadline`.
  /// @param[in] deadline  latest time to wait until
  /// @return the reply
  /// @throws CommunicationError (Timeout, ServerStopped, HandlerFailed)
  Reply get(std::chrono::steady_clock::time_point deadline) {
    std::unique_lock<std::mutex> lock(slot_->mutex);
    if (!slot_->cv.wait_until(lock, deadline, [&] { return slot_->ready; }))
      throw CommunicationError(CommunicationError::Kind::Timeout, "Client: no reply within the timeout");
    if (!slot_->value) throw CommunicationError(slot_->kind, slot_->error);  // a fresh copy for this thread
    return *slot_->value;
  }
  /// Waits for the reply at most `timeout`.
  /// @param[in] timeout  longest wait
  /// @return the reply
  /// @throws CommunicationError (Timeout, ServerStopped, HandlerFailed)
  Reply get(std::chrono::milliseconds timeout = std::chrono::milliseconds(1000)) {
    return get(std::chrono::steady_clock::now() + timeout);
  }

 private:
  std::shared_ptr<Slot> slot_;
};

/// Serves requests of type `Request` with replies of type `Reply` in its own thread, one at a
/// time, in arrival order, from a bounded queue. Clients call it through Client.
/// @tparam Request  request type (copyable or movable)
/// @tparam Reply    reply type
template <typename Request, typename Reply>
class Server {
 public:
  /// The function that answers a request (runs in the server thread).
  using Handler = std::function<Reply(const Request&)>;

  /// Creates a stopped server.
  /// @param[in] queueCapacity  most requests waiting at once (>= 1)
  explicit Server(std::size_t queueCapacity = 64) : capacity_(queueCapacity == 0 ? 1 : queueCapacity) {}
  /// Stops the server.
  ~Server() { stop(); }
  Server(const Server&) = delete;             ///< not copyable
  Server& operator=(const Server&) = delete;  ///< not copyable

  /// Starts the server thread.
  /// @param[in] handler  computes the reply of a request; an exception it throws goes to the client
  /// @throws std::logic_error if already running
  void start(Handler handler) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (running_) throw std::logic_error("Server::start: already running");
    handler_ = std::move(handler);
    running_ = true;
    stopping_ = false;
    thread_ = std::thread([this] { serve(); });
  }
  /// Stops accepting requests, finishes the one being served, fails the queued ones with
  /// ServerStopped and joins the thread. Idempotent.
  void stop() {
    std::deque<std::shared_ptr<Pending>> dropped;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!running_) return;
      stopping_ = true;
      dropped.swap(queue_);
    }
    cv_.notify_all();
    if (thread_.joinable()) thread_.join();
    for (auto& p : dropped)
      p->slot->setError(CommunicationError::Kind::ServerStopped, "Server: stopped before serving the request");
    std::lock_guard<std::mutex> lock(mutex_);
    running_ = false;
  }
  /// Whether the server thread runs.
  bool isRunning() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return running_ && !stopping_;
  }
  /// Number of requests waiting.
  std::size_t getQueueLength() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return queue_.size();
  }

  /// @cond INTERNAL
  struct Pending {
    Request request;
    std::shared_ptr<typename PendingReply<Reply>::Slot> slot;
  };
  // Queues a request, waiting until `deadline` for room. Used by Client.
  PendingReply<Reply> post(Request request, std::chrono::steady_clock::time_point deadline) {
    auto slot = std::make_shared<typename PendingReply<Reply>::Slot>();
    auto pending = std::make_shared<Pending>(Pending{std::move(request), slot});
    std::unique_lock<std::mutex> lock(mutex_);
    if (!running_ || stopping_)
      throw CommunicationError(CommunicationError::Kind::ServerStopped, "Client: the server is not running");
    if (!space_.wait_until(lock, deadline, [&] { return queue_.size() < capacity_ || stopping_; }))
      throw CommunicationError(CommunicationError::Kind::Timeout, "Client: the server's queue stayed full");
    if (stopping_) throw CommunicationError(CommunicationError::Kind::ServerStopped, "Client: the server stopped");
    queue_.push_back(std::move(pending));
    lock.unlock();
    cv_.notify_one();
    return PendingReply<Reply>(slot);
  }
  /// @endcond

 private:
  void serve() {
    for (;;) {
      std::shared_ptr<Pending> p;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        cv_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
        if (stopping_) {
          space_.notify_all();
          return;
        }
        p = std::move(queue_.front());
        queue_.pop_front();
      }
      space_.notify_one();
      // Errors cross threads as plain strings (never as a shared exception object).
      try {
        p->slot->setValue(handler_(p->request));
      } catch (const std::exception& e) {
        p->slot->setError(CommunicationError::Kind::HandlerFailed, e.what());
      } catch (...) {
        p->slot->setError(CommunicationError::Kind::HandlerFailed, "Server: the handler threw");
      }
    }
  }

  const std::size_t capacity_;
  mutable std::mutex mutex_;
  std::condition_variable cv_, space_;
  std::deque<std::shared_ptr<Pending>> queue_;
  Handler handler_;
  std::thread thread_;
  bool running_ = false;
  bool stopping_ = false;
};

}  // namespace rp
