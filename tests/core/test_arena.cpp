#include <CppUTest/TestHarness.h>

#include <cstdint>

#include "sdpslam/core/arena.h"

TEST_GROUP(Arena){};

TEST(Arena, allocations_are_aligned_and_disjoint) {
  alignas(64) static unsigned char buffer[256];
  sdpslam::Arena arena(buffer, sizeof buffer);
  void* a = arena.allocate(3, 1);
  void* b = arena.allocate(8, 8);
  void* c = arena.allocate(16, 32);
  CHECK(a != nullptr && b != nullptr && c != nullptr);
  LONGS_EQUAL(0, reinterpret_cast<std::uintptr_t>(b) % 8);
  LONGS_EQUAL(0, reinterpret_cast<std::uintptr_t>(c) % 32);
  CHECK(static_cast<unsigned char*>(b) >= static_cast<unsigned char*>(a) + 3);
  CHECK(static_cast<unsigned char*>(c) >= static_cast<unsigned char*>(b) + 8);
}

TEST(Arena, exhaustion_returns_null_counts_and_keeps_state) {
  alignas(16) static unsigned char buffer[32];
  sdpslam::Arena arena(buffer, sizeof buffer);
  CHECK(arena.allocate(24, 8) != nullptr);
  const std::size_t used = arena.used_bytes();
  POINTERS_EQUAL(nullptr, arena.allocate(16, 8));
  LONGS_EQUAL(1, arena.oom_count());
  LONGS_EQUAL(used, arena.used_bytes());
  CHECK(arena.allocate(8, 8) != nullptr);  // what fits still fits
}

TEST(Arena, non_power_of_two_alignment_is_refused) {
  alignas(16) static unsigned char buffer[32];
  sdpslam::Arena arena(buffer, sizeof buffer);
  POINTERS_EQUAL(nullptr, arena.allocate(4, 3));
  POINTERS_EQUAL(nullptr, arena.allocate(4, 0));
  LONGS_EQUAL(2, arena.oom_count());
}

TEST(Arena, huge_array_request_does_not_overflow) {
  alignas(16) static unsigned char buffer[32];
  sdpslam::Arena arena(buffer, sizeof buffer);
  POINTERS_EQUAL(nullptr, arena.allocate_array<std::uint64_t>(SIZE_MAX / 4));
  POINTERS_EQUAL(nullptr, arena.allocate(SIZE_MAX, 8));
  LONGS_EQUAL(0, arena.used_bytes());
}

TEST(Arena, arrays_are_value_initialised) {
  alignas(16) static unsigned char buffer[128];
  for (auto& b : buffer) b = 0xAB;
  sdpslam::Arena arena(buffer, sizeof buffer);
  int* xs = arena.allocate_array<int>(8);
  CHECK(xs != nullptr);
  for (int i = 0; i < 8; ++i) LONGS_EQUAL(0, xs[i]);
}

TEST(Arena, null_buffer_has_no_capacity) {
  sdpslam::Arena arena(nullptr, 100);
  LONGS_EQUAL(0, arena.capacity_bytes());
  POINTERS_EQUAL(nullptr, arena.allocate(1, 1));
}
