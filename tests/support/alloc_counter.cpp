// Replacement of glibc's allocation entry points in the test executable. The dynamic
// linker resolves libstdc++'s and CppUTest's calls to malloc to these definitions, which
// forward to glibc's own __libc_* implementations and count while armed.
#include "alloc_counter.h"

#include <atomic>
#include <cerrno>
#include <cstddef>

extern "C" {
void* __libc_malloc(size_t);
void* __libc_calloc(size_t, size_t);
void* __libc_realloc(void*, size_t);
void* __libc_memalign(size_t, size_t);
void __libc_free(void*);
}

namespace {
std::atomic<int> g_armed{0};
std::atomic<std::size_t> g_count{0};
std::atomic<bool> g_seen{false};

inline void note() {
  g_seen.store(true, std::memory_order_relaxed);
  if (g_armed.load(std::memory_order_relaxed) > 0) g_count.fetch_add(1, std::memory_order_relaxed);
}
}  // namespace

extern "C" {
void* malloc(size_t n) {
  note();
  return __libc_malloc(n);
}
void* calloc(size_t n, size_t m) {
  note();
  return __libc_calloc(n, m);
}
void* realloc(void* p, size_t n) {
  note();
  return __libc_realloc(p, n);
}
void* memalign(size_t a, size_t n) {
  note();
  return __libc_memalign(a, n);
}
void* aligned_alloc(size_t a, size_t n) {
  note();
  return __libc_memalign(a, n);
}
int posix_memalign(void** out, size_t a, size_t n) {
  note();
  if (a < sizeof(void*) || (a & (a - 1)) != 0) return EINVAL;
  void* p = __libc_memalign(a, n);
  if (p == nullptr) return ENOMEM;
  *out = p;
  return 0;
}
void free(void* p) { __libc_free(p); }
}

namespace sdpslam::test {

std::size_t allocation_count() { return g_count.load(); }

bool allocation_counting_active() {
  // Make one allocation through the normal path and see whether it was observed here.
  g_seen.store(false);
  void* volatile p = ::malloc(1);
  ::free(p);
  return g_seen.load();
}

AllocationScope::AllocationScope() : start_(g_count.load()) { g_armed.fetch_add(1); }
AllocationScope::~AllocationScope() { g_armed.fetch_sub(1); }
std::size_t AllocationScope::allocations() const { return g_count.load() - start_; }

}  // namespace sdpslam::test
