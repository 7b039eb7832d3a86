// Barrier, ReaderWriterLock, Client/Server and TripleBuffer (run under ThreadSanitizer).
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <shared_mutex>
#include <string>
#include <thread>
#include <vector>

#include "rp/rt/Barrier.hpp"
#include "rp/rt/Client.hpp"
#include "rp/rt/ReaderWriterLock.hpp"
#include "rp/rt/Server.hpp"
#include "rp/rt/TripleBuffer.hpp"

namespace rp {
namespace {

using namespace std::chrono_literals;

TEST(BarrierThreads, NoThreadStartsARoundBeforeAllFinishedThePrevious) {
  constexpr int kThreads = 4, kRounds = 200;
  Barrier barrier(kThreads);
  std::atomic<int> arrived{0};
  std::atomic<int> serial{0};
  std::atomic<bool> violated{false};
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t)
    threads.emplace_back([&] {
      for (int r = 0; r < kRounds; ++r) {
        arrived.fetch_add(1);
        if (barrier.wait()) serial.fetch_add(1);
        // Everyone of round r has arrived before anyone leaves it.
        if (arrived.load() < (r + 1) * kThreads) violated = true;
        barrier.wait();
      }
    });
  for (auto& th : threads) th.join();
  EXPECT_FALSE(violated);
  EXPECT_EQ(serial.load(), kRounds);
  EXPECT_EQ(barrier.getCount(), 4u);
  EXPECT_THROW(Barrier(0), std::invalid_argument);
}

TEST(ReaderWriterLockThreads, WritersAreExclusive) {
  ReaderWriterLock lock;
  long a = 0, b = 0;  // invariant under the lock: a == b
  std::atomic<bool> broken{false};
  std::vector<std::thread> threads;
  for (int t = 0; t < 2; ++t)
    threads.emplace_back([&] {
      for (int i = 0; i < 2000; ++i) {
        WriteGuard g(lock);
        ++a;
        ++b;
      }
    });
  for (int t = 0; t < 3; ++t)
    threads.emplace_back([&] {
      for (int i = 0; i < 2000; ++i) {
        ReadGuard g(lock);
        if (a != b) broken = true;
      }
    });
  for (auto& th : threads) th.join();
  EXPECT_FALSE(broken);
  EXPECT_EQ(a, 4000);
  // Readers share; a writer excludes them.
  ASSERT_TRUE(lock.tryReadLock());
  EXPECT_TRUE(lock.tryReadLock());
  EXPECT_FALSE(lock.tryWriteLock());
  lock.readUnlock();
  lock.readUnlock();
  ASSERT_TRUE(lock.tryWriteLock());
  EXPECT_FALSE(lock.tryReadLock());
  lock.writeUnlock();
  { std::shared_lock<ReaderWriterLock> s(lock); }
  { std::unique_lock<ReaderWriterLock> u(lock); }
}

TEST(ClientServerThreads, RequestsAndReplies) {
  Server<int, std::string> server(4);
  server.start([](const int& x) { return std::to_string(x * x); });
  EXPECT_TRUE(server.isRunning());
  std::vector<std::thread> clients;
  std::atomic<int> correct{0};
  for (int t = 0; t < 4; ++t)
    clients.emplace_back([&, t] {
      Client<int, std::string> client(server);
      for (int i = 0; i < 100; ++i)
        if (client.call(t * 100 + i, 10s) == std::to_string((t * 100 + i) * (t * 100 + i))) ++correct;
    });
  for (auto& c : clients) c.join();
  EXPECT_EQ(correct.load(), 400);
  server.stop();
  EXPECT_FALSE(server.isRunning());
  Client<int, std::string> client(server);
  try {
    client.call(1);
    FAIL();
  } catch (const CommunicationError& e) {
    EXPECT_EQ(e.kind(), CommunicationError::Kind::ServerStopped);
  }
}

TEST(ClientServerThreads, TimeoutsFullQueueHandlerErrorsAndCleanStop) {
  Server<int, int> server(1);
  std::mutex gate;
  gate.lock();  // the handler blocks until the test opens the gate
  server.start([&](const int& x) {
    if (x < 0) throw std::runtime_error("negative request");
    std::lock_guard<std::mutex> g(gate);
    return x + 1;
  });
  Client<int, int> client(server);
  PendingReply<int> first = client.send(1);  // taken by the server, blocked in the handler
  while (server.getQueueLength() != 0) std::this_thread::yield();
  PendingReply<int> queued = client.send(2);  // fills the queue (capacity 1)
  try {
    client.call(3, 20ms);  // no room
    FAIL();
  } catch (const CommunicationError& e) {
    EXPECT_EQ(e.kind(), CommunicationError::Kind::Timeout);
    EXPECT_STREQ(e.what(), "Client: the server's queue stayed full");
  }
  EXPECT_FALSE(first.isReady());
  gate.unlock();
  EXPECT_EQ(first.get(10s), 2);
  EXPECT_EQ(queued.get(10s), 3);
  EXPECT_TRUE(first.isReady());
  try {
    client.call(-1);
    FAIL();
  } catch (const CommunicationError& e) {
    EXPECT_EQ(e.kind(), CommunicationError::Kind::HandlerFailed);
    EXPECT_STREQ(e.what(), "negative request");
  }
  // No reply in time.
  gate.lock();
  try {
    client.call(5, 20ms);
    FAIL();
  } catch (const CommunicationError& e) {
    EXPECT_EQ(e.kind(), CommunicationError::Kind::Timeout);
    EXPECT_STREQ(e.what(), "Client: no reply within the timeout");
  }
  PendingReply<int> dropped = client.send(6);
  std::thread stopper([&] { server.stop(); });
  while (server.isRunning()) std::this_thread::sleep_for(1ms);  // stop() has taken the queue
  gate.unlock();  // let the request being served finish; the queued one is failed
  stopper.join();
  try {
    dropped.get();
    FAIL();
  } catch (const CommunicationError& e) {
    EXPECT_EQ(e.kind(), CommunicationError::Kind::ServerStopped);
  }
}

struct Pair {
  long a = 0, b = 0;  // b == 2 * a in every published value
};

// A reader of `buffer` until `done`: flags a torn value (b != 2 a) and one older than the last.
void readUntilDone(const TripleBuffer<Pair>& buffer, const std::atomic<bool>& done, std::atomic<bool>& torn,
                   std::atomic<bool>& backwards) {
  long last = 0;
  Pair v;
  while (!done) {
    if (!buffer.read(v)) continue;
    if (v.b != 2 * v.a) torn = true;
    if (v.a < last) backwards = true;
    last = v.a;
  }
}

TEST(TripleBufferThreads, ReadersSeeWholeValuesInOrder) {
  TripleBuffer<Pair> buffer;
  Pair p;
  EXPECT_FALSE(buffer.read(p));
  std::atomic<bool> done{false};
  std::thread writer([&] {
    for (long i = 1; i <= 50000; ++i) buffer.write(Pair{i, 2 * i});
    done = true;
  });
  std::vector<std::thread> readers;
  std::atomic<bool> torn{false}, backwards{false};
  for (int r = 0; r < 2; ++r) readers.emplace_back([&] { readUntilDone(buffer, done, torn, backwards); });
  writer.join();
  for (auto& r : readers) r.join();
  EXPECT_FALSE(torn);
  EXPECT_FALSE(backwards);
  ASSERT_TRUE(buffer.read(p));
  EXPECT_EQ(p.a, 50000);
}

// update() fills the buffer in place (an arm publishes its n joints of arrays sized for the most
// joints so): readers see whole values in order, and the fields it leaves alone keep what they
// had (the buffer it fills holds an older value, not a fresh one).
TEST(TripleBufferThreads, ValuesUpdatedInPlaceAreWholeAndInOrder) {
  TripleBuffer<Pair> buffer;
  std::atomic<bool> done{false};
  std::thread writer([&] {
    for (long i = 1; i <= 50000; ++i)
      buffer.update([i](Pair& p) noexcept {
        p.a = i;
        p.b = 2 * i;
      });
    done = true;
  });
  std::atomic<bool> torn{false}, backwards{false};
  std::thread reader([&] { readUntilDone(buffer, done, torn, backwards); });
  writer.join();
  reader.join();
  EXPECT_FALSE(torn);
  EXPECT_FALSE(backwards);
  Pair p;
  ASSERT_TRUE(buffer.read(p));
  EXPECT_EQ(p.a, 50000);
  // A field update() does not set: what the buffer held. Each of the three buffers had b set.
  for (int k = 0; k < 3; ++k) buffer.update([](Pair& q) noexcept { q.a = -1; });
  ASSERT_TRUE(buffer.read(p));
  EXPECT_EQ(p.a, -1);
  EXPECT_GT(p.b, 0) << "update() handed a buffer that was not the one written before";
}

// The one reader of readAsOnlyReader() (no lock): whole values, in order, and the last one.
TEST(TripleBufferThreads, TheOnlyReaderSeesWholeValuesInOrderWithoutALock) {
  TripleBuffer<Pair> buffer;
  Pair p;
  EXPECT_FALSE(buffer.readAsOnlyReader(p));
  std::atomic<bool> reading{false};
  bool torn = false, backwards = false;
  long seen = 0;
  long last = 0;
  std::thread reader([&] {  // until it has the last value (or 20 s have passed)
    const auto deadline = std::chrono::steady_clock::now() + 20s;
    Pair v;
    reading = true;
    while (last != 50000 && std::chrono::steady_clock::now() < deadline) {
      if (!buffer.readAsOnlyReader(v)) continue;
      if (v.b != 2 * v.a) torn = true;
      if (v.a < last) backwards = true;
      if (v.a != last) ++seen;
      last = v.a;
    }
  });
  while (!reading) std::this_thread::yield();
  for (long i = 1; i <= 50000; ++i) buffer.write(Pair{i, 2 * i});
  reader.join();
  EXPECT_EQ(last, 50000) << "the reader never had the last value";
  EXPECT_FALSE(torn);
  EXPECT_FALSE(backwards);
  EXPECT_GT(seen, 0);
  ASSERT_TRUE(buffer.readAsOnlyReader(p));
  EXPECT_EQ(p.a, 50000);
}

}  // namespace
}  // namespace rp
