// `sdpslam localize LOG --map map.yaml --out D`: Monte Carlo localization of a log on a
// saved map (firmware-host/runtime/slam run_localize.h), globally or from --start.
#include <cstdio>
#include <memory>
#include <string>

#include "cli_common.h"
#include "sdpslam/slam/run_localize.h"

namespace sdpslam::cli {
namespace {

struct LocalizeArgs {
  std::string log;
  std::string map;
  std::string out;
  std::string start;
  std::uint64_t seed = 1U;
  std::uint64_t skip_scans = 0U;
  std::uint32_t min_particles = 0U;
  std::uint32_t max_particles = 0U;
  bool quiet = false;
  BagTopics bag;
};

int run_localize_command(const LocalizeArgs& a) {
  slam::LocalizeRunOptions o;
  o.seed = a.seed;
  o.skip_scans = a.skip_scans;
  a.bag.apply(&o.log);
  if (a.min_particles != 0U) o.localizer.min_particles = a.min_particles;
  if (a.max_particles != 0U) o.localizer.max_particles = a.max_particles;
  if (!a.start.empty()) {
    if (!slam::parse_start_pose(a.start, &o.start)) {
      std::fprintf(stderr, "sdpslam localize: --start: expected x,y,theta (m, m, rad), not '%s'\n", a.start.c_str());
      return kExitUsage;
    }
    o.have_start = true;
  }
  o.painter = figure_painter();
  Progress progress("KiB", file_size_kib(a.log), a.quiet);
  o.progress = [&progress](std::uint64_t bytes) { progress.update(bytes / 1024U); };
  slam::LocalizeSummary s;
  std::string error;
  const slam::LocalizeStatus st = slam::run_localize(a.log, a.map, o, a.out, &s, &error);
  progress.finish();
  if (st != slam::LocalizeStatus::kOk) {
    std::fprintf(stderr, "sdpslam localize: %s\n", error.c_str());
    return st == slam::LocalizeStatus::kBadInput ? kExitBadInput
           : st == slam::LocalizeStatus::kIoError ? kExitIo
                                                   : kExitInternal;
  }
  std::printf("sdpslam localize: %llu scans (%llu updates) of %.0f s in %.2f s CPU (%.3f ms per scan); ",
              static_cast<unsigned long long>(s.scans), static_cast<unsigned long long>(s.updates), s.log_seconds,
              s.cpu_seconds, s.cpu_ms_per_scan_mean);
  if (s.converged_at_scan >= 0) {
    std::printf("converged at scan %lld", static_cast<long long>(s.converged_at_scan));
  } else {
    std::printf("never converged (spread stayed above %.1f m)", slam::kConvergedSpreadM);
  }
  std::printf(", final spread %.3f m with %u particles; state %.1f MiB; outputs in %s\n", s.final_spread_m,
              s.final_particles, static_cast<double>(s.state_bytes) / (1024.0 * 1024.0), a.out.c_str());
  return kExitOk;
}

std::function<int()> setup_localize(CLI::App& app) {
  auto args = std::make_shared<LocalizeArgs>();
  app.add_option("LOG", args->log, "robot log (as for run)")->required();
  app.add_option("--map", args->map, "saved map: map.yaml (sdpslam run's, or map_server's with a PGM)")
      ->required()
      ->check(non_empty());
  app.add_option("--out", args->out, "Output directory")->required()->check(non_empty());
  app.add_option("--start", args->start,
                 "x,y,theta: the start pose in the map's frame (m, m, rad); without it the robot is localized "
                 "globally");
  app.add_option("--skip-scans", args->skip_scans, "leave out this many scans at the start of the log")
      ->check(whole_number(UINT64_MAX));
  app.add_option("--min-particles", args->min_particles, "KLD-sampling's floor (default 200)")
      ->check(whole_number(1000000U));
  app.add_option("--max-particles", args->max_particles, "KLD-sampling's ceiling and memory (default 20000)")
      ->check(whole_number(1000000U));
  app.add_option("--seed", args->seed, "Random seed (same seed, same output)")->check(whole_number(UINT64_MAX));
  add_bag_options(app, &args->bag);
  app.add_flag("--quiet", args->quiet, "no progress display (errors, warnings and the summary still print)");
  return [args] { return run_localize_command(*args); };
}

}  // namespace

SDPSLAM_REGISTER_COMMAND(localize, "localize", "Localize a log on a saved map (Monte Carlo localization)", 45,
                         setup_localize);

}  // namespace sdpslam::cli
