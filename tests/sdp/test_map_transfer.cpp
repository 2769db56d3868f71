// A permanent submap's copy into the global map (map_transfer.h) through its own API:
// popped or read in rows it gives the same cells, moved by its frame, within the budget,
// and releases the submap's node when done.
#include <CppUTest/TestHarness.h>

#include <map>
#include <memory>
#include <tuple>
#include <vector>

#include "../dpslam_filter/filter_harness.h"
#include "top/map_transfer.h"
#include "top/permanent_map.h"

using namespace sdpslam;

namespace {

using Cells = std::map<std::pair<std::int32_t, std::int32_t>, std::tuple<std::uint16_t, std::uint16_t, std::uint32_t>>;

// The filter after a lap of the room, its particles' nodes anchored by a restart.
struct Rig {
  test::FilterRig filter;
  std::vector<unsigned char> buffer = std::vector<unsigned char>(8U * 1024U * 1024U);
  Arena arena{buffer.data(), buffer.size()};
  PermanentMap map;
  std::vector<CellObservation> fine_values = std::vector<CellObservation>(20000U);
  std::vector<std::uint8_t> fine_known = std::vector<std::uint8_t>(20000U);
  FineBuffer fine{fine_values.data(), fine_known.data(), 20000U};
  NodeId anchored[3] = {kNoNode, kNoNode, kNoNode};
  CellRect rect{};

  Rig() {
    CHECK_TRUE(filter.init(test::sim_options(3U), 5U));
    const std::vector<test::Segment> world = test::room_world();
    const test::SimRun run = test::make_loop(1U);
    for (std::size_t i = 0; i < run.truth.size(); ++i) (void)filter.step(run, world, i);
    for (std::uint32_t i = 0; i < 3U; ++i) anchored[i] = filter.filter->particle_node(i);
    CHECK_TRUE(filter.filter->map().touched_bounds(&rect));
    CHECK_TRUE(filter.filter->restart_segment(filter.filter->best_pose()));
    CHECK_TRUE(map.init(arena, 512U));
  }

  // Copies anchored[0] at `frame` within `budget` per call; returns the steps' totals.
  TransferStep copy(const Pose2& frame, std::uint32_t budget, std::uint32_t* calls, std::uint32_t* most) {
    MapTransfer transfer;
    transfer.start(anchored[0], frame, 7U, rect);
    NodeId node = kNoNode;
    CellRect rest{};
    CHECK_TRUE(transfer.pending(&node, &rest));
    LONGS_EQUAL(anchored[0], node);
    TransferStep total;
    *calls = 0U;
    *most = 0U;
    while (transfer.active()) {
      const TransferStep st = transfer.work(budget, *filter.filter, map, fine);
      total.cells_copied += st.cells_copied;
      total.cells_dropped += st.cells_dropped;
      total.popped = total.popped || st.popped;
      total.by_rows = total.by_rows || st.by_rows;
      total.released = total.released || st.released;
      total.observations_freed += st.observations_freed;
      if (st.work_cells > *most) *most = st.work_cells;
      ++*calls;
    }
    CHECK_FALSE(transfer.pending(&node, &rest));
    return total;
  }

  Cells cells() const {
    Cells out;
    map.for_each_cell([&out](std::int32_t ix, std::int32_t iy, const PermanentMap::Cell& c) {
      out[{ix, iy}] = std::make_tuple(c.value.hits, c.value.misses, c.tag);
    });
    return out;
  }
};

}  // namespace

TEST_GROUP(MapTransfer){};

TEST(MapTransfer, popped_or_read_in_rows_the_same_cells_reach_the_global_map) {
  // Rows: the other anchored nodes are still held, so the copied node is not a root.
  Rig rows;
  std::uint32_t calls = 0U;
  std::uint32_t most = 0U;
  const TransferStep by_rows = rows.copy(Pose2{}, 5000U, &calls, &most);
  CHECK_TRUE(by_rows.by_rows);
  CHECK_FALSE(by_rows.popped);
  CHECK(calls > 3U);
  CHECK(most <= 5000U + rows.rect.width);  // the budget, plus at most one row
  CHECK_TRUE(by_rows.released);
  LONGS_EQUAL(0U, by_rows.cells_dropped);
  // Pop: the others released first, prune merges the lineage into the copied node.
  Rig pop;
  CHECK_TRUE(pop.filter.filter->release_anchored(pop.anchored[1]));
  CHECK_TRUE(pop.filter.filter->release_anchored(pop.anchored[2]));
  const std::uint32_t held = pop.filter.filter->map().observations_used();
  const TransferStep popped = pop.copy(Pose2{}, 5000U, &calls, &most);
  CHECK_TRUE(popped.popped);
  CHECK(calls > 3U);
  CHECK(most <= 5000U + MapTransfer::kPopCostCells);
  CHECK_TRUE(popped.released);
  // The pool got the node's observations back as they were copied.
  CHECK(popped.observations_freed > 1000U);
  CHECK(pop.filter.filter->map().observations_used() < held);
  const Cells a = rows.cells();
  const Cells b = pop.cells();
  CHECK(a.size() > 1000U);
  LONGS_EQUAL(a.size(), b.size());
  CHECK_TRUE(a == b);
  LONGS_EQUAL(by_rows.cells_copied, popped.cells_copied);
}

TEST(MapTransfer, cells_go_where_the_submap_frame_puts_them) {
  Rig at_origin;
  std::uint32_t calls = 0U;
  std::uint32_t most = 0U;
  (void)at_origin.copy(Pose2{}, 0xFFFFFFFFU, &calls, &most);
  Rig moved;
  // Ten cells east and four north (exact multiples of the 0.05 m cells), no rotation.
  (void)moved.copy(Pose2{0.5, 0.2, 0.0}, 0xFFFFFFFFU, &calls, &most);
  const Cells a = at_origin.cells();
  const Cells b = moved.cells();
  LONGS_EQUAL(a.size(), b.size());
  std::size_t same = 0U;
  for (const auto& [key, value] : a) {
    const auto it = b.find({key.first + 10, key.second + 4});
    if (it != b.end() && it->second == value) ++same;
  }
  // Cell centres sit half a cell from the edges, so the shift is exact for every cell.
  LONGS_EQUAL(a.size(), same);
}
