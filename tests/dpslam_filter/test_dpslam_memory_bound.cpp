// Memory of the bottom-level filter is bounded by the explored area, not by run length
// (paper §II-A: merged and pruned ancestry keeps one observation per live lineage and
// cell): driving the same synthetic loop over and over, the pools' high-water marks
// stop growing once the room has been seen.
#include <CppUTest/TestHarness.h>

#include <cstdio>
#include <vector>

#include "filter_harness.h"

using namespace sdpslam;
using sdpslam::test::FilterRig;

namespace {

struct HighWater {
  std::uint32_t nodes = 0U;
  std::uint32_t path_entries = 0U;
  std::uint32_t observations = 0U;
  std::uint32_t tiles = 0U;
};

HighWater high_water(const DpSlamFilter& f) {
  return HighWater{f.tree().peak_used(), f.tree().path_entries_peak(), f.map().observations_peak(),
                   f.map().tiles_peak()};
}

}  // namespace

TEST_GROUP(DpSlamMemoryBound){};

TEST(DpSlamMemoryBound, pool_high_water_marks_stop_growing_after_the_first_laps) {
  constexpr std::uint32_t kLaps = 10U;
  constexpr std::uint32_t kSettledLap = 3U;
  const test::SimRun run = test::make_loop(kLaps);
  const std::size_t per_lap = (run.truth.size() - 1U) / kLaps;
  const auto world = test::room_world();
  FilterRig rig;
  CHECK_TRUE(rig.init(test::sim_options(10), 5));
  std::vector<HighWater> after_lap;
  std::vector<std::uint32_t> used_after_lap;
  for (std::size_t i = 0; i < run.truth.size(); ++i) {
    rig.step(run, world, i);
    if (i > 0U && i % per_lap == 0U) {
      after_lap.push_back(high_water(*rig.filter));
      used_after_lap.push_back(rig.filter->map().observations_used());
    }
  }
  LONGS_EQUAL(kLaps, after_lap.size());
  for (std::size_t l = 0; l < after_lap.size(); ++l) {
    std::printf("\n  lap %zu: nodes %u, path entries %u, observations %u (in use %u), tiles %u", l + 1U,
                after_lap[l].nodes, after_lap[l].path_entries, after_lap[l].observations, used_after_lap[l],
                after_lap[l].tiles);
  }
  std::printf("\n");
  const HighWater& settled = after_lap[kSettledLap - 1U];
  const HighWater& last = after_lap[kLaps - 1U];
  // The first lap really fills the pools (the check below could fail).
  CHECK(after_lap[0].observations > 10000U);
  CHECK(after_lap[0].tiles > 50U);
  // Tiles cover the room; later laps add at most a few at its edge (pose spread).
  CHECK(last.tiles <= settled.tiles + settled.tiles / 20U);
  // Nodes and path entries are bounded by the particle count (3N, uncommitted poses).
  CHECK(last.nodes <= rig.filter->tree().capacity());
  CHECK(last.nodes <= settled.nodes + 2U);
  CHECK(last.path_entries <= settled.path_entries + settled.path_entries / 10U);
  // Observations: one per live lineage and cell; 7 more laps may add at most 10 %.
  CHECK(last.observations <= settled.observations + settled.observations / 10U);
  LONGS_EQUAL(0, rig.filter->stats().map_updates_dropped);
  CHECK_TRUE(rig.filter->map().invariants_hold());
  CHECK_TRUE(rig.filter->tree().invariants_hold());
}
