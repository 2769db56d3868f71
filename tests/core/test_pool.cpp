#include <CppUTest/TestHarness.h>

#include <cstdint>

#include "sdpslam/core/arena.h"
#include "sdpslam/core/pool.h"
#include "sdpslam/core/state_io.h"
#include "memory_state.h"

namespace {

struct Node {
  int value;
  std::uint32_t link;
  explicit Node(int v = 0) : value(v), link(0U) { ++live; }
  ~Node() { --live; }
  static int live;
};
int Node::live = 0;

// Deterministic xorshift for the randomised invariant test.
struct Rng {
  std::uint64_t s = 0x9E3779B97F4A7C15ULL;
  std::uint32_t next() {
    s ^= s << 13U;
    s ^= s >> 7U;
    s ^= s << 17U;
    return static_cast<std::uint32_t>(s >> 32U);
  }
};

}  // namespace

TEST_GROUP(Pool) {
  void setup() override { Node::live = 0; }
};

TEST(Pool, new_pool_is_empty_with_full_capacity) {
  static sdpslam::Pool<Node, 4> pool;
  LONGS_EQUAL(4, pool.capacity());
  LONGS_EQUAL(0, pool.size());
  LONGS_EQUAL(4, pool.available());
  CHECK_TRUE(pool.empty());
  CHECK_FALSE(pool.full());
  CHECK_TRUE(pool.invariants_hold());
}

TEST(Pool, create_constructs_and_destroy_destructs) {
  sdpslam::Pool<Node, 4> pool;
  Node* n = pool.create(42);
  CHECK(n != nullptr);
  LONGS_EQUAL(42, n->value);
  LONGS_EQUAL(1, Node::live);
  CHECK_TRUE(pool.owns(n));
  CHECK_TRUE(pool.destroy(n));
  LONGS_EQUAL(0, Node::live);
  CHECK_FALSE(pool.owns(n));
  CHECK_TRUE(pool.invariants_hold());
}

TEST(Pool, exhaustion_returns_null_and_counts) {
  sdpslam::Pool<Node, 3> pool;
  for (int i = 0; i < 3; ++i) CHECK(pool.create(i) != nullptr);
  CHECK_TRUE(pool.full());
  POINTERS_EQUAL(nullptr, pool.create(99));
  POINTERS_EQUAL(nullptr, pool.allocate());
  LONGS_EQUAL(2, pool.oom_count());
  LONGS_EQUAL(3, pool.size());
  CHECK_TRUE(pool.invariants_hold());
}

TEST(Pool, slot_freed_after_exhaustion_is_reusable) {
  sdpslam::Pool<Node, 2> pool;
  Node* a = pool.create(1);
  pool.create(2);
  POINTERS_EQUAL(nullptr, pool.create(3));
  CHECK_TRUE(pool.destroy(a));
  Node* c = pool.create(3);
  CHECK(c != nullptr);
  LONGS_EQUAL(3, c->value);
  CHECK_TRUE(pool.invariants_hold());
}

TEST(Pool, release_of_foreign_pointer_is_refused) {
  sdpslam::Pool<Node, 2> pool;
  Node outside(5);
  CHECK_FALSE(pool.release(&outside));
  CHECK_FALSE(pool.destroy(&outside));
  LONGS_EQUAL(2, pool.misuse_count());
  LONGS_EQUAL(1, Node::live);  // `outside` was not destroyed by the pool
  CHECK_TRUE(pool.invariants_hold());
}

TEST(Pool, double_release_is_refused) {
  sdpslam::Pool<Node, 2> pool;
  Node* a = pool.create(1);
  CHECK_TRUE(pool.destroy(a));
  CHECK_FALSE(pool.destroy(a));
  CHECK_FALSE(pool.release(a));
  LONGS_EQUAL(2, pool.misuse_count());
  LONGS_EQUAL(0, pool.size());
  CHECK_TRUE(pool.invariants_hold());
}

TEST(Pool, misaligned_interior_pointer_is_refused) {
  sdpslam::Pool<Node, 2> pool;
  Node* a = pool.create(1);
  const void* interior = reinterpret_cast<const unsigned char*>(a) + 1;
  CHECK_FALSE(pool.owns(interior));
  CHECK_FALSE(pool.release(interior));
  LONGS_EQUAL(1, pool.size());
}

TEST(Pool, null_release_is_refused) {
  sdpslam::Pool<Node, 1> pool;
  CHECK_FALSE(pool.release(nullptr));
  LONGS_EQUAL(1, pool.misuse_count());
}

TEST(Pool, peak_used_never_decreases) {
  sdpslam::Pool<Node, 4> pool;
  Node* a = pool.create(1);
  Node* b = pool.create(2);
  Node* c = pool.create(3);
  LONGS_EQUAL(3, pool.peak_used());
  pool.destroy(a);
  pool.destroy(b);
  pool.destroy(c);
  LONGS_EQUAL(3, pool.peak_used());
  pool.create(4);
  LONGS_EQUAL(3, pool.peak_used());
}

TEST(Pool, handle_resolves_to_its_object) {
  sdpslam::Pool<Node, 4> pool;
  Node* a = pool.create(7);
  sdpslam::Handle<Node> h = pool.handle_of(a);
  CHECK_TRUE(h.valid());
  POINTERS_EQUAL(a, pool.get(h));
}

TEST(Pool, handle_to_released_slot_is_stale_even_after_reuse) {
  sdpslam::Pool<Node, 1> pool;
  Node* a = pool.create(1);
  sdpslam::Handle<Node> h = pool.handle_of(a);
  pool.destroy(a);
  POINTERS_EQUAL(nullptr, pool.get(h));
  Node* b = pool.create(2);
  POINTERS_EQUAL(a, b);  // same slot reused ...
  POINTERS_EQUAL(nullptr, pool.get(h));  // ... but the old handle does not alias it
  POINTERS_EQUAL(b, pool.get(pool.handle_of(b)));
}

TEST(Pool, invalid_and_out_of_range_handles_resolve_to_null) {
  sdpslam::Pool<Node, 2> pool;
  POINTERS_EQUAL(nullptr, pool.get(sdpslam::Handle<Node>::invalid()));
  POINTERS_EQUAL(nullptr, pool.get(sdpslam::Handle<Node>{5U, 0U}));
  CHECK_FALSE(pool.handle_of(nullptr).valid());
}

TEST(Pool, clear_destroys_every_live_object) {
  sdpslam::Pool<Node, 4> pool;
  pool.create(1);
  pool.create(2);
  pool.clear();
  LONGS_EQUAL(0, Node::live);
  LONGS_EQUAL(0, pool.size());
  LONGS_EQUAL(2, pool.peak_used());
  CHECK_TRUE(pool.invariants_hold());
}

TEST(Pool, size_erased_base_reports_diagnostics) {
  sdpslam::Pool<Node, 3> pool;
  pool.create(1);
  const sdpslam::IPool& base = pool;
  LONGS_EQUAL(3, base.capacity());
  LONGS_EQUAL(1, base.size());
  CHECK(base.footprint_bytes() >= 3 * sizeof(Node));
}

TEST(Pool, arena_pool_takes_capacity_at_init) {
  alignas(16) static unsigned char buffer[4096];
  sdpslam::Arena arena(buffer, sizeof buffer);
  sdpslam::ArenaPool<Node> pool;
  CHECK_TRUE(pool.init(arena, 10));
  LONGS_EQUAL(10, pool.capacity());
  for (int i = 0; i < 10; ++i) CHECK(pool.create(i) != nullptr);
  POINTERS_EQUAL(nullptr, pool.create(10));
  LONGS_EQUAL(1, pool.oom_count());
  CHECK_TRUE(pool.invariants_hold());
}

TEST(Pool, arena_pool_init_fails_cleanly_when_arena_too_small) {
  alignas(16) static unsigned char buffer[64];
  sdpslam::Arena arena(buffer, sizeof buffer);
  sdpslam::ArenaPool<Node> pool;
  CHECK_FALSE(pool.init(arena, 100));
  LONGS_EQUAL(0, pool.capacity());
  POINTERS_EQUAL(nullptr, pool.create(1));
  CHECK_TRUE(pool.invariants_hold());
}

TEST(Pool, randomised_operations_keep_invariants) {
  constexpr std::uint32_t kCap = 64;
  static sdpslam::Pool<Node, kCap> pool;
  pool.clear();
  Node* live[kCap] = {};
  std::uint32_t live_count = 0;
  Rng rng;
  for (int step = 0; step < 20000; ++step) {
    const std::uint32_t r = rng.next();
    if ((r & 1U) != 0U) {
      Node* n = pool.create(step);
      if (live_count < kCap) {
        CHECK(n != nullptr);
        live[live_count++] = n;
      } else {
        POINTERS_EQUAL(nullptr, n);
      }
    } else if (live_count > 0U) {
      const std::uint32_t i = (r >> 1U) % live_count;
      CHECK_TRUE(pool.destroy(live[i]));
      live[i] = live[--live_count];
    }
    LONGS_EQUAL(live_count, pool.size());
    CHECK_TRUE(pool.invariants_hold());
  }
  LONGS_EQUAL(kCap, pool.peak_used());
  CHECK(pool.oom_count() > 0U);
  LONGS_EQUAL(0, pool.misuse_count());
}

// A snapshot carries the bookkeeping; the capacity is fixed at init, so a snapshot of
// another capacity is refused, naming it, and changes nothing.
TEST(Pool, a_snapshot_loads_only_into_a_pool_of_the_same_capacity) {
  sdpslam::Pool<Node, 4> saved;  // small: on the stack
  CHECK(saved.create(1) != nullptr);
  CHECK(saved.create(2) != nullptr);
  sdpslam::test::MemoryWriter bytes;
  sdpslam::StateIo out(bytes, nullptr, 0U);
  saved.transfer_state(out);
  CHECK_TRUE(out.ok());

  sdpslam::Pool<Node, 5> other;
  sdpslam::test::MemoryReader first(bytes.bytes_);
  sdpslam::StateIo refused(first, nullptr, 0U);
  other.transfer_state(refused);
  CHECK_FALSE(refused.ok());
  STRCMP_EQUAL("pool capacity: differs from this engine's", refused.why());
  LONGS_EQUAL(0, other.size());

  // Only the bookkeeping travels (a Pool's slots are its own; an ArenaPool's travel
  // with the arena): the counters come back.
  sdpslam::Pool<Node, 4> same;
  sdpslam::test::MemoryReader second(bytes.bytes_);
  sdpslam::StateIo loaded(second, nullptr, 0U);
  same.transfer_state(loaded);
  CHECK_TRUE(loaded.ok());
  LONGS_EQUAL(2, same.size());
  LONGS_EQUAL(2, same.peak_used());
}
