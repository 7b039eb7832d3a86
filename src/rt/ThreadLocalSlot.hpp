// Storage for one object per thread, made in place (internal): for the servo cycle's scratch,
// which an executor stepping hundreds of programs in one thread keeps in that thread's caches
// (ThreadWorkspace.hpp, ManipulatorSimulation's step scratch).
#pragma once

#include <new>
#include <type_traits>
#include <utility>

namespace rp::internal {

// Raw storage for a T and the T made in it. Declared `thread_local`, it is part of the thread's
// thread-local block: making the object allocates nothing. The slot is trivially destructible, so
// the thread-local needs no exit handler (registering one allocates) and the object is never
// destroyed at thread exit: T must own no heap memory, or its owner must accept the leak.
template <typename T>
class ThreadLocalSlot {
 public:
  // The object, or null before the first make().
  T* get() const noexcept { return object_; }

  // Makes the object in place from `args` (destroying the one made before, if any).
  template <typename... Args>
  T& make(Args&&... args) noexcept(std::is_nothrow_constructible_v<T, Args...>) {
    if (object_ != nullptr) object_->~T();
    object_ = new (bytes_) T(std::forward<Args>(args)...);
    return *object_;
  }

  // The object, made with T() on first use.
  T& getOrMake() noexcept(std::is_nothrow_default_constructible_v<T>) {
    return object_ != nullptr ? *object_ : make();
  }

 private:
  alignas(T) unsigned char bytes_[sizeof(T)];
  T* object_ = nullptr;
};

}  // namespace rp::internal
