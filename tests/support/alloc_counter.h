#pragma once
// Heap-allocation counting for tests of the no-heap-after-init rule.
//
// A test executable that links sdpslam_alloc_counter replaces malloc, calloc, realloc,
// posix_memalign, aligned_alloc, memalign and free (and with them every operator new,
// which glibc's libstdc++ routes to malloc). Counting is off until a scope arms it:
//
//   sdpslam::test::AllocationScope scope;   // arms
//   filter.process(scan);                   // code under test
//   LONGS_EQUAL(0, scope.allocations());    // heap calls made while armed
//
// Not available under AddressSanitizer (which owns malloc); such tests are built with
// NO_SANITIZE and skipped in the sanitizer preset.
#include <cstddef>

namespace sdpslam::test {

// Total allocation calls (malloc family and operator new) seen while armed.
std::size_t allocation_count();
// Whether the replacement allocator is linked and active in this executable.
bool allocation_counting_active();

class AllocationScope {
 public:
  AllocationScope();
  ~AllocationScope();
  AllocationScope(const AllocationScope&) = delete;
  AllocationScope& operator=(const AllocationScope&) = delete;
  // Allocations since this scope was opened.
  std::size_t allocations() const;

 private:
  std::size_t start_;
};

}  // namespace sdpslam::test
