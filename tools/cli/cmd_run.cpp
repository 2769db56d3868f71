// `sdpslam run LOG [--mode sdp|dpslam] [--top-particles T] [--particles B]
//               [--topology sdp|segslam] [--profile accurate|paper] [--config FILE.ini]
//               [--seed S] [--memory-budget-mib M] [--snapshot FILE [--snapshot-every-s S]]
//               [--resume FILE | --extend FILE [--extend-window-m M]] --out DIR`
// sdp (the default): Segmented DP-SLAM, 60 top-level / 10 bottom-level particles
// (firmware-host/runtime/slam/run_sdp.h), starting from the options of --profile (core/sdp_profile.h:
// accurate by default, or the paper's algorithm) with the --config file's keys on top;
// dpslam: the bottom-level DP-SLAM filter alone, the baseline (firmware-host/runtime/slam/run_offline.h).
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>

#include "cli_common.h"
#include "sdpslam/slam/config_ini.h"
#include "sdpslam/slam/option_text.h"
#include "sdpslam/slam/run_offline.h"
#include "sdpslam/core/sdp_profile.h"
#include "sdpslam/slam/run_sdp.h"
#include "sdpslam/io/snapshot_file.h"
#include "sdpslam/slam/session_continuation.h"

namespace sdpslam::cli {
namespace {

// The same default as sdpslamd's [daemon] memory_budget_mib.
constexpr std::uint32_t kDefaultMemoryBudgetMib = 128U;

struct RunArgs {
  std::string log;
  bool quiet = false;
  std::string mode = "sdp";
  std::uint32_t particles = 0U;      // 0 = from the config (sdp: the profile's 10 unless the file says)
  std::uint32_t top_particles = 0U;  // 0 = from the sdp config (60)
  std::string topology;
  std::string profile;               // empty = kDefaultSdpProfile
  std::string config;
  std::uint64_t seed = 1U;
  std::string out;
  std::uint32_t memory_budget_mib = kDefaultMemoryBudgetMib;
  std::string snapshot;
  double snapshot_every_s = 0.0;
  std::string resume;
  std::string extend;
  double extend_window_m = slam::SessionContinuation::kDefaultWindowM;
  BagTopics bag;
  bool print_config = false;
};

// What sets the options of a run, for snapshots (io/snapshot_file.h): the mode, the
// profile, the flags that override keys, and the configuration file's text. A snapshot
// resumes only under the same (the seed is not part of it: the generators' state is).
std::uint64_t config_fingerprint(const RunArgs& a, SdpProfile profile, std::string* error) {
  std::string text = "mode=" + a.mode + "\nprofile=" + to_string(profile) + "\nparticles=" +
                     std::to_string(a.particles) + "\ntop_particles=" + std::to_string(a.top_particles) +
                     "\ntopology=" + a.topology + "\nscan_topic=" + a.bag.scan_topic +
                     "\nodom_topic=" + a.bag.odom_topic + "\nconfig:\n";
  if (!a.config.empty()) {
    std::FILE* f = std::fopen(a.config.c_str(), "rb");
    if (f == nullptr) {
      *error = a.config + ": cannot be read";
      return 0U;
    }
    char buf[4096];
    std::size_t n = 0U;
    while ((n = std::fread(buf, 1, sizeof buf, f)) > 0U) text.append(buf, n);
    std::fclose(f);
  }
  return io::fingerprint(text);
}

int report(const char* what, int code, const std::string& error) {
  std::fprintf(stderr, "sdpslam run: %s%s\n", what, error.c_str());
  return code;
}

// The whole SLAM state is one arena sized from the options before any work (the fixed
// memory of the core). It is sized by the runners, which own the core's classes: the
// command line includes none of their headers (the core is built without RTTI, and
// UBSan's vptr check then refuses the core's objects in the host tools). It must fit the declared budget, as sdpslamd's [daemon]
// memory_budget_mib: a capacity with a digit too many asks for gigabytes, and is refused
// here with the size it asked for instead of failing or swapping mid-run. 0 bytes: the
// options' sizes overflow.
int check_memory_budget(const RunArgs& a, std::size_t arena_bytes) {
  if (arena_bytes == 0U) {
    return report("", kExitUsage, "the options' state size overflows (lower the [map]/[sdp] capacities)");
  }
  const double need_mib = static_cast<double>(arena_bytes) / (1024.0 * 1024.0);
  if (need_mib > static_cast<double>(a.memory_budget_mib)) {
    char text[240];
    std::snprintf(text, sizeof text,
                  "the SLAM state needs %.1f MiB, above --memory-budget-mib %u (lower the [map]/[sdp] capacities or "
                  "raise the budget)",
                  need_mib, a.memory_budget_mib);
    return report("", kExitUsage, text);
  }
  return kExitOk;
}

// Whether the INI file has a `[name]` section (the file was read whole before: a read
// failure here only means no warning).
bool ini_has_section(const std::string& path, const char* name) {
  std::FILE* f = std::fopen(path.c_str(), "r");
  if (f == nullptr) return false;
  const std::string want = std::string("[") + name + "]";
  char line[512];
  bool found = false;
  while (!found && std::fgets(line, sizeof line, f) != nullptr) {
    const char* p = line;
    while (*p == ' ' || *p == '\t') ++p;
    found = std::strncmp(p, want.c_str(), want.size()) == 0;
  }
  std::fclose(f);
  return found;
}

// The log reader's repairs of odometry that ran against the log's own velocity
// (io::LogReader::next()): worth a line, the map depends on them.
void report_odometry_repairs(std::size_t repaired) {
  if (repaired == 0U) return;
  std::fprintf(stderr,
               "sdpslam run: %zu odometry increments moved against the log's measured velocity (reverse driving "
               "integrated as forward) and were mirrored\n",
               repaired);
}

// Impossible input the reader handled by its documented rules (io::LogReader::next()).
void report_implausible(std::size_t jumps, std::size_t backwards, const std::string& first_backwards_at) {
  if (jumps > 0U) {
    std::fprintf(stderr,
                 "sdpslam run: %zu odometry increments beyond the plausible speed or turn rate ([log] max_speed_mps, "
                 "max_turn_rate_radps) were not applied (named above)\n",
                 jumps);
  }
  if (backwards > 0U) {
    std::fprintf(stderr,
                 "sdpslam run: %zu scans are stamped before the scan they follow (the first at %s); processed in file "
                 "order, stamps as written\n",
                 backwards, first_backwards_at.c_str());
  }
}

// `config` holds the profile's bottom-level options with the file's keys on top; `sdp`
// the profile's top-level options, the file's [sdp] keys go on top of them here.
int run_sdp_mode(const RunArgs& a, const slam::SlamConfig& config, const SdpOptions& sdp, SdpProfile profile) {
  slam::SdpRunOptions ro;
  ro.config = config;
  ro.sdp = sdp;
  ro.profile = profile;
  std::string error;
  if (!a.config.empty() && !slam::load_sdp_ini(a.config, &ro.sdp, &error)) {
    return report("", kExitBadInput, error);
  }
  if (a.particles != 0U) ro.config.filter.particle_count = a.particles;  // else the profile's B or the file's
  if (a.top_particles != 0U) ro.sdp.top_particles = a.top_particles;
  if (!a.topology.empty()) {
    if (slam::apply_sdp_key(&ro.sdp, "topology", a.topology.c_str(), &error) != slam::SdpKeyResult::kApplied) {
      return report("", kExitUsage, error);
    }
  }
  // Every check the core makes at init, before any work: a refusal names the key (and
  // the config's line that set it).
  if (!slam::sdp_check_options(ro, &error)) return report("", kExitUsage, slam::locate_option_error(a.config, error));
  if (a.print_config) {
    std::printf("; sdpslam run --mode sdp --profile %s: the effective configuration\n%s\n%s\n%s", to_string(profile),
                slam::options_ini_text(DpSlamOptions::table(), ro.config.filter).c_str(),
                slam::options_ini_text(slam::log_option_table(), ro.config.log).c_str(),
                slam::options_ini_text(SdpOptions::table(), ro.sdp).c_str());
    return kExitOk;
  }
  if (const int rc = check_memory_budget(a, slam::sdp_state_bytes(ro)); rc != kExitOk) {
    return rc;
  }
  ro.seed = a.seed;
  ro.painter = figure_painter();
  ro.snapshot_path = a.snapshot;
  ro.snapshot_every_s = a.snapshot_every_s;
  ro.resume_path = a.resume;
  ro.extend_path = a.extend;
  ro.extend_window_m = a.extend_window_m;
  if (!a.snapshot.empty() || !a.resume.empty() || !a.extend.empty()) {
    ro.config_fingerprint = config_fingerprint(a, profile, &error);
    if (!error.empty()) return report("", kExitBadInput, error);
  }
  Progress progress("KiB", file_size_kib(a.log), a.quiet);
  ro.progress = [&progress](std::uint64_t bytes) { progress.update(bytes / 1024U); };
  slam::SdpRunSummary s;
  const slam::SdpRunStatus status = slam::run_sdp_offline(a.log, ro, a.out, &s, &error);
  progress.finish();
  switch (status) {
    case slam::SdpRunStatus::kOk:
      io::write_log_errors(stderr, s.log_errors, s.log_error_count, kLogErrorsShown);
      std::printf("sdpslam run: %llu scans (%llu processed, %llu segments) in %.1f s, %zu log errors; ICP error "
                  "%.3f +- %.3f m over %llu samples; outputs in %s\n",
                  static_cast<unsigned long long>(s.scans), static_cast<unsigned long long>(s.processed),
                  static_cast<unsigned long long>(s.segments), s.wall_time_s, s.log_error_count, s.icp_error_mean_m,
                  s.icp_error_std_m, static_cast<unsigned long long>(s.icp_error_samples), a.out.c_str());
      if (s.resumed_at_scan > 0U) {
        std::printf("sdpslam run: resumed from %s after scan %llu\n", a.resume.c_str(),
                    static_cast<unsigned long long>(s.resumed_at_scan));
      }
      if (s.extended_after_scan > 0U) {
        std::printf("sdpslam run: extended the session of %s (%llu scans) with this log; %s\n", a.extend.c_str(),
                    static_cast<unsigned long long>(s.extended_after_scan), s.extend_place.c_str());
      }
      if (s.snapshots_written > 0U) {
        std::printf("sdpslam run: %llu snapshots written to %s (%.1f MiB, at most %.0f ms each)\n",
                    static_cast<unsigned long long>(s.snapshots_written), a.snapshot.c_str(),
                    static_cast<double>(s.snapshot_bytes) / (1024.0 * 1024.0), s.snapshot_write_ms_max);
      }
      report_odometry_repairs(s.odometry_reversals_repaired);
      report_implausible(s.odometry_jumps_removed, s.scans_stamped_backwards, s.first_backwards_at);
      return kExitOk;
    case slam::SdpRunStatus::kBadInput: return report("", kExitBadInput, error);
    case slam::SdpRunStatus::kIoError: return report("", kExitIo, error);
    default: return report("internal error: ", kExitInternal, error);
  }
}

int run_dpslam_mode(const RunArgs& a, slam::SlamConfig config) {
  slam::RunOptions ro;
  ro.config = config;
  if (a.particles != 0U) ro.config.filter.particle_count = a.particles;
  char why[200];
  if (!ro.config.filter.validate(why, sizeof why)) return report("", kExitUsage, slam::locate_option_error(a.config, why));
  if (a.print_config) {
    std::printf("; sdpslam run --mode dpslam: the effective configuration\n%s\n%s",
                slam::options_ini_text(DpSlamOptions::table(), ro.config.filter).c_str(),
                slam::options_ini_text(slam::log_option_table(), ro.config.log).c_str());
    return kExitOk;
  }
  if (const int rc = check_memory_budget(a, slam::dpslam_state_bytes(ro)); rc != kExitOk) {
    return rc;
  }
  ro.seed = a.seed;
  ro.painter = figure_painter();
  Progress progress("KiB", file_size_kib(a.log), a.quiet);
  ro.progress = [&progress](std::uint64_t bytes) { progress.update(bytes / 1024U); };
  slam::RunSummary summary;
  std::string error;
  const slam::RunStatus st = slam::run_offline(a.log, ro, a.out, &summary, &error);
  progress.finish();
  switch (st) {
    case slam::RunStatus::kOk:
      io::write_log_errors(stderr, summary.log_errors, summary.log_error_count, kLogErrorsShown);
      std::printf("sdpslam run: %llu scans (%llu processed) in %.1f s, %zu log errors; outputs in %s\n",
                  static_cast<unsigned long long>(summary.scans), static_cast<unsigned long long>(summary.processed),
                  summary.wall_time_s, summary.log_error_count, a.out.c_str());
      report_odometry_repairs(summary.odometry_reversals_repaired);
      report_implausible(summary.odometry_jumps_removed, summary.scans_stamped_backwards, summary.first_backwards_at);
      return kExitOk;
    case slam::RunStatus::kBadInput: return report("", kExitBadInput, error);
    case slam::RunStatus::kIoError: return report("", kExitIo, error);
    default: return report("internal error: ", kExitInternal, error);
  }
}

std::function<int()> setup_run(CLI::App& app) {
  auto args = std::make_shared<RunArgs>();
  app.add_option("log", args->log, "Robot log (CARMEN .clf[.gz], tinySLAM .dat, DP-SLAM .log, ROS 1 .bag, ROS 2 bag folder or .db3)")->required();
  app.add_option("--mode", args->mode,
                 "Algorithm: sdp (Segmented DP-SLAM, default) or dpslam (the bottom-level DP-SLAM filter alone)")
      ->check(CLI::IsMember({"sdp", "dpslam"}))
      ->capture_default_str();
  app.add_option("--particles", args->particles,
                 "Bottom-level particles, over [filter] particles (default: sdp 10, dpslam 30)")
      ->check(whole_number(UINT32_MAX));
  app.add_option("--top-particles", args->top_particles, "sdp: top-level particles (default 60, [sdp] top_particles)")
      ->check(whole_number(UINT32_MAX));
  app.add_option("--topology", args->topology, "sdp: topology estimation, sdp (default) or segslam (local analysis)")
      ->check(CLI::IsMember({"sdp", "segslam"}));
  app.add_option("--profile", args->profile,
                 "sdp: options to start from before --config: accurate (default: scan-matching proposals, loop "
                 "closure and wide loop search) or paper (the paper's algorithm); core/sdp_profile.h")
      ->check(CLI::IsMember({"accurate", "paper"}));
  app.add_option("--config", args->config,
                 "INI options on top of the profile: bottom level and [sdp] (see firmware-host/runtime/slam/default.ini)");
  app.add_option("--seed", args->seed, "Random seed (same seed, same output)")->check(whole_number(UINT64_MAX));
  app.add_option("--out", args->out, "Output directory")->required()->check(non_empty());
  app.add_option("--memory-budget-mib", args->memory_budget_mib,
                 "The SLAM state (sized before any work) may not exceed this, as sdpslamd's [daemon] "
                 "memory_budget_mib (default 128)")
      ->check(whole_number(65536U))
      ->check(CLI::Range(8U, 65536U));
  app.add_option("--snapshot", args->snapshot,
                 "sdp: write the run's whole state to this file (replaced atomically) after the last scan, and every "
                 "--snapshot-every-s of log time, so that --resume can continue it");
  app.add_option("--snapshot-every-s", args->snapshot_every_s,
                 "with --snapshot: also write it every this many seconds of log time (0 = only at the end)")
      ->check(CLI::Range(0.0, 1.0e9));
  app.add_option("--resume", args->resume,
                 "sdp: continue the run a --snapshot file holds, on the same log with the same options (the scans "
                 "it holds are not processed again; the outputs are those of an uninterrupted run)");
  app.add_option("--extend", args->extend,
                 "sdp: continue the session a --snapshot file holds with this log, another recording of the same "
                 "building (same options); the robot starts where the session left it, or where its first scan is "
                 "found in the saved map within --extend-window-m; the outputs hold both runs");
  app.add_option("--extend-window-m", args->extend_window_m,
                 "with --extend: +- metres around where the session left the robot in which its first scan is looked "
                 "for, at every heading (0 = take it to stand where it was left)")
      ->check(CLI::Range(0.0, 50.0));
  add_bag_options(app, &args->bag);
  app.add_flag("--print-config", args->print_config,
               "print the effective configuration (profile, file and flags applied, as INI) and exit");
  app.add_flag("--quiet", args->quiet, "no progress display (errors, warnings and the summary still print)");
  return [args]() -> int {
    const bool sdp = args->mode != "dpslam";
    if (!sdp && (!args->snapshot.empty() || !args->resume.empty() || !args->extend.empty())) {
      return report("", kExitUsage, "--snapshot, --resume and --extend apply to --mode sdp");
    }
    if (!args->resume.empty() && !args->extend.empty()) {
      return report("", kExitUsage, "--resume continues the snapshot's own log, --extend another: give one");
    }
    if (args->snapshot.empty() && args->snapshot_every_s > 0.0) {
      return report("", kExitUsage, "--snapshot-every-s needs --snapshot");
    }
    // Options of the top level mean nothing to DP-SLAM alone: refused, not ignored.
    if (!sdp && !args->profile.empty()) {
      return report("", kExitUsage, "--profile applies to --mode sdp (dpslam starts from firmware-host/runtime/slam/default.ini)");
    }
    if (!sdp && (args->top_particles != 0U || !args->topology.empty())) {
      return report("", kExitUsage, "--top-particles and --topology apply to --mode sdp");
    }
    SdpProfile profile = kDefaultSdpProfile;
    if (!args->profile.empty()) (void)parse_sdp_profile(args->profile.c_str(), &profile);  // checked by CLI11
    slam::SlamConfig config;
    SdpOptions sdp_options;
    if (sdp) apply_profile(profile, &config.filter, &sdp_options);
    std::string error;
    if (!args->config.empty() && !slam::load_config_ini(args->config, &config, &error)) {
      return report("", kExitBadInput, error);
    }
    args->bag.apply(&config.log);
    if (!sdp && !args->config.empty() && ini_has_section(args->config, "sdp")) {
      std::fprintf(stderr, "sdpslam run: warning: %s: [sdp] keys have no effect in --mode dpslam\n",
                   args->config.c_str());
    }
    return sdp ? run_sdp_mode(*args, config, sdp_options, profile) : run_dpslam_mode(*args, config);
  };
}

}  // namespace

SDPSLAM_REGISTER_COMMAND(run, "run", "Run SLAM over a log (SDP-SLAM by default): trajectory, map and stats", 40,
                         setup_run);

}  // namespace sdpslam::cli
