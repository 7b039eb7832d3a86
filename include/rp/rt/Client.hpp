#pragma once
/// @file
/// Client: sends typed requests to a Server and waits for the replies (paper section 3.7).

#include <chrono>

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
    return server_.post(std::move(request), deadline).get(deadline);
  }
  /// Sends a request without waiting for the reply.
  /// @param[in] request  the request
  /// @param[in] timeout  longest wait for room in the queue
  /// @return the reply to come (PendingReply::get() waits for it)
  /// @throws CommunicationError (Timeout, ServerStopped)
  PendingReply<Reply> send(Request request, std::chrono::milliseconds timeout = std::chrono::milliseconds(1000)) {
    return server_.post(std::move(request), std::chrono::steady_clock::now() + timeout);
  }

 private:
  Server<Request, Reply>& server_;
};

}  // namespace rp
