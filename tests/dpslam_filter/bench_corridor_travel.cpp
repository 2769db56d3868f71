// How far the bottom-level filter (core/bottom/dpslam_filter.h) believes the robot went
// down a corridor it drove with PERFECT odometry. A plain program (not a test) that
// prints figures; build it in a Release directory:
//   cmake --build --preset host-release --target bench_corridor_travel
//   build/host-release/tests/dpslam_filter/bench_corridor_travel [SEEDS] [section.key=value ...]
//
// The robot drives 60 m straight down a 3 m corridor (sim_world.h corridor_world: plain
// walls, or a door recess every 3 m) whose end walls stay out of its 30 m laser's
// reach; scans are exact (181 beams over 180 deg). Odometry is the true motion, so the
// filter's only errors are its own: after the run, the best particle's travel along the
// corridor is compared with 60 m, for each seed (SEEDS, default 20). The filter is the
// bottom level as `sdpslam run` configures it by default (DpSlamOptions with the default
// profile, sdp_profile.h: 10 particles, scan-matching proposal), in a map large enough
// for the corridor. Rows: odometry or scan-matching proposal, with the motion model's
// default translation noise or none.
// An unbiased filter scatters around 0 %; a negative mean is a filter that shortens
// paths (the observation model prefers poses behind the true one: bench_beam_bias).
// Without translation noise the exact odometry pins each step's length; what is left
// comes from the heading noise (a path that wanders covers less of the corridor) and,
// with scan matching, from the noise drawn around each match.
// Then one run is diagnosed (plain corridor, scan matching, no translation noise, seed
// 1): the mean log-likelihood of each new scan along the robot's heading around where
// its proposal starts (a slope there is what the scan match follows against the motion
// prior), and the hits and misses of the wall cells behind, beside and ahead of the
// robot at the end: a wall seen so far only from behind, at grazing incidence, holds
// the misses of beams that passed through its cells' free part and few hits yet.
// Each section.key=value (a key of DpSlamOptions::table(), as in the INI files, e.g.
// observation.likelihood_temperature=5) is set on every row's options after the row's
// own, so that one option's share of the error can be measured.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include "filter_harness.h"
#include "sdpslam/core/sdp_profile.h"
#include "option_override.h"

namespace {

using namespace sdpslam;

constexpr double kTravel_m = 60.0;
constexpr double kOdometryStep_m = 0.1;

std::vector<test::OptionOverride> g_overrides;

// The bottom level as `sdpslam run` configures it by default (sdp_profile.h).
DpSlamOptions product_options() {
  DpSlamOptions o;
  apply_profile(kDefaultSdpProfile, &o, nullptr);
  return o;
}

struct Row {
  bool doors;
  bool scan_match;
  bool translation_noise;
};

// What the diagnosed run (`diagnose` of travel_m()) measured.
constexpr int kShifts = 7;  // -6 .. +6 cm along the corridor
constexpr double kShiftStep_m = 0.02;
constexpr double kWallFrom_m[] = {-2.0, 0.0, 1.0, 2.0, 4.0, 6.0, 8.0};
constexpr std::size_t kWallStretches = std::size(kWallFrom_m);
constexpr double kWallStretch_m = 0.5;
constexpr double kProfileAfter_m = 2.0;  // the first scans see a map still being started
struct Diagnosis {
  double log_likelihood_sum[kShifts] = {};  // relative to the prediction's
  int scans = 0;
  std::uint32_t wall_hits[kWallStretches] = {};
  std::uint32_t wall_misses[kWallStretches] = {};
};

// Before each scan: the beam model's log-likelihood of that scan (its rays in *rays) in
// the best particle's map at the pose the odometry predicts from that particle (where
// its proposal starts), moved along its heading by each shift.
void profile_scan(const test::FilterRig& rig, const BeamModel& beam, const Pose2& predicted, ScanRays* rays,
                  Diagnosis* d) {
  prepare_rays(*rig.scan, rays);
  const NodeId node = rig.filter->best_node();
  const double at_prediction = beam.log_likelihood(rig.filter->map(), node, *rays, predicted);
  for (int k = 0; k < kShifts; ++k) {
    const Pose2 moved = predicted.compose(Pose2{kShiftStep_m * (k - kShifts / 2), 0.0, 0.0});
    d->log_likelihood_sum[k] += beam.log_likelihood(rig.filter->map(), node, *rays, moved) - at_prediction;
  }
  ++d->scans;
}

// After the run: the counts of both walls' cells, in stretches of kWallStretch_m from
// each distance ahead of the robot (negative: behind). A wall's row is the row at its
// side, or next to it, with the most hits in the stretches (the wall may lie on a cell
// boundary).
void count_wall(const test::FilterRig& rig, const Pose2& robot, Diagnosis* d) {
  const DpMap& map = rig.filter->map();
  const NodeId node = rig.filter->best_node();
  const double res = map.options().resolution_m;
  const auto stretch = static_cast<std::int32_t>(kWallStretch_m / res + 0.5);
  for (double wall_y : {-1.5, 1.5}) {
    std::int32_t ix_robot;
    std::int32_t iy_wall;
    if (!map.world_to_cell(robot.x_m, wall_y, &ix_robot, &iy_wall)) continue;
    // Row iy's counts in stretch k.
    const auto count = [&](std::int32_t iy, std::size_t k, std::uint32_t* hits, std::uint32_t* misses) {
      const std::int32_t ix0 = ix_robot + static_cast<std::int32_t>(std::lround(kWallFrom_m[k] / res));
      for (std::int32_t ix = ix0; ix < ix0 + stretch; ++ix) {
        CellObservation v;
        if (!map.lookup(node, ix, iy, &v)) continue;
        *hits += v.hits;
        *misses += v.misses;
      }
    };
    std::int32_t wall_row = iy_wall;
    std::uint32_t wall_row_hits = 0U;
    for (std::int32_t iy = iy_wall - 1; iy <= iy_wall + 1; ++iy) {
      std::uint32_t hits = 0U;
      std::uint32_t misses = 0U;
      for (std::size_t k = 0; k < kWallStretches; ++k) count(iy, k, &hits, &misses);
      if (hits > wall_row_hits) {
        wall_row_hits = hits;
        wall_row = iy;
      }
    }
    for (std::size_t k = 0; k < kWallStretches; ++k) count(wall_row, k, &d->wall_hits[k], &d->wall_misses[k]);
  }
}

// The best particle's travel along the corridor (x) after the run, or NaN if the filter
// could not be set up. With `diagnose`, also fills it.
double travel_m(const Row& row, std::uint64_t seed, Diagnosis* diagnose = nullptr) {
  DpSlamOptions o = product_options();
  o.map_width_m = 2.0 * (kTravel_m + 10.0);  // centred on the first pose
  o.map_height_m = 20.0;
  o.map_observations_base = 3000000U;
  o.map_observations_per_particle = 100000U;
  if (!row.translation_noise) {
    o.motion.alpha_trans_from_trans = 0.0;
    o.motion.alpha_trans_from_rot = 0.0;
    o.motion.min_sigma_trans_m = 0.0;
  }
  o.proposal = row.scan_match ? DpSlamOptions::Proposal::kScanMatch : DpSlamOptions::Proposal::kOdometry;
  std::string why;
  for (const test::OptionOverride& v : g_overrides) {
    if (!test::apply_override(v, &o, &why)) return std::nan("");
  }
  test::FilterRig rig;
  if (!rig.init(o, seed)) return std::nan("");
  const std::vector<test::Segment> world = test::corridor_world(row.doors, 0.0, kTravel_m + 40.0);
  test::SimRun run;
  const int steps = static_cast<int>(kTravel_m / kOdometryStep_m + 0.5);
  for (int i = 0; i <= steps; ++i) run.truth.push_back(Pose2{kOdometryStep_m * i, 0.0, 0.0});
  run.odom = run.truth;
  BeamModel beam;
  std::unique_ptr<ScanRays> rays;
  if (diagnose != nullptr) {
    if (!beam.init(o.beam, o.map_resolution_m)) return std::nan("");
    rays = std::make_unique<ScanRays>();
  }
  std::size_t last_processed = 0U;
  for (std::size_t i = 0; i < run.truth.size(); ++i) {
    if (diagnose != nullptr && run.truth[i].x_m >= kProfileAfter_m) {
      test::make_scan(world, run.truth[i], static_cast<std::int64_t>(i) * 100000, rig.scan.get());
      const Pose2 predicted = rig.filter->best_pose().compose(between(run.odom[last_processed], run.odom[i]));
      profile_scan(rig, beam, predicted, rays.get(), diagnose);
    }
    if (rig.step(run, world, i).status == StepResult::Status::kProcessed) last_processed = i;
  }
  if (diagnose != nullptr) count_wall(rig, run.truth.back(), diagnose);
  return rig.filter->best_pose().x_m;
}

}  // namespace

int main(int argc, char** argv) {
  const long seeds = argc > 1 ? std::strtol(argv[1], nullptr, 10) : 20L;
  if (seeds < 1 || seeds > 1000) {
    std::fprintf(stderr, "usage: bench_corridor_travel [SEEDS: 1 .. 1000, default 20] [section.key=value ...]\n");
    return 2;
  }
  for (int i = 2; i < argc; ++i) {
    test::OptionOverride v;
    std::string why;
    if (!test::parse_override(argv[i], product_options(), &v, &why)) {
      std::fprintf(stderr, "bench_corridor_travel: '%s': %s\n", argv[i], why.c_str());
      return 2;
    }
    g_overrides.push_back(v);
    std::printf("with %s\n", argv[i]);
  }
  std::printf("| walls | proposal | translation noise | mean travel error | worst seed | seeds |\n");
  std::printf("|---|---|---|---|---|---|\n");
  int failed = 0;
  for (bool doors : {false, true}) {
    for (bool scan_match : {false, true}) {
      for (bool noise : {true, false}) {
        double sum = 0.0;
        double worst = 0.0;
        long worst_seed = 0;
        for (long s = 1; s <= seeds; ++s) {
          const double x = travel_m(Row{doors, scan_match, noise}, static_cast<std::uint64_t>(s));
          if (std::isnan(x)) {
            ++failed;
            continue;
          }
          const double e = 100.0 * (x - kTravel_m) / kTravel_m;
          sum += e;
          if (worst_seed == 0 || std::fabs(e) > std::fabs(worst)) {
            worst = e;
            worst_seed = s;
          }
        }
        std::printf("| %s | %s | %s | %+.2f %% | %+.2f %% (%ld) | %ld |\n", doors ? "door recesses" : "plain",
                    scan_match ? "scan match" : "odometry", noise ? "default" : "none", sum / static_cast<double>(seeds),
                    worst, worst_seed, seeds);
      }
    }
  }
  // Why the path comes out short: the run of the plain corridor with scan matching and
  // no translation noise (its poses stay right along the corridor), seed 1.
  Diagnosis d;
  if (std::isnan(travel_m(Row{false, true, false}, 1U, &d)) || d.scans == 0) {
    ++failed;
  } else {
    std::printf("\nPlain corridor, scan match, no translation noise, seed 1: mean log-likelihood of each new scan "
                "(%d scans) in the best particle's map, at the odometry's prediction from that particle moved along "
                "its heading, relative to the prediction\n\n",
                d.scans);
    std::printf("| shift |");
    for (int k = 0; k < kShifts; ++k) std::printf(" %+.0f cm |", 100.0 * kShiftStep_m * (k - kShifts / 2));
    std::printf("\n|---|");
    for (int k = 0; k < kShifts; ++k) std::printf("---|");
    std::printf("\n| log-likelihood |");
    for (int k = 0; k < kShifts; ++k) std::printf(" %+.3f |", d.log_likelihood_sum[k] / d.scans);
    std::printf("\n\nThe same run's map after the run: both walls' cells, %.1f m of each from the distance given "
                "(negative: behind the robot)\n\n",
                kWallStretch_m);
    std::printf("| from the robot | hits | misses | hits / (hits + misses) |\n|---|---|---|---|\n");
    for (std::size_t k = 0; k < kWallStretches; ++k) {
      const std::uint32_t n = d.wall_hits[k] + d.wall_misses[k];
      std::printf("| %+.1f m | %u | %u | ", kWallFrom_m[k], d.wall_hits[k], d.wall_misses[k]);
      if (n > 0U) {
        std::printf("%.2f |\n", static_cast<double>(d.wall_hits[k]) / static_cast<double>(n));
      } else {
        std::printf("- |\n");
      }
    }
  }
  if (failed > 0) std::fprintf(stderr, "bench_corridor_travel: %d runs could not set up the filter\n", failed);
  return failed > 0 ? 1 : 0;
}
