// A submap's skeleton read from the DP map (skeleton_reader.h) through its own API: the
// same result in slices as at once, within the budget, and obstacle points only when
// asked for.
#include <CppUTest/TestHarness.h>

#include <cstring>
#include <memory>
#include <vector>

#include "../dpslam_filter/filter_harness.h"
#include "top/skeleton_reader.h"
#include "top/submap_store.h"

using namespace sdpslam;

namespace {

constexpr std::uint32_t kDownsample = 2U;
constexpr std::uint32_t kPatchSide = 130U;  // coarse cells: (130 - 2) × 2 × 0.05 m = 12.8 m of map

// The filter after a lap of the room, and the storage the reader works on.
struct Rig {
  test::FilterRig filter;
  std::vector<unsigned char> buffer = std::vector<unsigned char>(4U * 1024U * 1024U);
  Arena arena{buffer.data(), buffer.size()};
  SubmapStore store;
  SkeletonReader reader;
  std::vector<CellObservation> fine_values;
  std::vector<std::uint8_t> fine_known;
  FineBuffer fine;

  explicit Rig(std::uint32_t obstacle_points, std::size_t fine_cells = 40000U) {
    CHECK_TRUE(filter.init(test::sim_options(3U), 5U));
    const std::vector<test::Segment> world = test::room_world();
    const test::SimRun run = test::make_loop(1U);
    for (std::size_t i = 0; i < run.truth.size(); ++i) (void)filter.step(run, world, i);
    SubmapStoreOptions so;
    so.max_levels = 2U;
    so.nodes = 1U;
    so.skeleton_points = 200U;
    so.obstacle_points = obstacle_points;
    so.max_permanent = 1U;
    CHECK_TRUE(store.init(so, arena));
    SkeletonReaderOptions ro;
    ro.patch_side = kPatchSide;
    ro.downsample = kDownsample;
    ro.skeleton_points = 200U;
    ro.obstacle_points = obstacle_points;
    CHECK_TRUE(reader.init(ro, arena));
    fine_values.resize(fine_cells);
    fine_known.resize(fine_cells);
    fine = FineBuffer{fine_values.data(), fine_known.data(), fine_cells};
    // The submap: the best particle's view, over its uncommitted path's cells padded by 3 m.
    Submap& sm = store.submap(0U, 0U);
    sm.node = filter.filter->best_node();
    double b[4] = {1e9, 1e9, -1e9, -1e9};
    filter.filter->for_each_best_pose([&b](std::int64_t, const Pose2& p) {
      b[0] = p.x_m < b[0] ? p.x_m : b[0];
      b[1] = p.y_m < b[1] ? p.y_m : b[1];
      b[2] = p.x_m > b[2] ? p.x_m : b[2];
      b[3] = p.y_m > b[3] ? p.y_m : b[3];
    });
    std::int32_t ix0 = 0, iy0 = 0, ix1 = 0, iy1 = 0;
    CHECK_TRUE(filter.filter->map().world_to_cell(b[0] - 3.0, b[1] - 3.0, &ix0, &iy0));
    CHECK_TRUE(filter.filter->map().world_to_cell(b[2] + 3.0, b[3] + 3.0, &ix1, &iy1));
    sm.path_rect = CellRect{ix0, iy0, static_cast<std::uint32_t>(ix1 - ix0 + 1), static_cast<std::uint32_t>(iy1 - iy0 + 1)};
  }

  // Reads the submap's skeleton within `budget` cells per call; returns the calls.
  std::uint32_t read(std::uint32_t budget, std::uint32_t* most_cells = nullptr) {
    reader.start(store, 0U, 0U);
    CHECK_TRUE(reader.is_job(0U, 0U));
    std::uint32_t calls = 0U;
    std::uint32_t extracted = 0U;
    while (reader.active()) {
      CHECK_FALSE(store.submap(0U, 0U).skeleton_done);
      const SkeletonStep st = reader.work(budget, *filter.filter, store, fine);
      if (most_cells != nullptr && st.cells_read > *most_cells) *most_cells = st.cells_read;
      extracted += st.extracted ? 1U : 0U;
      ++calls;
    }
    CHECK_TRUE(store.submap(0U, 0U).skeleton_done);
    LONGS_EQUAL(1U, extracted);
    return calls;
  }
};

}  // namespace

TEST_GROUP(SkeletonReader){};

TEST(SkeletonReader, a_skeleton_read_in_slices_is_the_one_read_at_once) {
  Rig rig(64U);
  CHECK_EQUAL(1U, rig.read(0xFFFFFFFFU));
  const Submap whole = rig.store.submap(0U, 0U);
  CHECK(whole.point_count >= 20U);
  CHECK(whole.obstacle_count >= 20U);
  std::vector<Point2> points(rig.store.points(0U, 0U), rig.store.points(0U, 0U) + whole.point_count);
  std::vector<CellPoint> obstacles(rig.store.obstacles(0U, 0U), rig.store.obstacles(0U, 0U) + whole.obstacle_count);
  // Now within 1,000 cells a call: more calls, none reading much more than its budget
  // (at most one more strip of one coarse row), the same skeleton.
  std::uint32_t most = 0U;
  CHECK(rig.read(1000U, &most) > 5U);
  const Submap& sliced = rig.store.submap(0U, 0U);
  CHECK(most <= 1000U + sliced.path_rect.width * kDownsample);
  LONGS_EQUAL(whole.point_count, sliced.point_count);
  LONGS_EQUAL(whole.obstacle_count, sliced.obstacle_count);
  for (int i = 0; i < 4; ++i) DOUBLES_EQUAL(whole.box[i], sliced.box[i], 0.0);
  CHECK_EQUAL(0, std::memcmp(points.data(), rig.store.points(0U, 0U), points.size() * sizeof(Point2)));
  CHECK_EQUAL(0, std::memcmp(obstacles.data(), rig.store.obstacles(0U, 0U), obstacles.size() * sizeof(CellPoint)));
  // Skeleton points lie within the patch read.
  const CellRect& r = sliced.path_rect;
  for (const Point2& p : points) {
    std::int32_t ix = 0, iy = 0;
    CHECK_TRUE(rig.filter.filter->map().world_to_cell(p.x_m, p.y_m, &ix, &iy));
    CHECK(ix >= r.ix0 - 1 && ix <= r.ix0 + static_cast<std::int32_t>(r.width) + 1);
    CHECK(iy >= r.iy0 - 1 && iy <= r.iy0 + static_cast<std::int32_t>(r.height) + 1);
  }
}

TEST(SkeletonReader, a_small_strip_buffer_gives_the_same_skeleton) {
  Rig big(0U);
  (void)big.read(0xFFFFFFFFU);
  Rig small(0U, 2000U);  // a few fine rows per strip
  CHECK(small.read(0xFFFFFFFFU) == 1U);
  LONGS_EQUAL(big.store.submap(0U, 0U).point_count, small.store.submap(0U, 0U).point_count);
  CHECK_EQUAL(0, std::memcmp(big.store.points(0U, 0U), small.store.points(0U, 0U),
                             big.store.submap(0U, 0U).point_count * sizeof(Point2)));
  // No obstacle points asked for: none extracted.
  LONGS_EQUAL(0U, small.store.submap(0U, 0U).obstacle_count);
}

TEST(SkeletonReader, init_refuses_invalid_options) {
  std::vector<unsigned char> buffer(1U << 20U);
  Arena arena(buffer.data(), buffer.size());
  SkeletonReader reader;
  SkeletonReaderOptions o;
  o.patch_side = 2U;
  o.skeleton_points = 10U;
  LONGS_EQUAL(0U, SkeletonReader::required_bytes(o));
  CHECK_FALSE(reader.init(o, arena));
  o.patch_side = 64U;
  o.free_threshold = 0.7;  // above occupied_threshold
  CHECK_FALSE(reader.init(o, arena));
  o.free_threshold = 0.35;
  Arena small(buffer.data(), SkeletonReader::required_bytes(o) - 1U);
  CHECK_FALSE(reader.init(o, small));
  CHECK_TRUE(reader.init(o, arena));
  CHECK_FALSE(reader.active());
}
