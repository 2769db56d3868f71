// The global map's permanent part (permanent_map.h): tagged cells in fixed tiles over an
// unbounded area, the merge rule, exhaustion and untagged writes counted, deterministic
// iteration.
#include <CppUTest/TestHarness.h>

#include <cstdint>
#include <vector>

#include "sdpslam/core/arena.h"
#include "sdpslam/core/top/permanent_map.h"

using sdpslam::Arena;
using sdpslam::PermanentMap;

namespace {

struct Rig {
  std::vector<unsigned char> buffer;
  Arena arena;
  PermanentMap map;
  bool init(std::uint32_t tiles) {
    buffer.assign(PermanentMap::required_bytes(tiles), 0U);
    arena.reset(buffer.data(), buffer.size());
    return map.init(arena, tiles);
  }
};

}  // namespace

TEST_GROUP(PermanentMap){};

TEST(PermanentMap, sizes_out_of_range_need_nothing_and_init_refuses_them) {
  LONGS_EQUAL(0, PermanentMap::required_bytes(0U));
  LONGS_EQUAL(0, PermanentMap::required_bytes(sdpslam::capacity::kDpMaxTiles + 1U));
  CHECK(PermanentMap::required_bytes(9U) < PermanentMap::required_bytes(1000U));
  Rig r;
  CHECK_TRUE(r.init(1000U));
  LONGS_EQUAL(1000, r.map.tile_capacity());
  // Too small an arena: refused, and every write refused afterwards.
  std::vector<unsigned char> small(64U);
  Arena a;
  a.reset(small.data(), small.size());
  PermanentMap m;
  CHECK_FALSE(m.init(a, 4U));
  CHECK_FALSE(m.initialised());
  CHECK_FALSE(m.add(1, 1, 1U, 0U, 1U));
}

TEST(PermanentMap, cells_keep_their_counts_and_the_tag_of_the_larger_contribution) {
  Rig r;
  CHECK_TRUE(r.init(16U));
  LONGS_EQUAL(0, r.map.cell(3, 4).tag);
  CHECK_TRUE(r.map.add(3, 4, 2U, 1U, 7U));
  PermanentMap::Cell c = r.map.cell(3, 4);
  LONGS_EQUAL(7, c.tag);
  LONGS_EQUAL(2, c.value.hits);
  LONGS_EQUAL(1, c.value.misses);
  // A smaller contribution adds its counts and leaves the tag.
  CHECK_TRUE(r.map.add(3, 4, 1U, 0U, 9U));
  c = r.map.cell(3, 4);
  LONGS_EQUAL(7, c.tag);
  LONGS_EQUAL(3, c.value.hits);
  // One at least as large as everything before takes the tag.
  CHECK_TRUE(r.map.add(3, 4, 0U, 4U, 9U));
  c = r.map.cell(3, 4);
  LONGS_EQUAL(9, c.tag);
  LONGS_EQUAL(3, c.value.hits);
  LONGS_EQUAL(5, c.value.misses);
  // Saturation keeps the ratio (accumulate()).
  CHECK_TRUE(r.map.add(3, 4, 0xFFF0U, 0U, 9U));
  c = r.map.cell(3, 4);
  CHECK(c.value.hits < 0xFFFFU);
  CHECK(c.value.hits > c.value.misses);
  LONGS_EQUAL(1, r.map.known_cells());
  LONGS_EQUAL(1, r.map.tiles_used());
}

TEST(PermanentMap, untagged_writes_and_writes_past_the_last_tile_are_refused_and_counted) {
  Rig r;
  CHECK_TRUE(r.init(2U));
  CHECK_FALSE(r.map.add(0, 0, 1U, 0U, 0U));  // tag 0 means "no data"
  LONGS_EQUAL(1, r.map.refused_untagged());
  CHECK_TRUE(r.map.add(0, 0, 1U, 0U, 1U));    // tile (0, 0)
  CHECK_TRUE(r.map.add(20, 0, 1U, 0U, 1U));   // tile (1, 0)
  CHECK_FALSE(r.map.add(40, 40, 1U, 0U, 1U));  // a third tile: none left
  CHECK_TRUE(r.map.add(15, 15, 1U, 0U, 2U));  // an existing tile still takes cells
  LONGS_EQUAL(1, r.map.refused_no_tile());
  LONGS_EQUAL(2, r.map.tiles_used());
  LONGS_EQUAL(3, r.map.known_cells());
  LONGS_EQUAL(0, r.map.cell(40, 40).tag);  // the refused write left nothing behind
}

TEST(PermanentMap, cells_anywhere_in_int32_are_kept_apart_each_in_its_own_tile) {
  Rig r;
  CHECK_TRUE(r.init(8U));
  // Far from the origin, negative, and at the extremes of int32: no area bound.
  const std::int32_t cells[][2] = {{-1, -1}, {0, 0}, {-17, 5}, {1000000, -2000000}, {2147483647, -2147483647 - 1},
                                   {-2147483647 - 1, 2147483647}};
  std::uint32_t tag = 1U;
  for (const auto& c : cells) CHECK_TRUE(r.map.add(c[0], c[1], 1U, 0U, tag++));
  LONGS_EQUAL(6, r.map.tiles_used());
  tag = 1U;
  for (const auto& c : cells) LONGS_EQUAL(tag++, r.map.cell(c[0], c[1]).tag);
  // A neighbour in another tile, and the same cell a tile-table width away, stay unknown.
  LONGS_EQUAL(0, r.map.cell(-1, 0).tag);
  LONGS_EQUAL(0, r.map.cell(-1 + (1 << 20), -1).tag);
  LONGS_EQUAL(6, r.map.known_cells());
}

TEST(PermanentMap, every_known_cell_is_visited_once_in_tile_order) {
  Rig r;
  CHECK_TRUE(r.init(20U));
  // Written in an order unlike the visit order.
  const std::int32_t cells[][2] = {{49, 49}, {0, 0}, {17, 3}, {3, 17}, {16, 16}, {15, 0}, {-3, -20}};
  for (const auto& c : cells) CHECK_TRUE(r.map.add(c[0], c[1], 1U, 1U, static_cast<std::uint32_t>(c[0] + 100)));
  std::vector<std::int32_t> xs;
  std::vector<std::int32_t> ys;
  r.map.for_each_cell([&](std::int32_t ix, std::int32_t iy, const PermanentMap::Cell& c) {
    xs.push_back(ix);
    ys.push_back(iy);
    LONGS_EQUAL(ix + 100, c.tag);
  });
  // Tile (-1,-2): (-3,-20); tile (0,0): (0,0) then (15,0); tile (1,0): (17,3); tile (0,1):
  // (3,17); tile (1,1): (16,16); tile (3,3): (49,49).
  const std::int32_t ex[] = {-3, 0, 15, 17, 3, 16, 49};
  const std::int32_t ey[] = {-20, 0, 0, 3, 17, 16, 49};
  LONGS_EQUAL(7, xs.size());
  for (std::size_t i = 0; i < 7U; ++i) {
    LONGS_EQUAL(ex[i], xs[i]);
    LONGS_EQUAL(ey[i], ys[i]);
  }
}
