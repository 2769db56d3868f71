// No heap after init: many generations of resampling, prune/merge, map updates,
// lookups, extraction and commitment run with the allocation counter armed.
#include <CppUTest/TestHarness.h>

#include <cstdint>

#include "alloc_counter.h"
#include "sdpslam/core/bottom/ancestry_tree.h"
#include "sdpslam/core/bottom/dp_map.h"
#include "test_rng.h"

using sdpslam::CellObservation;
using sdpslam::NodeId;

namespace {

constexpr std::uint32_t kParticles = 24U;

struct CountingSink final : sdpslam::PoseSink {
  std::uint32_t count = 0U;
  void on_committed(std::int64_t, const sdpslam::Pose2&) override { ++count; }
};

alignas(64) unsigned char g_arena[4U << 20U];
sdpslam::AncestryTree g_tree;
sdpslam::DpMap g_map;

}  // namespace

TEST_GROUP(DpStructuresNoHeap){};

TEST(DpStructuresNoHeap, counter_is_armed) { CHECK_TRUE(sdpslam::test::allocation_counting_active()); }

TEST(DpStructuresNoHeap, generations_of_tree_and_map_operations_never_allocate) {
  sdpslam::DpMap::Options o;
  o.width_m = 20.0;
  o.height_m = 20.0;
  o.resolution_m = 0.05;
  o.tile_capacity = 200U;
  o.observation_capacity = 60000U;
  sdpslam::Arena arena(g_arena, sizeof g_arena);
  CHECK_TRUE(g_tree.init(arena, 3U * kParticles, 8192U));
  CHECK_TRUE(g_map.init(arena, o, g_tree));

  NodeId current[kParticles];
  NodeId next[kParticles];
  CellObservation rect_values[32U * 32U];
  std::uint8_t rect_known[32U * 32U];
  CountingSink sink;
  sdpslam::test::SplitMix64 rng(5U);
  std::uint32_t known_total = 0U;

  sdpslam::test::AllocationScope scope;
  current[0] = g_tree.create_root();
  std::uint32_t n = 1U;
  for (std::uint32_t g = 0; g < 400U; ++g) {
    for (std::uint32_t k = 0; k < kParticles; ++k) next[k] = g_tree.add_child(current[rng.below(n)]);
    for (std::uint32_t k = 0; k < n; ++k) g_tree.set_active(current[k], false);
    g_tree.prune(&g_map);
    const std::int32_t cx = static_cast<std::int32_t>(20U + g % 360U);
    for (std::uint32_t k = 0; k < kParticles; ++k) {
      current[k] = next[k];
      g_tree.append_pose(current[k], static_cast<std::int64_t>(g) * 1000, sdpslam::Pose2{1.0, 2.0, 0.5});
      for (std::uint32_t u = 0; u < 40U; ++u) {
        const std::int32_t ix = cx + static_cast<std::int32_t>(rng.below(30U));
        const std::int32_t iy = 100 + static_cast<std::int32_t>(rng.below(30U));
        g_map.add(current[k], ix, iy, 1U, 0U);
        CellObservation v;
        known_total += g_map.lookup(current[k], ix + 1, iy, &v) ? 1U : 0U;
      }
    }
    n = kParticles;
    g_tree.drain_committed(sink);
    if (g % 50U == 0U) {
      g_map.fill_rect(current[0], sdpslam::CellRect{cx, 100, 32U, 32U}, rect_values, rect_known);
      g_map.for_each_known_cell(current[1], [&](std::int32_t, std::int32_t, const CellObservation&) { ++known_total; });
      std::uint32_t poses = 0U;
      g_tree.for_each_pose_from_root(current[2], [&](std::int64_t, const sdpslam::Pose2&) { ++poses; });
      CHECK(poses > 0U);
    }
  }
  const std::size_t allocations = scope.allocations();
  LONGS_EQUAL(0, allocations);
  CHECK_TRUE(g_tree.invariants_hold());
  CHECK_TRUE(g_map.invariants_hold());
  CHECK(known_total > 1000U);
  CHECK(sink.count > 100U);
  CHECK(g_map.tiles_peak() > 4U);
  LONGS_EQUAL(0, g_map.observation_oom_count());
  LONGS_EQUAL(0, g_tree.path_oom_count());
}
