#pragma once
// Counts heap allocations made by the calling thread, so tests can prove that real-time code paths
// do not allocate (in the spirit of Drake's LimitMalloc). Link AllocationCounter.cpp into the test
// binary. It counts every malloc-family call (operator new and Eigen both end there): by replacing
// malloc in a normal build, and through the sanitizer allocator hooks under ASan or TSan.
#include <cstddef>

namespace rp::test {

// Number of heap allocations made by this thread so far.
std::size_t allocationCount();

// Counts the allocations made by this thread between construction and count().
class AllocationGuard {
 public:
  AllocationGuard() : start_(allocationCount()) {}
  std::size_t count() const { return allocationCount() - start_; }

 private:
  std::size_t start_;
};

}  // namespace rp::test
