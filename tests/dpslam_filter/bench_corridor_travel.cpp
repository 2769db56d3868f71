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
// Each section.key=value (a key of DpSlamOptions::table(), as in the INI files, e.g.
// observation.likelihood_temperature=5) is set on every row's options after the row's
// own, so that one option's share of the error can be measured.
#include <cmath>
#include <cstdio>
#include <cstdlib>
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

// The best particle's travel along the corridor (x) after the run, or NaN if the filter
// could not be set up.
double travel_m(const Row& row, std::uint64_t seed) {
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
  for (std::size_t i = 0; i < run.truth.size(); ++i) rig.step(run, world, i);
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
  if (failed > 0) std::fprintf(stderr, "bench_corridor_travel: %d runs could not set up the filter\n", failed);
  return failed > 0 ? 1 : 0;
}
