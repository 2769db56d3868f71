// The global map's permanent part (permanent_map.h): tagged cells in fixed tiles over an
// unbounded area, the merge rule, a full store coarsened instead of refusing, exhaustion
// and untagged writes counted, deterministic iteration.
#include <CppUTest/TestHarness.h>

#include <cstdint>
#include <vector>

#include "sdpslam/core/arena.h"
#include "top/permanent_map.h"

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

TEST(PermanentMap, untagged_writes_and_writes_past_the_coarsest_scale_are_refused_and_counted) {
  Rig r;
  CHECK_TRUE(r.init(2U));
  CHECK_FALSE(r.map.add(0, 0, 1U, 0U, 0U));  // tag 0 means "no data"
  LONGS_EQUAL(1, r.map.refused_untagged());
  // Three cells so far apart that no coarsening puts two in one tile: the third is
  // refused once the map is as coarse as it may become.
  const std::int32_t far = 1 << 28;
  CHECK_TRUE(r.map.add(0, 0, 1U, 0U, 1U));
  CHECK_TRUE(r.map.add(far, 0, 1U, 0U, 1U));
  CHECK_FALSE(r.map.add(0, far, 1U, 0U, 1U));
  LONGS_EQUAL(PermanentMap::kMaxScaleLog2, r.map.scale_log2());
  LONGS_EQUAL(PermanentMap::kMaxScaleLog2, r.map.compactions());
  CHECK_TRUE(r.map.add(15, 15, 1U, 0U, 2U));  // an existing tile still takes cells
  LONGS_EQUAL(1, r.map.refused_no_tile());
  LONGS_EQUAL(2, r.map.tiles_used());
  LONGS_EQUAL(2, r.map.known_cells());      // (0, 0) and (15, 15) share a coarse cell
  LONGS_EQUAL(0, r.map.cell(0, far).tag);   // the refused write left nothing behind
  LONGS_EQUAL(2, r.map.cell(0, 0).value.hits);
}

TEST(PermanentMap, a_full_store_is_coarsened_and_keeps_every_cell_it_had) {
  Rig r;
  CHECK_TRUE(r.init(4U));
  // Four tiles in a 2 x 2 block (cells 0..31 each way), then a fifth tile: the store is
  // full, so it is coarsened once and the block becomes one tile.
  CHECK_TRUE(r.map.add(0, 0, 3U, 0U, 1U));     // tile (0, 0)
  CHECK_TRUE(r.map.add(1, 1, 0U, 2U, 2U));     // same coarse cell (0, 0) after the halving
  CHECK_TRUE(r.map.add(17, 0, 1U, 1U, 3U));    // tile (1, 0)
  CHECK_TRUE(r.map.add(0, 16, 1U, 0U, 4U));    // tile (0, 1)
  CHECK_TRUE(r.map.add(31, 31, 0U, 5U, 5U));   // tile (1, 1)
  LONGS_EQUAL(4, r.map.tiles_used());
  LONGS_EQUAL(0, r.map.compactions());
  CHECK_TRUE(r.map.add(100, -100, 2U, 0U, 6U));  // a fifth tile
  LONGS_EQUAL(1, r.map.compactions());
  LONGS_EQUAL(1, r.map.scale_log2());
  LONGS_EQUAL(2, r.map.tiles_used());  // the old block, and the new cell's tile
  LONGS_EQUAL(0, r.map.refused_no_tile());
  // Every fine cell written still reads back, from the coarse cell that covers it: counts
  // summed, the tag of the largest contribution.
  PermanentMap::Cell c = r.map.cell(0, 0);
  LONGS_EQUAL(3, c.value.hits);
  LONGS_EQUAL(2, c.value.misses);
  LONGS_EQUAL(1, c.tag);  // 3 observations beat 2
  CHECK(r.map.cell(1, 0).tag == c.tag);  // (1, 0) is in the same 2 x 2 block
  LONGS_EQUAL(3, r.map.cell(17, 0).tag);
  LONGS_EQUAL(4, r.map.cell(0, 16).tag);
  LONGS_EQUAL(5, r.map.cell(31, 31).tag);
  LONGS_EQUAL(5, r.map.cell(30, 30).value.misses);
  LONGS_EQUAL(6, r.map.cell(100, -100).tag);
  LONGS_EQUAL(0, r.map.cell(2, 0).tag);  // the next coarse cell was never written
  LONGS_EQUAL(5, r.map.known_cells());
  // Visits are in coarse coordinates, tile order, each coarse cell once.
  std::vector<std::int32_t> seen;
  r.map.for_each_cell([&](std::int32_t ix, std::int32_t iy, const PermanentMap::Cell& cell) {
    seen.push_back(ix);
    seen.push_back(iy);
    seen.push_back(static_cast<std::int32_t>(cell.tag));
  });
  const std::int32_t expect[] = {50, -50, 6, 0, 0, 1, 8, 0, 3, 0, 8, 4, 15, 15, 5};
  LONGS_EQUAL(15, seen.size());
  for (std::size_t i = 0; i < 15U; ++i) LONGS_EQUAL(expect[i], seen[i]);
}

TEST(PermanentMap, coarsening_keeps_every_count_written) {
  // A small store and cells spread over a wide area: several compactions. The counts
  // summed over the map equal those written (no saturation at these counts), and every
  // cell written reads back known.
  Rig r;
  CHECK_TRUE(r.init(6U));
  std::uint64_t hits = 0U;
  std::uint64_t misses = 0U;
  std::int32_t x = 3;
  std::int32_t y = -7;
  for (std::uint32_t i = 0; i < 400U; ++i) {
    x = (x * 37 + 11) % 2000 - 1000;
    y = (y * 53 + 29) % 1500 - 750;
    const auto h = static_cast<std::uint16_t>(i % 5U);
    const auto m = static_cast<std::uint16_t>(1U + i % 3U);
    CHECK_TRUE(r.map.add(x, y, h, m, 1U + i % 7U));
    hits += h;
    misses += m;
    CHECK(r.map.cell(x, y).tag != 0U);
  }
  CHECK(r.map.compactions() >= 2U);
  LONGS_EQUAL(r.map.compactions(), r.map.scale_log2());
  std::uint64_t h_sum = 0U;
  std::uint64_t m_sum = 0U;
  std::uint64_t cells = 0U;
  r.map.for_each_cell([&](std::int32_t, std::int32_t, const PermanentMap::Cell& c) {
    h_sum += c.value.hits;
    m_sum += c.value.misses;
    ++cells;
  });
  LONGS_EQUAL(hits, h_sum);
  LONGS_EQUAL(misses, m_sum);
  LONGS_EQUAL(r.map.known_cells(), cells);
  LONGS_EQUAL(0, r.map.refused_no_tile());
}
