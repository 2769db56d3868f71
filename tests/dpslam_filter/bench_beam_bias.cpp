// Along-track bias of the bottom level's observation model (core/bottom/beam_model.h).
// A plain program (not a test) that prints figures; build it in a Release directory:
//   cmake --build --preset host-release --target bench_beam_bias
//   build/host-release/tests/dpslam_filter/bench_beam_bias [section.key=value ...]
//
// A robot drives straight down a 3 m corridor in 0.2 m steps; exact scans (181 beams over
// 180 deg, 1 cm range noise) are written into one lineage of the DP map from the TRUE
// poses. Before each scan is written, its log-likelihood is profiled along the corridor
// around the true pose (+-5 cm in 2.5 mm steps) and the offset of the maximum recorded.
// An unbiased model peaks at 0 on average; a negative mean means the model places the
// robot behind where it is, and a filter that follows it shortens every path by about
// (mean offset / step) — even with perfect odometry. The laser faces forward, so a model
// that sees surfaces nearer than they are pulls every match back.
// Rows: plain walls (only the corridor's end walls constrain the motion along it) or
// walls with door recesses every 3 m; laser reach 8 m or 30 m; corridor along the grid
// or turned 0.3 rad to it; the map written from the poses behind the robot only (as in
// SLAM), from every pose of the run first (every viewpoint), or from the last 5 scans
// only (a map as sparse as a new segment's: SDP-SLAM's bottom level starts each segment
// with its first few scans, sdp_slam.h). The last three columns profile the same scans
// on a part of their beams only, by angle from the direction of travel (0-30, 30-60 and
// 60-90 deg to either side): which beams carry the offset.
// Arguments: section.key=value ... (keys of DpSlamOptions::table(), as in the INI files,
// e.g. observation.prior_hits=0.05) set the observation model's options (and
// map.resolution_m the grid's), so that one option's share of the offset can be measured.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "sdpslam/core/bottom/beam_model.h"
#include "sdpslam/core/dpslam_options.h"
#include "option_override.h"
#include "sim_world.h"

namespace {

using namespace sdpslam;

constexpr double kStep_m = 0.2;  // travel between scans
constexpr int kRecentScans = 5;  // the sparse map's scans

// Where the map the scans are profiled against comes from.
enum class History { kBehind, kEveryPose, kRecent };

struct Case {
  bool doors;
  double reach_m;
  double heading_rad;
  History history;
};

// The default options with the command line's overrides.
DpSlamOptions g_options;

constexpr int kSectors = 3;  // beams by angle from the direction of travel, 30 deg each

struct Result {
  double mean_m = 0.0;
  double mean_abs_m = 0.0;
  double sector_mean_m[kSectors] = {};
  int scans = 0;
};

bool run_case(const Case& k, Result* out) {
  constexpr double kLength = 60.0;
  const std::vector<test::Segment> world = test::corridor_world(k.doors, k.heading_rad, kLength);
  DpMap::Options mo;
  mo.origin_x_m = -10.0;
  mo.origin_y_m = -10.0;
  mo.width_m = 80.0;
  mo.height_m = 40.0;
  mo.resolution_m = g_options.map_resolution_m;
  mo.tile_capacity = 6000U;
  mo.observation_capacity = 2000000U;
  std::vector<unsigned char> buffer(AncestryTree::required_arena_bytes(4, 4) + DpMap::required_arena_bytes(mo, 4) + 4096U);
  Arena arena;
  std::unique_ptr<DpMap> map_ptr;
  std::unique_ptr<AncestryTree> tree_ptr;
  NodeId lineage = kNoNode;
  // An empty map (again).
  auto fresh_map = [&]() {
    map_ptr.reset();
    tree_ptr = std::make_unique<AncestryTree>();
    map_ptr = std::make_unique<DpMap>();
    arena.reset(buffer.data(), buffer.size());
    if (!tree_ptr->init(arena, 4, 4) || !map_ptr->init(arena, mo, *tree_ptr)) return false;
    lineage = tree_ptr->create_root();
    return lineage != kNoNode;
  };
  BeamModel beam;
  if (!fresh_map() || !beam.init(g_options.beam, mo.resolution_m)) return false;
  auto scan = std::make_unique<RangeScan>();
  auto rays = std::make_unique<ScanRays>();
  std::vector<ScanRays> recent(kRecentScans);  // ring of the last scans (History::kRecent)
  std::vector<Pose2> recent_pose(kRecentScans);
  int recent_count = 0;
  Rng noise(5U);
  const double c = std::cos(k.heading_rad);
  const double s = std::sin(k.heading_rad);
  auto pose_at = [&](double along_m) { return Pose2{along_m * c, along_m * s, k.heading_rad}; };
  auto make = [&](const Pose2& truth) {
    test::make_scan(world, truth, 0, scan.get(), &noise, 0.01);
    for (std::uint32_t i = 0; i < scan->beam_count; ++i) {
      if (static_cast<double>(scan->ranges_m[i]) >= k.reach_m) scan->ranges_m[i] = scan->geometry.range_max_m;  // no return
    }
    prepare_rays(*scan, rays.get());
  };
  const int steps = static_cast<int>((kLength - 20.0) / kStep_m);
  if (k.history == History::kEveryPose) {
    for (int i = 0; i < steps; ++i) {
      make(pose_at(kStep_m * i));
      beam.update_map(*map_ptr, lineage, *rays, pose_at(kStep_m * i));
    }
  }
  // The offset of the log-likelihood's maximum along the corridor from `along`, on the
  // beams of `sector` only (-1: every beam).
  auto peak_offset = [&](double along, int sector) {
    std::vector<std::uint8_t> kind(rays->kind, rays->kind + rays->count);
    if (sector >= 0) {
      const double lo = sector * M_PI / 6.0;
      for (std::uint32_t b = 0; b < rays->count; ++b) {
        const double a = std::fabs(std::atan2(rays->sin_a[b], rays->cos_a[b]));
        if (!(a >= lo && a < lo + M_PI / 6.0 + (sector == kSectors - 1 ? 1e-9 : 0.0))) {
          rays->kind[b] = static_cast<std::uint8_t>(RangeScan::Beam::kInvalid);
        }
      }
    }
    double best = -1e300;
    double best_offset = 0.0;
    for (int j = -20; j <= 20; ++j) {
      const double offset = 0.0025 * j;
      const double ll = beam.log_likelihood_strided(*map_ptr, lineage, *rays, pose_at(along + offset), 1U, nullptr);
      if (ll > best) {
        best = ll;
        best_offset = offset;
      }
    }
    std::copy(kind.begin(), kind.end(), rays->kind);
    return best_offset;
  };
  double sum = 0.0;
  double sum_abs = 0.0;
  double sector_sum[kSectors] = {};
  int n = 0;
  for (int i = 0; i < steps; ++i) {
    const double along = kStep_m * i;
    make(pose_at(along));
    if (k.history == History::kRecent && recent_count >= kRecentScans) {
      if (!fresh_map()) return false;
      for (int j = 0; j < kRecentScans; ++j) beam.update_map(*map_ptr, lineage, recent[j], recent_pose[j]);
    }
    if (along > 5.0) {  // some map behind the robot first
      const double best_offset = peak_offset(along, -1);
      sum += best_offset;
      sum_abs += std::fabs(best_offset);
      for (int q = 0; q < kSectors; ++q) sector_sum[q] += peak_offset(along, q);
      ++n;
    }
    if (k.history == History::kBehind) beam.update_map(*map_ptr, lineage, *rays, pose_at(along));
    recent[recent_count % kRecentScans] = *rays;
    recent_pose[recent_count % kRecentScans] = pose_at(along);
    ++recent_count;
  }
  out->mean_m = n > 0 ? sum / n : 0.0;
  out->mean_abs_m = n > 0 ? sum_abs / n : 0.0;
  for (int q = 0; q < kSectors; ++q) out->sector_mean_m[q] = n > 0 ? sector_sum[q] / n : 0.0;
  out->scans = n;
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    test::OptionOverride v;
    std::string why;
    if (!test::parse_override(argv[i], g_options, &v, &why) || !test::apply_override(v, &g_options, &why)) {
      std::fprintf(stderr, "bench_beam_bias: '%s': %s\n", argv[i], why.c_str());
      return 2;
    }
    std::printf("with %s\n", argv[i]);
  }
  std::printf("| walls | laser reach | corridor to the grid | map written from | mean offset of the peak | mean |offset| | as path length per %.1f m step | scans | beams 0-30 deg | beams 30-60 deg | beams 60-90 deg |\n",
              kStep_m);
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
  int failed = 0;
  for (bool doors : {false, true}) {
    for (double reach : {8.0, 30.0}) {
      for (double heading : {0.0, 0.3}) {
        for (History history : {History::kBehind, History::kEveryPose, History::kRecent}) {
          Result r;
          if (!run_case(Case{doors, reach, heading, history}, &r)) {
            ++failed;
            continue;
          }
          std::printf("| %s | %.0f m | %.1f rad | %s | %+.1f mm | %.1f mm | %+.2f %% | %d | %+.1f mm | %+.1f mm | %+.1f mm |\n",
                      doors ? "door recesses" : "plain", reach, heading,
                      history == History::kBehind      ? "poses behind"
                      : history == History::kEveryPose ? "every pose"
                                                       : "last 5 scans",
                      r.mean_m * 1e3, r.mean_abs_m * 1e3, 100.0 * r.mean_m / kStep_m, r.scans,
                      r.sector_mean_m[0] * 1e3, r.sector_mean_m[1] * 1e3, r.sector_mean_m[2] * 1e3);
        }
      }
    }
  }
  if (failed > 0) std::fprintf(stderr, "bench_beam_bias: %d cases could not set up their map\n", failed);
  return failed > 0 ? 1 : 0;
}
