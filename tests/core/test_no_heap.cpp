// Proves that the allocation-counting harness sees heap use (so that a "zero
// allocations" assertion elsewhere means something), and that the core's containers do
// not allocate once set up.
#include <CppUTest/TestHarness.h>

#include <cstdlib>
#include <memory>
#include <vector>

#include "alloc_counter.h"
#include "sdpslam/core/arena.h"
#include "sdpslam/core/pool.h"
#include "sdpslam/core/ring_buffer.h"
#include "sdpslam/core/static_vector.h"

namespace {
// Keeps the optimiser from eliding an allocation/release pair (allowed since C++14).
void escape(const void* p) { asm volatile("" : : "g"(p) : "memory"); }
}  // namespace

TEST_GROUP(NoHeap){};

TEST(NoHeap, harness_is_active) { CHECK_TRUE(sdpslam::test::allocation_counting_active()); }

TEST(NoHeap, harness_counts_operator_new_and_malloc) {
  sdpslam::test::AllocationScope scope;
  auto p = std::make_unique<int>(3);
  void* m = std::malloc(16);
  std::vector<int> v(10);
  escape(p.get());
  escape(m);
  escape(v.data());
  std::free(m);
  CHECK(scope.allocations() >= 3U);
}

TEST(NoHeap, pools_vectors_rings_and_arena_never_allocate) {
  alignas(16) static unsigned char buffer[1 << 16];
  static sdpslam::Pool<double, 128> pool;
  sdpslam::test::AllocationScope scope;
  sdpslam::Arena arena(buffer, sizeof buffer);
  sdpslam::ArenaPool<int> apool;
  CHECK_TRUE(apool.init(arena, 100));
  sdpslam::StaticVector<int, 64> vec;
  sdpslam::RingBuffer<int, 16> ring;
  for (int i = 0; i < 1000; ++i) {
    double* d = pool.create(1.0 * i);
    int* x = apool.create(i);
    vec.push_back(i);
    ring.push_overwrite(i);
    pool.destroy(d);
    apool.destroy(x);
  }
  LONGS_EQUAL(0, scope.allocations());
}
