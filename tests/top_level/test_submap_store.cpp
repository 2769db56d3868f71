// The submaps' storage (paper §III, Fig. 3) through its own API: live submaps by level
// slot, and the ring of permanent submaps that forgets its oldest when full and keeps
// its skeleton points as cells of their grid.
#include <CppUTest/TestHarness.h>

#include <cstdint>
#include <cstring>

#include "sdpslam/core/arena.h"
#include "top/submap_store.h"

using sdpslam::Arena;
using sdpslam::CellPoint;
using sdpslam::PermanentSubmap;
using sdpslam::Point2;
using sdpslam::SkeletonGrid;
using sdpslam::Submap;
using sdpslam::SubmapStore;
using sdpslam::SubmapStoreOptions;

namespace {

alignas(16) unsigned char g_buffer[256U * 1024U];

SubmapStoreOptions options(std::uint32_t obstacle_points = 4U, std::uint32_t max_permanent = 3U) {
  SubmapStoreOptions o;
  o.max_levels = 4U;
  o.nodes = 3U;
  o.skeleton_points = 5U;
  o.obstacle_points = obstacle_points;
  o.max_permanent = max_permanent;
  return o;
}

// Fills level `level`'s submap `node` with values derived from (level, node).
void fill(SubmapStore& store, std::uint32_t level, std::uint32_t node) {
  const double tag = 100.0 * level + node;
  Submap& sm = store.submap(level, node);
  sm = Submap{};
  sm.node = 1000U + 10U * level + node;
  sm.initial = sdpslam::Pose2{tag, 0.0, 0.0};
  sm.box[0] = -tag;
  sm.box[2] = tag;
  sm.point_count = 1U + node;
  sm.obstacle_count = 2U + node;
  sm.skeleton_grid = SkeletonGrid{-0.5, -0.5, 1.0};  // cell centres at whole metres
  for (std::uint32_t i = 0; i < sm.point_count; ++i) store.points(level, node)[i] = Point2{tag, static_cast<double>(i)};
  for (std::uint32_t i = 0; i < sm.obstacle_count; ++i) {
    store.obstacles(level, node)[i] = CellPoint{static_cast<std::uint16_t>(10U * level + node), static_cast<std::uint16_t>(i)};
  }
  store.level(level).start_stamp_us = static_cast<std::int64_t>(level) * 1000;
  store.level(level).end_stamp_us = static_cast<std::int64_t>(level + 1U) * 1000;
  store.level(level).count = 3U;
}

}  // namespace

TEST_GROUP(SubmapStore){};

TEST(SubmapStore, init_refuses_invalid_options_and_a_short_arena) {
  SubmapStoreOptions bad = options();
  bad.nodes = 0U;
  LONGS_EQUAL(0U, SubmapStore::required_bytes(bad));
  SubmapStore store;
  Arena arena(g_buffer, sizeof g_buffer);
  CHECK_FALSE(store.init(bad, arena));
  const std::size_t need = SubmapStore::required_bytes(options());
  Arena small(g_buffer, need - 1U);
  CHECK_FALSE(store.init(options(), small));
  Arena enough(g_buffer, need);
  CHECK_TRUE(store.init(options(), enough));
  LONGS_EQUAL(0U, store.permanent_count());
  // Without obstacle points (no loop closure) none are kept, and less is carved.
  CHECK(SubmapStore::required_bytes(options(0U)) < need);
  Arena other(g_buffer, sizeof g_buffer);
  CHECK_TRUE(store.init(options(0U), other));
  POINTERS_EQUAL(nullptr, store.obstacles(0U, 0U));
}

TEST(SubmapStore, live_submaps_are_stored_by_level_slot) {
  Arena arena(g_buffer, sizeof g_buffer);
  SubmapStore store;
  CHECK_TRUE(store.init(options(), arena));
  for (std::uint32_t node = 0; node < 3U; ++node) fill(store, 1U, node);
  for (std::uint32_t node = 0; node < 3U; ++node) fill(store, 2U, node);
  // Each (level, node) has its own record and points.
  for (std::uint32_t level = 1U; level <= 2U; ++level) {
    for (std::uint32_t node = 0; node < 3U; ++node) {
      LONGS_EQUAL(1000U + 10U * level + node, store.submap(level, node).node);
      DOUBLES_EQUAL(100.0 * level + node, store.points(level, node)[0].x_m, 0.0);
      LONGS_EQUAL(10U * level + node, store.obstacles(level, node)[1].ix);
    }
  }
  // Level 5 takes level 1's slot (max_levels 4), as the PGS reuses it.
  POINTERS_EQUAL(&store.submap(1U, 2U), &store.submap(5U, 2U));
  POINTERS_EQUAL(&store.level(1U), &store.level(5U));
}

TEST(SubmapStore, a_permanent_submap_keeps_its_record_and_points) {
  Arena arena(g_buffer, sizeof g_buffer);
  SubmapStore store;
  CHECK_TRUE(store.init(options(), arena));
  for (std::uint32_t node = 0; node < 3U; ++node) fill(store, 0U, node);
  bool forgot = true;
  const std::uint32_t slot = store.make_permanent(0U, 2U, &forgot);
  CHECK_FALSE(forgot);
  LONGS_EQUAL(1U, store.permanent_count());
  // The live level may now be overwritten: the permanent copy stays.
  fill(store, 4U, 2U);
  const PermanentSubmap& pm = store.permanent(slot);
  LONGS_EQUAL(0U, pm.level);
  LONGS_EQUAL(3U, pm.point_count);
  LONGS_EQUAL(4U, pm.obstacle_count);
  DOUBLES_EQUAL(2.0, pm.initial.x_m, 0.0);
  DOUBLES_EQUAL(-2.0, pm.box[0], 0.0);
  LONGS_EQUAL(0, pm.start_stamp_us);
  DOUBLES_EQUAL(2.0, store.permanent_points(slot)[2].x_m, 0.0);
  DOUBLES_EQUAL(2.0, store.permanent_points(slot)[2].y_m, 0.0);
  LONGS_EQUAL(2U, store.permanent_obstacles(slot)[3].ix);
  LONGS_EQUAL(3U, store.permanent_obstacles(slot)[3].iy);
  std::uint32_t found = 99U;
  CHECK_TRUE(store.find_permanent(0U, &found));
  LONGS_EQUAL(slot, found);
  CHECK_FALSE(store.find_permanent(1U, &found));
  LONGS_EQUAL(0U, store.first_held_level(7U));
}

TEST(SubmapStore, a_full_ring_forgets_its_oldest) {
  Arena arena(g_buffer, sizeof g_buffer);
  SubmapStore store;
  CHECK_TRUE(store.init(options(4U, 3U), arena));
  LONGS_EQUAL(6U, store.first_held_level(6U));  // none permanent: the first live level
  std::uint32_t forgotten = 0U;
  for (std::uint32_t level = 0; level < 5U; ++level) {
    for (std::uint32_t node = 0; node < 3U; ++node) fill(store, level, node);
    bool forgot = false;
    (void)store.make_permanent(level, level % 3U, &forgot);
    forgotten += forgot ? 1U : 0U;
  }
  LONGS_EQUAL(2U, forgotten);
  LONGS_EQUAL(3U, store.permanent_count());
  LONGS_EQUAL(2U, store.first_held_level(5U));
  std::uint32_t slot = 0U;
  CHECK_FALSE(store.find_permanent(0U, &slot));
  CHECK_FALSE(store.find_permanent(1U, &slot));
  for (std::uint32_t level = 2U; level < 5U; ++level) {
    CHECK_TRUE(store.find_permanent(level, &slot));
    LONGS_EQUAL(slot, store.permanent_slot_at(level - 2U));  // oldest first
    LONGS_EQUAL(level, store.permanent(slot).level);
    DOUBLES_EQUAL(100.0 * level + level % 3U, store.permanent_points(slot)[0].x_m, 0.0);
  }
  CHECK_FALSE(store.find_permanent(5U, &slot));
}

TEST(SubmapStore, a_permanent_skeleton_is_kept_as_grid_cells_and_comes_back_bit_for_bit) {
  Arena arena(g_buffer, sizeof g_buffer);
  SubmapStoreOptions o = options();
  o.skeleton_points = 64U;
  SubmapStore store;
  CHECK_TRUE(store.init(o, arena));
  // A skeleton as FreeSpaceSkeleton emits it: origin + (cell + 0.5) × cell size, on a
  // grid whose origin and cell are not round numbers.
  Submap& sm = store.submap(0U, 1U);
  sm = Submap{};
  sm.skeleton_grid = SkeletonGrid{-37.15, 12.05, 0.1};
  const SkeletonGrid& g = sm.skeleton_grid;
  Point2 emitted[64];
  for (std::uint32_t i = 0; i < 63U; ++i) {
    const std::uint32_t x = (i * 37U) % 300U;
    const std::uint32_t y = (i * 101U) % 300U;
    emitted[i] = Point2{g.origin_x_m + (static_cast<double>(x) + 0.5) * g.cell_m,
                        g.origin_y_m + (static_cast<double>(y) + 0.5) * g.cell_m};
  }
  // And one point off the grid: it is kept at the nearest cell centre.
  emitted[63] = Point2{g.origin_x_m + 4.54 * g.cell_m, g.origin_y_m + 0.3 * g.cell_m};
  sm.point_count = 64U;
  for (std::uint32_t i = 0; i < 64U; ++i) store.points(0U, 1U)[i] = emitted[i];
  bool forgot = true;
  const std::uint32_t slot = store.make_permanent(0U, 1U, &forgot);
  sm.point_count = 0U;  // the live slot may be reused: the permanent copy stays
  store.points(0U, 1U)[0] = Point2{1.0e6, 1.0e6};
  const Point2* kept = store.permanent_points(slot);
  CHECK_EQUAL(0, std::memcmp(emitted, kept, 63U * sizeof(Point2)));
  DOUBLES_EQUAL(g.origin_x_m + 4.5 * g.cell_m, kept[63].x_m, 1e-12);
  DOUBLES_EQUAL(g.origin_y_m + 0.5 * g.cell_m, kept[63].y_m, 1e-12);
  // Four bytes a point, not a Point2's sixteen.
  SubmapStoreOptions more = o;
  more.max_permanent = o.max_permanent + 1U;
  CHECK_TRUE(SubmapStore::required_bytes(more) - SubmapStore::required_bytes(o) <
             sizeof(PermanentSubmap) + 4U * o.skeleton_points + 4U * o.obstacle_points + 64U);
}
