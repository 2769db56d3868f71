// Stamped poses in an arena-backed ring (pose_ring.h): refusal when full, windows by
// stamp, dropping from the oldest end, across the ring's wrap.
#include <CppUTest/TestHarness.h>

#include <cstdint>
#include <vector>

#include "sdpslam/core/arena.h"
#include "pose_ring.h"

using sdpslam::Arena;
using sdpslam::PoseRing;
using sdpslam::Pose2;

namespace {
alignas(16) unsigned char g_buffer[4096];

std::vector<std::int64_t> stamps_between(const PoseRing& ring, std::int64_t after, std::int64_t through) {
  std::vector<std::int64_t> out;
  ring.for_each_between(after, through, [&out](std::int64_t s, const Pose2& p) {
    DOUBLES_EQUAL(static_cast<double>(s), p.x_m, 0.0);  // each pose travels with its stamp
    out.push_back(s);
  });
  return out;
}
}  // namespace

TEST_GROUP(PoseRing){};

TEST(PoseRing, a_full_ring_refuses_the_newest_and_keeps_the_oldest) {
  Arena arena(g_buffer, sizeof g_buffer);
  PoseRing ring;
  CHECK_TRUE(ring.init(arena, 4U));
  for (std::int64_t s = 1; s <= 4; ++s) CHECK_TRUE(ring.push(s, Pose2{static_cast<double>(s), 0.0, 0.0}));
  CHECK_FALSE(ring.push(5, Pose2{5.0, 0.0, 0.0}));
  LONGS_EQUAL(4U, ring.size());
  CHECK_TRUE((stamps_between(ring, 0, 100) == std::vector<std::int64_t>{1, 2, 3, 4}));
}

TEST(PoseRing, windows_are_after_a_stamp_and_through_another) {
  Arena arena(g_buffer, sizeof g_buffer);
  PoseRing ring;
  CHECK_TRUE(ring.init(arena, 8U));
  for (std::int64_t s = 10; s <= 60; s += 10) CHECK_TRUE(ring.push(s, Pose2{static_cast<double>(s), 0.0, 0.0}));
  CHECK_TRUE((stamps_between(ring, 20, 50) == std::vector<std::int64_t>{30, 40, 50}));
  CHECK_TRUE((stamps_between(ring, 60, INT64_MAX).empty()));
}

TEST(PoseRing, dropping_frees_room_from_the_oldest_end_across_the_wrap) {
  Arena arena(g_buffer, sizeof g_buffer);
  PoseRing ring;
  CHECK_TRUE(ring.init(arena, 4U));
  for (std::int64_t s = 1; s <= 4; ++s) CHECK_TRUE(ring.push(s, Pose2{static_cast<double>(s), 0.0, 0.0}));
  ring.drop_through(2);
  LONGS_EQUAL(2U, ring.size());
  CHECK_TRUE(ring.push(5, Pose2{5.0, 0.0, 0.0}));
  CHECK_TRUE(ring.push(6, Pose2{6.0, 0.0, 0.0}));
  CHECK_FALSE(ring.push(7, Pose2{7.0, 0.0, 0.0}));
  CHECK_TRUE((stamps_between(ring, 0, INT64_MAX) == std::vector<std::int64_t>{3, 4, 5, 6}));
  ring.drop_through(100);
  LONGS_EQUAL(0U, ring.size());
}

TEST(PoseRing, init_refuses_no_capacity_and_a_short_arena) {
  PoseRing ring;
  Arena arena(g_buffer, sizeof g_buffer);
  CHECK_FALSE(ring.init(arena, 0U));
  Arena small(g_buffer, PoseRing::required_bytes(8U) / 2U);
  CHECK_FALSE(ring.init(small, 8U));
  CHECK_FALSE(ring.push(1, Pose2{}));
}
