// `sdpslam run LOG --mode dpslam --particles N [--config FILE.ini] [--seed S] --out DIR`:
// runs the bottom-level DP-SLAM filter over a log (tools/slam/run_offline.h).
#include <cstdio>
#include <memory>
#include <string>

#include "cli_common.h"
#include "sdpslam/slam/run_offline.h"

namespace sdpslam::cli {
namespace {

struct RunArgs {
  std::string log;
  std::string mode = "dpslam";
  std::uint32_t particles = 0U;  // 0 = from the config
  std::string config;
  std::uint64_t seed = 1U;
  std::string out;
};

std::function<int()> setup_run(CLI::App& app) {
  auto args = std::make_shared<RunArgs>();
  app.add_option("log", args->log, "Robot log (CARMEN .clf[.gz], tinySLAM .dat, DP-SLAM .log)")->required();
  app.add_option("--mode", args->mode, "Algorithm: dpslam (the bottom-level DP-SLAM filter)")
      ->check(CLI::IsMember({"dpslam"}));
  app.add_option("--particles", args->particles, "Bottom-level particles (overrides [filter] particles)");
  app.add_option("--config", args->config, "INI options (see tools/slam/default.ini)");
  app.add_option("--seed", args->seed, "Random seed (same seed, same output)");
  app.add_option("--out", args->out, "Output directory")->required();
  return [args]() -> int {
    slam::RunOptions ro;
    std::string error;
    if (!args->config.empty() && !slam::load_config_ini(args->config, &ro.config, &error)) {
      std::fprintf(stderr, "sdpslam run: %s\n", error.c_str());
      return kExitBadInput;
    }
    if (args->particles != 0U) ro.config.filter.particle_count = args->particles;
    char why[200];
    if (!ro.config.filter.validate(why, sizeof why)) {
      std::fprintf(stderr, "sdpslam run: %s\n", why);
      return kExitUsage;
    }
    ro.seed = args->seed;
    ro.progress = true;
    slam::RunSummary summary;
    const slam::RunStatus st = slam::run_offline(args->log, ro, args->out, &summary, &error);
    switch (st) {
      case slam::RunStatus::kOk:
        std::fprintf(stderr, "sdpslam run: %llu scans (%llu processed) in %.1f s, %zu log errors; outputs in %s\n",
                     static_cast<unsigned long long>(summary.scans), static_cast<unsigned long long>(summary.processed),
                     summary.wall_time_s, summary.log_error_count, args->out.c_str());
        return kExitOk;
      case slam::RunStatus::kBadInput:
        std::fprintf(stderr, "sdpslam run: %s\n", error.c_str());
        return kExitBadInput;
      case slam::RunStatus::kIoError:
        std::fprintf(stderr, "sdpslam run: %s\n", error.c_str());
        return kExitIo;
      default:
        std::fprintf(stderr, "sdpslam run: internal error: %s\n", error.c_str());
        return kExitInternal;
    }
  };
}

}  // namespace

SDPSLAM_REGISTER_COMMAND(run, "run", "Run SLAM over a log: trajectory, map and stats", 40, setup_run);

}  // namespace sdpslam::cli
