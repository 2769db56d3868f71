// Timing of the top-level building blocks: ICP between two 500-point sets and
// free-space skeleton extraction on a 200×200 patch, the wide loop search
// (correlative matching of two 300-point sets over ±3 m and ±6 m, ±0.35 rad), and one
// loop-closure adjustment of the pose graph at the default capacities (every permanent
// submap and live level a node, every loop constraint used). Prints figures; build
// Release.
//   bench_top_level [repetitions]
#include <chrono>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <initializer_list>

#include "loops/frame_graph.h"
#include "sdpslam/core/arena.h"
#include "sdpslam/core/sdp_options.h"
#include "sdpslam/core/loops/correlative_matcher.h"
#include "top/free_space_skeleton.h"
#include "sdpslam/core/top/icp2d.h"
#include "top_level_fixtures.h"

namespace {

using Clock = std::chrono::steady_clock;

sdpslam::Icp2d g_icp;
sdpslam::Point2 g_scene[sdpslam::capacity::kMaxIcpPoints];
sdpslam::Point2 g_target[500];
sdpslam::Point2 g_source[500];
sdpslam::CellState g_cells[200U * 200U];
sdpslam::Point2 g_points[1024];
alignas(16) unsigned char g_buffer[1U << 20U];
sdpslam::Point2 g_outline[4096];
sdpslam::Point2 g_cm_target[300];
sdpslam::Point2 g_cm_source[300];

double micros(Clock::duration d) { return std::chrono::duration<double, std::micro>(d).count(); }
// Process CPU time: less disturbed than wall time when the machine is shared.
double cpu_us(std::clock_t ticks) { return 1e6 * static_cast<double>(ticks) / CLOCKS_PER_SEC; }

// Frame graph at SdpOptions' default capacities: a chain of frames 2.5 m apart, round
// and round a 60 m × 40 m block, whose last lap has a heading bias per step that no
// adjustment has corrected yet (earlier laps were adjusted when their loops came), and
// loop constraints between frames and the frame one lap earlier (exact: the truth),
// spread over the chain, as many as the capacity holds.
int bench_frame_graph(int reps) {
  const sdpslam::SdpOptions defaults;
  sdpslam::FrameGraphOptions o;
  o.max_nodes = defaults.max_permanent_submaps + defaults.max_levels;
  o.max_loops = defaults.max_loop_constraints;
  o.iterations = defaults.graph_iterations;
  o.robust_chi = defaults.loop_robust_chi;
  static unsigned char buffer[16U << 20U];
  sdpslam::Arena arena(buffer, sizeof buffer);
  static sdpslam::FrameGraph graph;
  if (!graph.init(o, arena)) {
    std::fprintf(stderr, "bench_top_level: frame graph of %u nodes does not fit %zu bytes\n", o.max_nodes, sizeof buffer);
    return 1;
  }
  constexpr std::uint32_t kLap = 80U;  // frames per lap of the 200 m block
  const auto truth = [](std::uint32_t k) {
    const double s = 2.5 * static_cast<double>(k % kLap);  // along the lap, m
    const double pi = 3.14159265358979323846;
    if (s < 60.0) return sdpslam::Pose2{s, 0.0, 0.0};
    if (s < 100.0) return sdpslam::Pose2{60.0, s - 60.0, 0.5 * pi};
    if (s < 160.0) return sdpslam::Pose2{160.0 - s, 40.0, pi};
    return sdpslam::Pose2{0.0, 200.0 - s, -0.5 * pi};
  };
  const sdpslam::FrameInfo chain_info = sdpslam::FrameInfo::from_sigma(0.05, 0.01);
  const sdpslam::FrameInfo loop_info = sdpslam::FrameInfo::from_sigma(defaults.loop_sigma_xy_m, defaults.loop_sigma_theta_rad);
  double total_cpu_us = 0.0;
  double worst_wall_us = 0.0;
  std::uint32_t loops = 0U;
  for (int rep = 0; rep < reps; ++rep) {
    graph.clear();
    sdpslam::Pose2 estimate{};
    for (std::uint32_t k = 0; k < o.max_nodes; ++k) {
      sdpslam::Pose2 step = k > 0U ? between(truth(k - 1U), truth(k)) : sdpslam::Pose2{};
      if (k + kLap >= o.max_nodes) step.heading_rad += 0.002;  // the last lap's drift, not yet corrected
      if (k > 0U) estimate = estimate.compose(step);
      (void)graph.add_node(estimate, step, chain_info);
    }
    loops = 0U;
    // Spread over the whole chain, newest first.
    const std::uint32_t spacing = (o.max_nodes - kLap + o.max_loops - 1U) / o.max_loops;
    for (std::uint32_t k = o.max_nodes - 1U; k >= kLap && loops < o.max_loops; k -= spacing) {
      if (graph.add_loop(k - kLap, k, between(truth(k - kLap), truth(k)), loop_info)) ++loops;
    }
    const std::clock_t cpu0 = std::clock();
    const auto t0 = Clock::now();
    graph.optimise();
    const double us = micros(Clock::now() - t0);
    total_cpu_us += cpu_us(std::clock() - cpu0);
    worst_wall_us = us > worst_wall_us ? us : worst_wall_us;
  }
  std::printf("frame_graph %u nodes, %u loops, %u Gauss-Newton steps: cpu mean %.1f ms, wall max %.1f ms per "
              "adjustment (%d runs); objective %.1f -> %.1f\n",
              graph.node_count(), loops, o.iterations, total_cpu_us / reps / 1000.0, worst_wall_us / 1000.0, reps,
              graph.stats().last_chi2_before, graph.stats().last_chi2_after);
  return 0;
}

// Four 80×80 rooms around a cross of 20-cell corridors, doors into the corridors.
void office_patch() {
  using sdpslam::CellState;
  using sdpslam::test::rect;
  sdpslam::test::fill(g_cells, 200U, 200U, CellState::kOccupied);
  rect(g_cells, 200U, 200U, 0, 90, 200, 110, CellState::kFree);  // horizontal corridor
  rect(g_cells, 200U, 200U, 90, 0, 110, 200, CellState::kFree);  // vertical corridor
  const int rooms[4][2] = {{5, 5}, {115, 5}, {5, 115}, {115, 115}};
  for (const auto& r : rooms) {
    rect(g_cells, 200U, 200U, r[0], r[1], r[0] + 80, r[1] + 80, CellState::kFree);
  }
  rect(g_cells, 200U, 200U, 40, 85, 50, 90, CellState::kFree);    // doors
  rect(g_cells, 200U, 200U, 150, 110, 160, 115, CellState::kFree);
  rect(g_cells, 200U, 200U, 85, 150, 90, 160, CellState::kFree);
  rect(g_cells, 200U, 200U, 110, 40, 115, 50, CellState::kFree);
  rect(g_cells, 200U, 200U, 0, 0, 200, 3, CellState::kUnknown);  // unexplored strip
}

}  // namespace

int main(int argc, char** argv) {
  const int reps = argc > 1 ? std::atoi(argv[1]) : 200;
  if (reps < 1) {
    std::fprintf(stderr, "bench_top_level: repetitions must be >= 1\n");
    return 2;
  }
  // ICP: 500 scene points, source = noisy copy moved by (0.2 m, -0.1 m, 5 deg).
  const std::size_t scene = sdpslam::test::structured_scene(g_scene, sdpslam::capacity::kMaxIcpPoints, 0.0240);
  if (scene < 500U) {
    std::fprintf(stderr, "bench_top_level: scene has only %zu points\n", scene);
    return 1;
  }
  for (std::size_t i = 0; i < 500U; ++i) g_target[i] = g_scene[i * scene / 500U];
  const sdpslam::Pose2 truth{0.2, -0.1, 5.0 * 3.14159265358979323846 / 180.0};
  sdpslam::test::transform_points(truth.inverse(), g_target, g_source, 500U);
  sdpslam::test::SplitMix64 rng(1U);
  for (auto& p : g_source) {
    p.x_m += 0.01 * rng.normal();
    p.y_m += 0.01 * rng.normal();
  }
  sdpslam::Icp2dOptions icp_options;
  icp_options.max_correspondence_m = 1.0;
  double icp_total_us = 0.0, icp_min_us = 1e30;
  sdpslam::Icp2dResult r;
  const std::clock_t icp_cpu0 = std::clock();
  for (int i = 0; i < reps; ++i) {
    const auto t0 = Clock::now();
    r = g_icp.match(g_target, 500U, g_source, 500U, sdpslam::Pose2{}, icp_options);
    const double us = micros(Clock::now() - t0);
    icp_total_us += us;
    icp_min_us = us < icp_min_us ? us : icp_min_us;
  }
  const double icp_cpu_us = cpu_us(std::clock() - icp_cpu0) / reps;
  std::printf("icp2d 500x500 points: wall mean %.1f us, min %.1f us, cpu mean %.1f us per match (%d runs); "
              "%u iterations, status %s, mean NN error %.4f m, error vs truth (%.4f m, %.4f m, %.4f rad)\n",
              icp_total_us / reps, icp_min_us, icp_cpu_us, reps, r.iterations, sdpslam::to_string(r.status), r.mean_nn_error_m,
              r.transform.x_m - truth.x_m, r.transform.y_m - truth.y_m, r.transform.heading_rad - truth.heading_rad);

  // Skeleton of a 200×200 office patch at 5 cm.
  sdpslam::Arena arena(g_buffer, sizeof g_buffer);
  sdpslam::FreeSpaceSkeleton skeleton;
  if (!skeleton.init(arena, 200U, 200U)) {
    std::fprintf(stderr, "bench_top_level: skeleton init failed\n");
    return 1;
  }
  office_patch();
  sdpslam::GridPatchView view;
  view.width = 200U;
  view.height = 200U;
  view.resolution_m = 0.05;
  view.cells = g_cells;
  const int sk_reps = reps / 4 > 0 ? reps / 4 : 1;
  double sk_total_us = 0.0, sk_min_us = 1e30;
  sdpslam::SkeletonResult s;
  const std::clock_t sk_cpu0 = std::clock();
  for (int i = 0; i < sk_reps; ++i) {
    const auto t0 = Clock::now();
    s = skeleton.extract(view, sdpslam::SkeletonOptions{}, g_points, 1024U);
    const double us = micros(Clock::now() - t0);
    sk_total_us += us;
    sk_min_us = us < sk_min_us ? us : sk_min_us;
  }
  const double sk_cpu_us = cpu_us(std::clock() - sk_cpu0) / sk_reps;
  std::printf("free_space_skeleton 200x200 cells: wall mean %.1f us, min %.1f us, cpu mean %.1f us per patch "
              "(%d runs); %u ridge cells, %u points, arena %zu bytes\n",
              sk_total_us / sk_reps, sk_min_us, sk_cpu_us, sk_reps, s.ridge_cell_count, s.point_count, arena.used_bytes());
  // Wide loop search: walls of a 20 m × 12 m floor (rooms off a corridor) thinned to
  // 300 points, as a submap's obstacle points are; the source is the same walls moved
  // by (2.3 m, -1.7 m, 0.15 rad). Grid side 318 cells of 0.1 m, as in the accurate profile.
  {
    using sdpslam::test::add_segment;
    std::size_t n = 0U;
    n = add_segment(g_outline, n, 4096U, 0.0, 0.0, 20.0, 0.0, 0.05);
    n = add_segment(g_outline, n, 4096U, 20.0, 0.0, 20.0, 12.0, 0.05);
    n = add_segment(g_outline, n, 4096U, 20.0, 12.0, 0.0, 12.0, 0.05);
    n = add_segment(g_outline, n, 4096U, 0.0, 12.0, 0.0, 0.0, 0.05);
    n = add_segment(g_outline, n, 4096U, 0.0, 5.0, 14.0, 5.0, 0.05);
    n = add_segment(g_outline, n, 4096U, 0.0, 7.0, 17.0, 7.0, 0.05);
    for (int k = 0; k < 4; ++k) {
      n = add_segment(g_outline, n, 4096U, 3.5 + 4.0 * k, 0.0, 3.5 + 4.0 * k, 4.0, 0.05);
      n = add_segment(g_outline, n, 4096U, 2.0 + 5.0 * k, 7.0, 2.0 + 5.0 * k, 10.5 - 0.7 * k, 0.05);
    }
    for (std::size_t i = 0; i < 300U; ++i) g_cm_target[i] = g_outline[i * n / 300U];
    const sdpslam::Pose2 moved{2.3, -1.7, 0.15};
    sdpslam::test::transform_points(moved.inverse(), g_cm_target, g_cm_source, 300U);
    sdpslam::Arena cm_arena(g_buffer, sizeof g_buffer);
    sdpslam::CorrelativeMatcher matcher;
    if (!matcher.init(318U, 300U, sdpslam::CorrelativeMatcher::steps_for(6.0, 0.1, 4U), cm_arena)) {
      std::fprintf(stderr, "bench_top_level: correlative matcher init failed\n");
      return 1;
    }
    for (double window_m : {3.0, 6.0}) {
      sdpslam::CorrelativeOptions co;
      co.window_xy_m = window_m;
      const int cm_reps = reps / 20 > 0 ? reps / 20 : 1;
      sdpslam::CorrelativeResult c;
      double max_us = 0.0;
      const std::clock_t cm_cpu0 = std::clock();
      for (int i = 0; i < cm_reps; ++i) {
        const auto t0 = Clock::now();
        c = matcher.match(g_cm_target, 300U, g_cm_source, 300U, sdpslam::Pose2{}, co);
        const double us = micros(Clock::now() - t0);
        max_us = us > max_us ? us : max_us;
      }
      const double cm_cpu_us = cpu_us(std::clock() - cm_cpu0) / cm_reps;
      std::printf("correlative_matcher 300x300 points, +-%.0f m, +-%.2f rad: cpu mean %.0f us, wall max %.0f us per "
                  "search (%d runs); %u poses scored, found %d, score %.3f (second %.3f), error (%.3f m, %.3f m, %.4f rad)\n",
                  window_m, co.window_theta_rad, cm_cpu_us, max_us, cm_reps, c.poses_scored, c.found() ? 1 : 0, c.score,
                  c.second_score, c.transform.x_m - moved.x_m, c.transform.y_m - moved.y_m,
                  c.transform.heading_rad - moved.heading_rad);
    }
  }
  const int fg_reps = reps / 20 > 0 ? reps / 20 : 1;
  return bench_frame_graph(fg_reps);
}
