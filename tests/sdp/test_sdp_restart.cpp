// Anchorage and restart of the bottom level (Algorithm 1 lines 5-6) through the
// DpSlamFilter API that SDP-SLAM uses.
#include <CppUTest/TestHarness.h>

#include <cmath>
#include <memory>
#include <vector>

#include "../dpslam_filter/filter_harness.h"

using namespace sdpslam;

namespace {

// Four particles, with room in the node pool for anchored segments.
DpSlamOptions restart_options() {
  DpSlamOptions o = test::sim_options(4);
  o.extra_ancestry_nodes = 32U;
  return o;
}

}  // namespace

TEST_GROUP(SdpRestart){};

TEST(SdpRestart, restart_before_the_first_scan_is_refused) {
  test::FilterRig rig;
  CHECK_TRUE(rig.init(test::sim_options(4), 1));
  CHECK_FALSE(rig.filter->restart_segment(Pose2{}));
  LONGS_EQUAL(1, rig.filter->restart_refused_count());
}

TEST(SdpRestart, restart_anchors_the_old_nodes_and_starts_every_particle_at_one_pose) {
  const DpSlamOptions o = restart_options();
  test::FilterRig rig;
  CHECK_TRUE(rig.init(o, 3));
  const test::SimRun run = test::make_loop(1);
  const auto world = test::room_world();
  for (std::size_t i = 0; i < 60; ++i) rig.step(run, world, i);
  NodeId old_nodes[4];
  CellRect rect;
  CHECK_TRUE(rig.filter->map().touched_bounds(&rect));
  std::uint32_t old_known[4];
  for (std::uint32_t i = 0; i < 4; ++i) {
    old_nodes[i] = rig.filter->particle_node(i);
    old_known[i] = 0U;
    rig.filter->map().for_each_known_cell(old_nodes[i], [&](std::int32_t, std::int32_t, const CellObservation&) { ++old_known[i]; });
    CHECK(old_known[i] > 100U);
  }
  const Pose2 start{1.0, 2.0, 0.5};
  CHECK_TRUE(rig.filter->restart_segment(start));
  for (std::uint32_t i = 0; i < 4; ++i) {
    const Pose2 p = rig.filter->particle_pose(i);
    DOUBLES_EQUAL(start.x_m, p.x_m, 0.0);
    DOUBLES_EQUAL(start.heading_rad, p.heading_rad, 0.0);
    // New particles do not descend from the anchored nodes: their maps are independent.
    CHECK_FALSE(rig.filter->tree().is_ancestor_or_self(old_nodes[0], rig.filter->particle_node(i)));
    // Anchored nodes stay active and keep their whole map.
    CHECK_TRUE(rig.filter->tree().is_active(old_nodes[i]));
    std::uint32_t known = 0U;
    rig.filter->map().for_each_known_cell(old_nodes[i], [&](std::int32_t, std::int32_t, const CellObservation&) { ++known; });
    LONGS_EQUAL(old_known[i], known);
  }
  CHECK_TRUE(rig.filter->tree().invariants_hold());
  CHECK_TRUE(rig.filter->map().invariants_hold());
  // The new submap starts with the last few scans only: far fewer cells than the old ones.
  std::uint32_t fresh = 0U;
  rig.filter->map().for_each_known_cell(rig.filter->particle_node(0), [&](std::int32_t, std::int32_t, const CellObservation&) { ++fresh; });
  CHECK(fresh > 0U);
  CHECK(fresh < old_known[0]);
  // Processing continues on the new roots.
  for (std::size_t i = 60; i < 100; ++i) rig.step(run, world, i);
  CHECK_TRUE(rig.filter->tree().invariants_hold());
  // The old nodes can no longer change.
  for (std::uint32_t i = 0; i < 4; ++i) {
    std::uint32_t known = 0U;
    rig.filter->map().for_each_known_cell(old_nodes[i], [&](std::int32_t, std::int32_t, const CellObservation&) { ++known; });
    LONGS_EQUAL(old_known[i], known);
  }
}

TEST(SdpRestart, a_new_segment_starts_with_the_last_scans_placed_as_the_best_lineage_placed_them) {
  const DpSlamOptions o = restart_options();
  test::FilterRig rig;
  CHECK_TRUE(rig.init(o, 3));
  const test::SimRun run = test::make_loop(1);
  const auto world = test::room_world();
  // The best lineage's path: poses every particle agrees on reach the sink, the rest
  // are on the tree.
  struct Path final : PoseSink {
    std::vector<std::int64_t> stamps;
    std::vector<Pose2> poses;
    void on_committed(std::int64_t stamp_us, const Pose2& p) override {
      stamps.push_back(stamp_us);
      poses.push_back(p);
    }
  } path;
  rig.filter->set_pose_sink(&path);
  std::vector<std::unique_ptr<RangeScan>> processed;
  for (std::size_t i = 0; i < 60; ++i) {
    if (rig.step(run, world, i).status == StepResult::Status::kProcessed) {
      processed.push_back(std::make_unique<RangeScan>(*rig.scan));
    }
  }
  CHECK(processed.size() > 5U);
  std::vector<std::int64_t>& stamps = path.stamps;
  std::vector<Pose2>& poses = path.poses;
  const std::size_t committed = stamps.size();
  rig.filter->for_each_best_pose([&](std::int64_t stamp_us, const Pose2& p) {
    stamps.push_back(stamp_us);
    poses.push_back(p);
  });
  CHECK(committed > 0U && committed < stamps.size());
  const Pose2 best_inverse = rig.filter->best_pose().inverse();
  const Pose2 start{1.0, 2.0, 0.5};  // anywhere: the scans follow it
  CHECK_TRUE(rig.filter->restart_segment(start));
  const NodeId fresh = rig.filter->particle_node(0);
  const DpMap& map = rig.filter->map();
  const double res = map.options().resolution_m;
  // Share of a scan's end points (within the update range) that are hits in the new map
  // when the scan is placed at `at`.
  auto hit_share = [&](const RangeScan& scan, const Pose2& at) {
    std::uint32_t ends = 0U;
    std::uint32_t hits = 0U;
    for (std::uint32_t b = 0; b < scan.beam_count; b += 3U) {
      const double r = static_cast<double>(scan.ranges_m[b]);
      if (scan.classify(b) != RangeScan::Beam::kReturn || r > o.beam.max_update_range_m - 0.5) continue;
      const double a = at.heading_rad + static_cast<double>(scan.beam_angle_rad(b));
      const auto ix = static_cast<std::int32_t>(std::floor((at.x_m + r * std::cos(a) - map.options().origin_x_m) / res));
      const auto iy = static_cast<std::int32_t>(std::floor((at.y_m + r * std::sin(a) - map.options().origin_y_m) / res));
      CellObservation obs;
      ++ends;
      if (map.lookup(fresh, ix, iy, &obs) && obs.hits > 0U) ++hits;
    }
    return ends > 0U ? static_cast<double>(hits) / ends : 0.0;
  };
  // The last processed scan at start_pose, and the three before it relative to it.
  CHECK(hit_share(*processed.back(), start) > 0.9);
  std::uint32_t from_committed = 0U;
  for (std::size_t k = processed.size() - 4U; k + 1U < processed.size(); ++k) {
    std::size_t j = 0;
    while (j < stamps.size() && stamps[j] != processed[k]->stamp_us) ++j;
    CHECK(j < stamps.size());  // on the best lineage's path (committed or not)
    if (j < committed) ++from_committed;
    const Pose2 at = start.compose(best_inverse.compose(poses[j]));
    CHECK(hit_share(*processed[k], at) > 0.9);
    CHECK(hit_share(*processed[k], poses[j]) < 0.5);  // not where the old frame had it
  }
  CHECK(from_committed > 0U);  // both routes: poses already committed and still on the tree
  // Nothing older than that.
  std::size_t j = 0;
  const std::size_t older = processed.size() - 5U;
  while (j < stamps.size() && stamps[j] != processed[older]->stamp_us) ++j;
  if (j < stamps.size()) CHECK(hit_share(*processed[older], start.compose(best_inverse.compose(poses[j]))) < 0.9);
  rig.filter->set_pose_sink(nullptr);
  CHECK_TRUE(rig.filter->tree().invariants_hold());
  CHECK_TRUE(rig.filter->map().invariants_hold());
}

TEST(SdpRestart, release_refuses_current_particles_and_frees_anchored_observations) {
  const DpSlamOptions o = restart_options();
  test::FilterRig rig;
  CHECK_TRUE(rig.init(o, 5));
  const test::SimRun run = test::make_loop(1);
  const auto world = test::room_world();
  for (std::size_t i = 0; i < 40; ++i) rig.step(run, world, i);
  NodeId anchored[4];
  for (std::uint32_t i = 0; i < 4; ++i) anchored[i] = rig.filter->particle_node(i);
  CHECK_TRUE(rig.filter->restart_segment(rig.filter->best_pose()));
  CHECK_FALSE(rig.filter->release_anchored(rig.filter->particle_node(0)));
  CHECK_FALSE(rig.filter->release_anchored(kNoNode));
  const std::uint32_t before = rig.filter->map().observations_used();
  for (std::uint32_t i = 0; i < 4; ++i) CHECK_TRUE(rig.filter->release_anchored(anchored[i]));
  CHECK(rig.filter->map().observations_used() < before);
  CHECK_FALSE(rig.filter->tree().contains(anchored[0]) && rig.filter->tree().is_active(anchored[0]));
  CHECK_TRUE(rig.filter->tree().invariants_hold());
  CHECK_TRUE(rig.filter->map().invariants_hold());
}

TEST(SdpRestart, restart_without_room_for_the_new_particles_changes_nothing) {
  DpSlamOptions o = test::sim_options(4);  // no extra nodes: 12 nodes in all
  test::FilterRig rig;
  CHECK_TRUE(rig.init(o, 5));
  const test::SimRun run = test::make_loop(1);
  const auto world = test::room_world();
  for (std::size_t i = 0; i < 40; ++i) rig.step(run, world, i);
  CHECK_TRUE(rig.filter->restart_segment(rig.filter->best_pose()));  // 4 anchored + 5 new
  CHECK_FALSE(rig.filter->restart_segment(rig.filter->best_pose()));  // no room for 5 more
  LONGS_EQUAL(1, rig.filter->restart_refused_count());
  CHECK_TRUE(rig.filter->tree().invariants_hold());
  const StepResult r = rig.step(run, world, 41);
  CHECK(r.status != StepResult::Status::kNotInitialised);
}
