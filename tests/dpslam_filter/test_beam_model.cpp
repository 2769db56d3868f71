// Observation model through the DP map: a scan consistent with the map scores higher
// than the same scan from a shifted or rotated pose; map updates write hits and misses.
#include <CppUTest/TestHarness.h>

#include <memory>
#include <vector>

#include "sdpslam/core/bottom/beam_model.h"
#include "sim_world.h"

using namespace sdpslam;

namespace {
struct MapFixture {
  std::vector<unsigned char> buffer;
  Arena arena;
  AncestryTree tree;
  DpMap map;
  BeamModel beam;
  NodeId root = kNoNode;
  std::unique_ptr<ScanRays> rays = std::make_unique<ScanRays>();
  std::unique_ptr<RangeScan> scan = std::make_unique<RangeScan>();

  explicit MapFixture(BeamModelOptions bo = BeamModelOptions{}) {
    DpMap::Options mo;
    mo.origin_x_m = -5.0;
    mo.origin_y_m = -5.0;
    mo.width_m = 20.0;
    mo.height_m = 15.0;
    mo.resolution_m = 0.05;
    mo.tile_capacity = 2000;
    mo.observation_capacity = 200000;
    buffer.resize(AncestryTree::required_arena_bytes(16, 16) + DpMap::required_arena_bytes(mo, 16) + 256);
    arena.reset(buffer.data(), buffer.size());
    CHECK_TRUE(tree.init(arena, 16, 16));
    CHECK_TRUE(map.init(arena, mo, tree));
    CHECK_TRUE(beam.init(bo, 0.05));
    root = tree.create_root();
  }
};

// A small deterministic generator for test poses and ranges.
struct Lcg {
  std::uint32_t state;
  double uniform(double lo, double hi) {
    state = state * 1664525U + 1013904223U;
    return lo + (hi - lo) * static_cast<double>(state >> 8U) / static_cast<double>(1U << 24U);
  }
};

// Every beam of a 270-degree 1081-beam laser (as many as a scan holds), ranges drawn by
// range_m(); readings at or beyond range_max_m are no-returns.
template <class Draw>
void dense_fan(RangeScan* scan, float range_max_m, Draw&& range_m) {
  scan->geometry.angle_min_rad = -2.356F;
  scan->geometry.angle_increment_rad = 0.004363F;
  scan->geometry.range_min_m = 0.1F;
  scan->geometry.range_max_m = range_max_m;
  scan->beam_count = capacity::kMaxBeams < 1081U ? capacity::kMaxBeams : 1081U;
  for (std::uint32_t b = 0; b < scan->beam_count; ++b) scan->ranges_m[b] = static_cast<float>(range_m());
}

// The scratch of cells_written() and update_map() for the default options at 0.05 m
// cells, zeroed.
std::vector<std::uint64_t> default_scratch() {
  return std::vector<std::uint64_t>(BeamModel::marks_words(BeamModelOptions{}.max_update_range_m, 0.05));
}
}  // namespace

TEST_GROUP(BeamModel){};

TEST(BeamModel, consistent_scan_scores_higher_than_shifted_or_turned_poses) {
  MapFixture f;
  const auto world = test::room_world();
  const Pose2 truth{3.0, 1.0, 0.3};
  test::make_scan(world, truth, 0, f.scan.get());
  prepare_rays(*f.scan, f.rays.get());
  LONGS_EQUAL(0, f.beam.update_map(f.map, f.root, *f.rays, truth));
  const double at_truth = f.beam.log_likelihood(f.map, f.root, *f.rays, truth);
  for (const Pose2& off : {Pose2{0.1, 0.0, 0.0}, Pose2{0.0, -0.1, 0.0}, Pose2{0.0, 0.0, 0.05}, Pose2{0.3, 0.2, -0.1}}) {
    const Pose2 wrong{truth.x_m + off.x_m, truth.y_m + off.y_m, truth.heading_rad + off.heading_rad};
    const double at_wrong = f.beam.log_likelihood(f.map, f.root, *f.rays, wrong);
    CHECK(at_truth > at_wrong + 5.0);
  }
}

TEST(BeamModel, likelihood_grows_as_the_pose_error_shrinks) {
  MapFixture f;
  const auto world = test::room_world();
  const Pose2 truth{1.0, 4.0, -1.0};
  test::make_scan(world, truth, 0, f.scan.get());
  prepare_rays(*f.scan, f.rays.get());
  f.beam.update_map(f.map, f.root, *f.rays, truth);
  double prev = -1e300;
  for (double off : {0.4, 0.2, 0.1, 0.05, 0.0}) {
    const double ll = f.beam.log_likelihood(f.map, f.root, *f.rays, Pose2{truth.x_m + off, truth.y_m, truth.heading_rad});
    CHECK(ll > prev);
    prev = ll;
  }
}

TEST(BeamModel, update_marks_the_end_point_hit_and_the_ray_free) {
  MapFixture f;
  f.scan->geometry.angle_min_rad = 0.0F;
  f.scan->geometry.angle_increment_rad = 0.01F;
  f.scan->geometry.range_min_m = 0.1F;
  f.scan->geometry.range_max_m = 30.0F;
  f.scan->beam_count = 1;
  f.scan->ranges_m[0] = 2.0F;
  prepare_rays(*f.scan, f.rays.get());
  f.beam.update_map(f.map, f.root, *f.rays, Pose2{0.02, 0.02, 0.0});
  std::int32_t ix, iy;
  CellObservation c;
  CHECK_TRUE(f.map.world_to_cell(2.02, 0.02, &ix, &iy));
  CHECK_TRUE(f.map.lookup(f.root, ix, iy, &c));
  LONGS_EQUAL(1, c.hits);
  CHECK_TRUE(f.map.world_to_cell(1.0, 0.02, &ix, &iy));
  CHECK_TRUE(f.map.lookup(f.root, ix, iy, &c));
  LONGS_EQUAL(0, c.hits);
  LONGS_EQUAL(1, c.misses);
  CHECK_TRUE(f.map.world_to_cell(2.5, 0.02, &ix, &iy));
  CHECK_FALSE(f.map.lookup(f.root, ix, iy, &c));
  CHECK(f.beam.stop_probability(CellObservation{10, 0}) > 0.9);
  CHECK(f.beam.stop_probability(CellObservation{0, 10}) < 0.1);
}

TEST(BeamModel, beams_leaving_the_map_are_counted_as_dropped_not_fatal) {
  MapFixture f;
  f.scan->geometry.angle_min_rad = 0.0F;
  f.scan->geometry.angle_increment_rad = 0.01F;
  f.scan->geometry.range_min_m = 0.1F;
  f.scan->geometry.range_max_m = 30.0F;
  f.scan->beam_count = 1;
  f.scan->ranges_m[0] = 14.0F;  // ends beyond x = 15 m
  prepare_rays(*f.scan, f.rays.get());
  CHECK(f.beam.update_map(f.map, f.root, *f.rays, Pose2{5.0, 0.0, 0.0}) > 0U);
  CHECK(f.map.out_of_bounds_count() > 0U);
  CHECK_TRUE(f.map.invariants_hold());
}

// cells_bound() is an upper bound on the new observations update_map() takes at any pose
// and heading (it does not know the pose), within twice what a dense fan of beams
// writes; cells_written() is what update_map() takes, exactly, into a fresh node or one
// that holds some of the cells already. Both hold for a write with a shortened update
// range too.
TEST(BeamModel, the_cells_bound_holds_at_every_pose_and_the_count_is_exact) {
  Lcg lcg{12345U};
  const auto world = test::room_world();
  const BeamModelOptions defaults;
  std::vector<std::uint64_t> marks = default_scratch();
  const auto all_zero = [&marks] {
    for (const std::uint64_t w : marks) {
      if (w != 0U) return false;
    }
    return true;
  };
  for (std::uint32_t trial = 0; trial < 40U; ++trial) {
    MapFixture f;
    const Pose2 pose{lcg.uniform(1.0, 9.0), lcg.uniform(1.0, 4.0), lcg.uniform(-3.14, 3.14)};
    if (trial % 2U == 0U) {
      test::make_scan(world, pose, 0, f.scan.get());
    } else {
      // a dense fan, ranges to 6 m, some beyond max_update_range_m's stand-in
      // (range_max_m: no return)
      dense_fan(f.scan.get(), 5.5F, [&] { return lcg.uniform(0.2, 6.0); });
    }
    prepare_rays(*f.scan, f.rays.get());
    const std::uint64_t counted =
        f.beam.cells_written(f.map, *f.rays, pose, defaults.max_update_range_m, kNoNode, marks.data());
    CHECK_TRUE(all_zero());
    const std::uint32_t before = f.map.observations_used();
    LONGS_EQUAL(0, f.beam.update_map(f.map, f.root, *f.rays, pose));
    const std::uint64_t written = f.map.observations_used() - before;
    const std::uint64_t bound = f.beam.cells_bound(*f.rays);
    CHECK(written > 0U);
    LONGS_EQUAL(written, counted);
    CHECK(bound >= written);
    if (trial % 2U == 1U) CHECK(bound <= 2U * written);
    // A write with a shortened update range.
    MapFixture g;
    const double reach_m = lcg.uniform(0.0, 4.0);
    const std::uint64_t counted_short = g.beam.cells_written(g.map, *f.rays, pose, reach_m, kNoNode, marks.data());
    LONGS_EQUAL(0, g.beam.update_map(g.map, g.root, *f.rays, pose, reach_m));
    const std::uint64_t shortened = g.map.observations_used();
    CHECK(shortened > 0U);
    CHECK(shortened <= written);
    LONGS_EQUAL(shortened, counted_short);
    CHECK(g.beam.cells_bound(*f.rays, reach_m) >= shortened);
    CHECK(g.beam.cells_bound(*f.rays, reach_m) <= bound);
    // Into a node that holds cells already (a restart's root takes several scans): what
    // the full write then adds, exactly.
    const std::uint64_t counted_more =
        g.beam.cells_written(g.map, *f.rays, pose, defaults.max_update_range_m, g.root, marks.data());
    CHECK_TRUE(all_zero());
    LONGS_EQUAL(0, g.beam.update_map(g.map, g.root, *f.rays, pose));
    LONGS_EQUAL(g.map.observations_used() - shortened, counted_more);
    LONGS_EQUAL(0, g.beam.cells_written(g.map, *f.rays, pose, defaults.max_update_range_m, g.root, marks.data()));
  }
}

// update_map() with its write-combining scratch writes the same map as without it: the
// same counts in every cell of every node, the same out-of-map writes counted, the same
// updates reported dropped, and the scratch left zeroed. Several scans go into a root and
// then into its children (whose first records copy the root's view), some from poses near
// the map's edge so that beams leave it.
TEST(BeamModel, write_combining_writes_the_same_map) {
  Lcg lcg{777U};
  const auto world = test::room_world();
  const BeamModelOptions defaults;
  std::vector<std::uint64_t> scratch = default_scratch();
  for (std::uint32_t trial = 0; trial < 12U; ++trial) {
    MapFixture plain;
    MapFixture combined;
    NodeId plain_node = plain.root;
    NodeId combined_node = combined.root;
    for (std::uint32_t k = 0; k < 6U; ++k) {
      if (k == 3U) {  // the later scans go into a child of the root
        plain_node = plain.tree.add_child(plain.root);
        combined_node = combined.tree.add_child(combined.root);
      }
      const Pose2 pose{lcg.uniform(0.5, 9.5), lcg.uniform(0.5, 4.5), lcg.uniform(-3.14, 3.14)};
      if (k % 2U == 0U) {
        test::make_scan(world, pose, 0, plain.scan.get());
      } else {  // a dense fan whose long beams leave the map (it ends at x = 15, y = 10)
        dense_fan(plain.scan.get(), 12.0F, [&] { return lcg.uniform(0.2, 13.0); });
      }
      prepare_rays(*plain.scan, plain.rays.get());
      const double reach_m = k == 4U ? 2.5 : defaults.max_update_range_m;
      const std::uint32_t dropped_plain = plain.beam.update_map(plain.map, plain_node, *plain.rays, pose, reach_m);
      const std::uint32_t dropped_combined =
          combined.beam.update_map(combined.map, combined_node, *plain.rays, pose, reach_m, scratch.data());
      LONGS_EQUAL(dropped_plain, dropped_combined);
      for (const std::uint64_t w : scratch) CHECK_EQUAL(0U, w);
    }
    CHECK(plain.map.out_of_bounds_count() > 0U);
    CHECK_EQUAL(plain.map.out_of_bounds_count(), combined.map.out_of_bounds_count());
    CHECK_EQUAL(plain.map.observations_used(), combined.map.observations_used());
    for (const auto& nodes : {std::make_pair(plain.root, combined.root), std::make_pair(plain_node, combined_node)}) {
      std::vector<std::uint64_t> a;
      std::vector<std::uint64_t> b;
      const auto cell = [](std::int32_t ix, std::int32_t iy, const CellObservation& v) {
        return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(ix) & 0xFFFFU) << 48U) |
               (static_cast<std::uint64_t>(static_cast<std::uint32_t>(iy) & 0xFFFFU) << 32U) |
               (static_cast<std::uint64_t>(v.hits) << 16U) | v.misses;
      };
      plain.map.for_each_known_cell(nodes.first, [&](std::int32_t ix, std::int32_t iy, const CellObservation& v) {
        a.push_back(cell(ix, iy, v));
      });
      combined.map.for_each_known_cell(nodes.second, [&](std::int32_t ix, std::int32_t iy, const CellObservation& v) {
        b.push_back(cell(ix, iy, v));
      });
      CHECK(a.size() > 1000U);
      CHECK_TRUE(a == b);
    }
    CHECK_TRUE(combined.map.invariants_hold());
  }
}

TEST(BeamModel, invalid_options_are_refused) {
  BeamModel b;
  BeamModelOptions o;
  o.sigma_hit_m = 0.0;
  CHECK_FALSE(b.init(o, 0.05));
  o = BeamModelOptions{};
  o.weight_beam_stride = 0;
  CHECK_FALSE(b.init(o, 0.05));
  CHECK_TRUE(b.init(BeamModelOptions{}, 0.05));
}
