#include "sdpslam/slam/run_localize.h"

#include <sys/resource.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "run_common.h"
#include "sdpslam/io/atomic_file.h"
#include "sdpslam/io/map_image.h"
#include "sdpslam/io/output_set.h"
#include "sdpslam/slam/slam_outputs.h"

namespace sdpslam::slam {
namespace {

using detail::fmt;
using detail::percentile;
using detail::thread_cpu_ms;

// The map's classes as map_server reads them (io::read_map_pgm_yaml: occupancy above
// occupied_thresh, below free_thresh, else unknown = -1).
std::vector<std::uint8_t> map_cells(const io::OccupancyImage& img, const io::MapWriteOptions& t) {
  std::vector<std::uint8_t> cells(img.occupancy.size(), LocalizerMap::kUnknown);
  for (std::size_t i = 0; i < cells.size(); ++i) {
    const double p = static_cast<double>(img.occupancy[i]);
    if (p < 0.0) continue;
    if (p > t.occupied_thresh) cells[i] = LocalizerMap::kOccupied;
    else if (p < t.free_thresh) cells[i] = LocalizerMap::kFree;
  }
  return cells;
}

}  // namespace

bool load_localization_map(const std::string& map_yaml, LocalizationMap* out, std::string* error) {
  io::MapWriteOptions thresholds;
  if (!io::read_map_pgm_yaml(map_yaml, &out->image, &thresholds, error)) return false;
  out->cells = map_cells(out->image, thresholds);
  out->map = LocalizerMap{};
  out->map.width = out->image.width;
  out->map.height = out->image.height;
  out->map.resolution_m = out->image.resolution_m;
  out->map.origin_x_m = out->image.origin_x_m;
  out->map.origin_y_m = out->image.origin_y_m;
  out->map.cells = out->cells.data();
  return true;
}

bool parse_start_pose(const std::string& text, Pose2* pose) {
  double v[3];
  const char* p = text.c_str();
  for (int k = 0; k < 3; ++k) {
    char* end = nullptr;
    v[k] = std::strtod(p, &end);
    if (end == p || !std::isfinite(v[k])) return false;
    p = end;
    while (*p == ' ' || *p == '\t') ++p;
    if (k < 2) {
      if (*p != ',') return false;
      ++p;
    }
  }
  if (*p != '\0') return false;
  *pose = Pose2{v[0], v[1], v[2]};
  return true;
}

LocalizeStatus run_localize(const std::string& log_path, const std::string& map_yaml, const LocalizeRunOptions& options,
                            const std::string& out_dir, LocalizeSummary* summary, std::string* error) {
  char why[160];
  if (!options.localizer.check(why, sizeof why)) {
    *error = std::string("invalid options: localize.") + why;
    return LocalizeStatus::kBadInput;
  }
  auto loaded = std::make_unique<LocalizationMap>();
  if (!load_localization_map(map_yaml, loaded.get(), error)) return LocalizeStatus::kBadInput;
  const io::OccupancyImage& image = loaded->image;
  const LocalizerMap& map = loaded->map;

  io::LogReader reader;
  if (!reader.open(log_path, options.log, error)) return LocalizeStatus::kBadInput;
  io::OutputSet outputs;
  if (!outputs.begin(out_dir, error)) return LocalizeStatus::kIoError;

  // The whole state: one arena sized for this map before any scan.
  const std::size_t arena_bytes = MonteCarloLocalizer::required_arena_bytes(options.localizer, map);
  if (arena_bytes == 0U) {
    *error = map_yaml + ": a map the localizer cannot hold (at least 2 x 2 cells, at most 65535 a side)";
    return LocalizeStatus::kBadInput;
  }
  std::unique_ptr<unsigned char[]> buffer(new unsigned char[arena_bytes]);
  Arena arena(buffer.get(), arena_bytes);
  auto mcl = std::make_unique<MonteCarloLocalizer>();
  if (!mcl->init(options.localizer, map, arena, options.seed, why, sizeof why)) {
    *error = map_yaml + ": " + why;
    return LocalizeStatus::kBadInput;
  }
  if (options.have_start) {
    mcl->start_at(options.start, options.start_sigma_xy_m, options.start_sigma_theta_rad);
  } else {
    mcl->start_global();
  }

  detail::ScanOdometryPairing pairing;
  OdometrySample od;
  std::vector<io::StampedPose> trajectory;
  std::vector<double> update_ms;
  std::uint64_t skipped = 0U;
  std::int64_t converged_at = -1;
  double cpu_ms = 0.0;
  while (pairing.next(reader, &od)) {
    if (options.progress) options.progress(reader.input_offset());
    if (skipped < options.skip_scans) {
      ++skipped;
      continue;
    }
    const double t0 = thread_cpu_ms();
    const MonteCarloLocalizer::Step step = mcl->update(od, reader.laser().scan);
    const double dt = thread_cpu_ms() - t0;
    cpu_ms += dt;
    if (step.updated) update_ms.push_back(dt);
    if (converged_at < 0 && step.updated && step.spread_m < kConvergedSpreadM) {
      converged_at = static_cast<std::int64_t>(trajectory.size());
    }
    trajectory.push_back(io::StampedPose{od.stamp_us, step.pose});
  }
  if (trajectory.empty()) {
    *error = log_path + ": no laser scan with odometry" + (options.skip_scans > 0U ? " after the skipped ones" : "");
    return LocalizeStatus::kBadInput;
  }

  if (!write_trajectories(outputs.staging_dir(), trajectory, error)) return LocalizeStatus::kIoError;
  const std::vector<Pose2> final_set(mcl->particles(), mcl->particles() + mcl->particle_count());
  if (!io::write_map_png(outputs.path("map.png"), image, trajectory, final_set, error)) return LocalizeStatus::kIoError;
  std::string particles = "# x_m y_m theta_rad: the final particle set\n";
  for (std::uint32_t i = 0; i < mcl->particle_count(); ++i) {
    const Pose2& p = mcl->particles()[i];
    char line[96];
    std::snprintf(line, sizeof line, "%.6f %.6f %.6f\n", p.x_m, p.y_m, p.heading_rad);
    particles += line;
  }
  if (!io::write_file_atomic(outputs.path("particles.tsv"), particles, error)) return LocalizeStatus::kIoError;

  const LocalizerStats& st = mcl->stats();
  const double log_s = static_cast<double>(trajectory.back().stamp_us - trajectory.front().stamp_us) * 1e-6;
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  auto u = [](std::uint64_t v) { return std::to_string(v); };
  std::string js = "{\n";
  js += "  \"mode\": \"localize\",\n  \"start\": \"" + std::string(options.have_start ? "given" : "global") + "\",\n";
  js += "  \"seed\": " + u(options.seed) + ",\n  \"skipped_scans\": " + u(skipped) + ",\n";
  js += "  \"scans\": " + u(trajectory.size()) + ",\n  \"filter_updates\": " + u(st.filter_updates) + ",\n";
  js += "  \"converged_at_scan\": " + std::to_string(converged_at) + ",\n";
  js += "  \"converged_spread_m\": " + fmt("%.3f", kConvergedSpreadM) + ",\n";
  js += "  \"final_spread_m\": " + fmt("%.6f", mcl->spread_m()) + ",\n";
  js += "  \"final_particles\": " + u(mcl->particle_count()) + ",\n";
  js += "  \"random_particles\": " + u(st.random_particles) + ",\n  \"kld_capped\": " + u(st.kld_capped) +
        ",\n  \"degenerate_weights\": " + u(st.degenerate_weights) + ",\n  \"beams_weighed\": " +
        u(st.beams_weighed) + ",\n";
  js += "  \"map\": {\"width\": " + u(map.width) + ", \"height\": " + u(map.height) +
        ", \"resolution_m\": " + fmt("%.6f", map.resolution_m) + ", \"free_cells\": " + u(st.free_cells) +
        ", \"occupied_cells\": " + u(st.occupied_cells) + "},\n";
  js += "  \"memory\": {\"arena_bytes\": " + u(arena_bytes) + ", \"arena_used_bytes\": " + u(arena.used_bytes()) +
        ", \"min_particles\": " + u(options.localizer.min_particles) + ", \"max_particles\": " +
        u(options.localizer.max_particles) + "},\n";
  js += "  \"timing\": {\"cpu_ms_per_scan_mean\": " + fmt("%.4f", cpu_ms / static_cast<double>(trajectory.size())) +
        ", \"cpu_ms_per_update_p50\": " + fmt("%.4f", percentile(update_ms, 0.5)) +
        ", \"cpu_ms_per_update_p99\": " + fmt("%.4f", percentile(update_ms, 0.99)) +
        ", \"cpu_ms_per_update_max\": " + fmt("%.4f", percentile(update_ms, 1.0)) + ", \"log_s\": " +
        fmt("%.3f", log_s) + ", \"localizer_cpu_s\": " + fmt("%.3f", cpu_ms * 1e-3) +
        ", \"peak_rss_kib\": " + u(static_cast<std::uint64_t>(ru.ru_maxrss)) + "}\n}\n";
  if (!io::write_file_atomic(outputs.path("stats.json"), js, error)) return LocalizeStatus::kIoError;
  if (!outputs.commit(error)) return LocalizeStatus::kIoError;

  if (summary != nullptr) {
    summary->scans = trajectory.size();
    summary->updates = st.filter_updates;
    summary->converged_at_scan = converged_at;
    summary->final_spread_m = mcl->spread_m();
    summary->final_particles = mcl->particle_count();
    summary->state_bytes = arena_bytes;
    summary->cpu_ms_per_scan_mean = cpu_ms / static_cast<double>(trajectory.size());
    summary->cpu_ms_per_update_p99 = percentile(update_ms, 0.99);
    summary->log_seconds = log_s;
    summary->cpu_seconds = cpu_ms * 1e-3;
  }
  return LocalizeStatus::kOk;
}

}  // namespace sdpslam::slam
