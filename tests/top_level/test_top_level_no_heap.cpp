// No heap after init: ICP matching, skeleton extraction, every PGS operation and the
// top-level particles' resampling run inside an allocation-counting scope once their
// storage is set up.
#include <CppUTest/TestHarness.h>

#include "alloc_counter.h"
#include "sdpslam/core/arena.h"
#include "top/free_space_skeleton.h"
#include "sdpslam/core/top/icp2d.h"
#include "top/segment_graph.h"
#include "top/top_particles.h"
#include "top_level_fixtures.h"

namespace {
sdpslam::Icp2d g_icp;
sdpslam::Point2 g_target[sdpslam::capacity::kMaxIcpPoints];
sdpslam::Point2 g_source[sdpslam::capacity::kMaxIcpPoints];
sdpslam::CellState g_cells[100U * 100U];
sdpslam::Point2 g_skeleton[512];
alignas(16) unsigned char g_buffer[512U * 1024U];
}  // namespace

TEST_GROUP(TopLevelNoHeap){};

TEST(TopLevelNoHeap, icp_skeleton_and_segment_graph_never_allocate_after_init) {
  using namespace sdpslam;
  Arena arena(g_buffer, sizeof g_buffer);
  FreeSpaceSkeleton skeleton;
  CHECK_TRUE(skeleton.init(arena, 100U, 100U));
  SegmentGraphOptions options;
  options.max_levels = 4U;
  options.nodes_per_level = 10U;
  SegmentGraph graph;
  CHECK_TRUE(graph.init(options, arena));
  SdpOptions sdp;
  sdp.max_levels = options.max_levels;
  TopParticles top;
  CHECK_TRUE(top.init(TopParticleOptions::from(sdp), arena));
  Rng top_rng(5U);
  CHECK_TRUE(test::allocation_counting_active());

  test::AllocationScope scope;
  // ICP on a structured scene.
  const std::size_t n = test::structured_scene(g_target, capacity::kMaxIcpPoints, 0.05);
  test::transform_points(Pose2{0.2, -0.1, 0.1}.inverse(), g_target, g_source, n);
  Icp2dOptions icp_options;
  icp_options.max_correspondence_m = 1.0;
  const Icp2dResult match = g_icp.match(g_target, n, g_source, n, Pose2{}, icp_options);
  CHECK_TRUE(match.converged);
  // Skeleton of an L corridor.
  test::fill(g_cells, 100U, 100U, CellState::kUnknown);
  test::rect(g_cells, 100U, 100U, 10, 10, 90, 21, CellState::kFree);
  test::rect(g_cells, 100U, 100U, 10, 10, 21, 90, CellState::kFree);
  GridPatchView view;
  view.width = 100U;
  view.height = 100U;
  view.cells = g_cells;
  const SkeletonResult sk = skeleton.extract(view, SkeletonOptions{}, g_skeleton, 512U);
  CHECK(sk.point_count > 100U);
  // The graph through fill-up, sampling, recording and permanence.
  test::SplitMix64 rng(3U);
  PgsNodeInput nodes[10];
  for (int step = 0; step < 40; ++step) {
    for (PgsNodeInput& nd : nodes) nd.final_pose = Pose2{1.0, rng.uniform(), 0.1};
    if (graph.add_level(nodes, 10U).status == PgsStatus::kFull) {
      CHECK_TRUE(graph.make_oldest_permanent(graph.sample_first(rng.uniform()).node).status == PgsStatus::kOk);
      CHECK_TRUE(graph.add_level(nodes, 10U).status == PgsStatus::kOk);
    }
    top.resample_and_diversify(graph, top_rng);
    top.extend_to_level(graph.level_end() - 1U, 0U, graph, top_rng);
    top.set_error(static_cast<std::uint32_t>(step) % top.size(), rng.uniform());
    if (graph.levels_used() < 2U) continue;
    std::uint32_t chain[4];
    chain[0] = graph.sample_first(rng.uniform()).node;
    for (std::uint32_t k = 1; k < graph.levels_used(); ++k) {
      chain[k] = graph.sample_next(graph.first_live_level() + k - 1U, chain[k - 1U], rng.uniform()).node;
    }
    graph.record_chain_error(graph.first_live_level(), chain, graph.levels_used(), match.mean_nn_error_m + 0.1);
    (void)graph.sample_pair(graph.first_live_level(), rng.uniform());
    (void)graph.pair_probability(graph.first_live_level(), 0U, 0U);
    Pose2 frames[4];
    CHECK_TRUE(graph.compose_chain(chain, graph.levels_used(), frames) == PgsStatus::kOk);
  }
  const std::size_t allocations = scope.allocations();
  LONGS_EQUAL(0, allocations);
  CHECK_TRUE(graph.invariants_hold());
  CHECK(graph.permanent_level_count() > 30U);
}
