#pragma once
/// @file
/// ReaderWriterLock: many readers or one writer (paper section 3.7).

#include <shared_mutex>

namespace rp {

/// A lock held by any number of readers at once or by one writer alone. Also meets the
/// standard SharedMutex requirements, so `std::shared_lock` and `std::unique_lock` work on it.
/// Real-time safe: no (it blocks); never use it between a servo thread and other threads.
class ReaderWriterLock {
 public:
  /// Waits until no writer holds the lock, then holds it for reading.
  void readLock() { m_.lock_shared(); }
  /// Releases a read hold.
  void readUnlock() { m_.unlock_shared(); }
  /// Holds the lock for reading if possible without waiting.
  /// @return true if acquired
  bool tryReadLock() { return m_.try_lock_shared(); }
  /// Waits until nobody holds the lock, then holds it for writing.
  void writeLock() { m_.lock(); }
  /// Releases the write hold.
  void writeUnlock() { m_.unlock(); }
  /// Holds the lock for writing if possible without waiting.
  /// @return true if acquired
  bool tryWriteLock() { return m_.try_lock(); }

  /// Same as writeLock() (SharedMutex requirement).
  void lock() { writeLock(); }
  /// Same as writeUnlock().
  void unlock() { writeUnlock(); }
  /// Same as tryWriteLock().
  /// @return true if acquired
  bool try_lock() { return tryWriteLock(); }
  /// Same as readLock().
  void lock_shared() { readLock(); }
  /// Same as readUnlock().
  void unlock_shared() { readUnlock(); }
  /// Same as tryReadLock().
  /// @return true if acquired
  bool try_lock_shared() { return tryReadLock(); }

 private:
  std::shared_mutex m_;
};

/// Holds a ReaderWriterLock for reading for the lifetime of the guard.
class ReadGuard {
 public:
  /// Acquires `lock` for reading.
  /// @param[in] lock  the lock
  explicit ReadGuard(ReaderWriterLock& lock) : lock_(lock) { lock_.readLock(); }
  ~ReadGuard() { lock_.readUnlock(); }
  ReadGuard(const ReadGuard&) = delete;             ///< not copyable
  ReadGuard& operator=(const ReadGuard&) = delete;  ///< not copyable

 private:
  ReaderWriterLock& lock_;
};

/// Holds a ReaderWriterLock for writing for the lifetime of the guard.
class WriteGuard {
 public:
  /// Acquires `lock` for writing.
  /// @param[in] lock  the lock
  explicit WriteGuard(ReaderWriterLock& lock) : lock_(lock) { lock_.writeLock(); }
  ~WriteGuard() { lock_.writeUnlock(); }
  WriteGuard(const WriteGuard&) = delete;             ///< not copyable
  WriteGuard& operator=(const WriteGuard&) = delete;  ///< not copyable

 private:
  ReaderWriterLock& lock_;
};

}  // namespace rp
