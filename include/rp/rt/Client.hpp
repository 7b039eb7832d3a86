#pragma once
/// @file
/// Client: sends typed requests to a Server and waits for the replies (paper section 3.7).

#include <chrono>
#include <future>

#include "rp/rt/Server.hpp"

namespace rp {

/// Calls a Server<Request, Reply> from any thread.
/// @tparam Request  request type
/// @tparam Reply    reply type
template <typename Request, typename Reply>
class Client {
 public:
  /// Connects to `server` (which must outlive the client).
  /// @param[in] server  the server
  explicit Client(Server<Request, Reply>& server) : server_(server) {}

  /// Sends a request and waits for the reply.
  /// @param[in] request  the request
  /// @param[in] timeout  longest total wait for room in the queue and for the reply
  /// @return the server's reply
  /// @throws CommunicationError (Timeout, ServerStopped, HandlerFailed)
  /// Real-time safe: no.
  Reply call(Request request, std::chrono::milliseconds timeout = std::chrono::milliseconds(1000)) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    std::future<Reply> reply = server_.post(std::move(request), deadline);
    if (reply.wait_until(deadline) != std::future_status::ready)
      throw CommunicationError(CommunicationError::Kind::Timeout, "Client: no reply within the timeout");
    return reply.get();
  }
  /// Sends a request without waiting for the reply.
  /// @param[in] request  the request
  /// @param[in] timeout  longest wait for room in the queue
  /// @return the future reply
  /// @throws CommunicationError (Timeout, ServerStopped)
  std::future<Reply> send(Request request, std::chrono::milliseconds timeout = std::chrono::milliseconds(1000)) {
    return server_.post(std::move(request), std::chrono::steady_clock::now() + timeout);
  }

 private:
  Server<Request, Reply>& server_;
};

}  // namespace rp
