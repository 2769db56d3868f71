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
#include "sdpslam/io/json_text.h"
#include "sdpslam/io/map_image.h"
#include "sdpslam/io/map_read.h"
#include "sdpslam/io/output_set.h"
#include "sdpslam/slam/localize_session.h"
#include "sdpslam/slam/slam_outputs.h"

namespace sdpslam::slam {
namespace {

using detail::percentile;
using detail::thread_cpu_ms;

// The map's classes as map_server reads them (io::read_map_yaml: occupancy above
// occupied_thresh, below free_thresh, else unknown: -1, or between the thresholds in
// mode scale).
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
  if (!io::read_map_yaml(map_yaml, &out->image, &thresholds, error)) return false;
  localization_map_from_image(thresholds, out);
  return true;
}

void localization_map_from_image(const io::MapWriteOptions& thresholds, LocalizationMap* out) {
  out->cells = map_cells(out->image, thresholds);
  out->map = LocalizerMap{};
  out->map.width = out->image.width;
  out->map.height = out->image.height;
  out->map.resolution_m = out->image.resolution_m;
  out->map.origin_x_m = out->image.origin_x_m;
  out->map.origin_y_m = out->image.origin_y_m;
  out->map.cells = out->cells.data();
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
  // The whole state: one arena sized for this map before any scan.
  LocalizeSession session;
  if (!session.create(options.localizer, map_yaml, options.seed, options.have_start ? &options.start : nullptr,
                      options.start_sigma_xy_m, options.start_sigma_theta_rad, error)) {
    return LocalizeStatus::kBadInput;
  }
  const io::OccupancyImage& image = session.map().image;
  const LocalizerMap& map = session.map().map;
  const MonteCarloLocalizer* mcl = &session.localizer();

  io::LogReader reader;
  if (!reader.open(log_path, options.log, error)) return LocalizeStatus::kBadInput;
  io::OutputSet outputs;
  if (!outputs.begin(out_dir, error)) return LocalizeStatus::kIoError;

  const std::size_t arena_bytes = session.arena_bytes();

  detail::ScanOdometryPairing pairing;
  OdometrySample od;
  const std::vector<io::StampedPose>& trajectory = session.trajectory();
  std::vector<double> update_ms;
  std::uint64_t skipped = 0U;
  double cpu_ms = 0.0;
  while (pairing.next(reader, &od)) {
    if (options.progress) options.progress(reader.input_offset());
    if (skipped < options.skip_scans) {
      ++skipped;
      continue;
    }
    const double t0 = thread_cpu_ms();
    const MonteCarloLocalizer::Step step = session.feed(od, reader.laser().scan);
    const double dt = thread_cpu_ms() - t0;
    cpu_ms += dt;
    if (step.updated) update_ms.push_back(dt);
  }
  if (trajectory.empty()) {
    *error = log_path + ": no laser scan with odometry" + (options.skip_scans > 0U ? " after the skipped ones" : "");
    return LocalizeStatus::kBadInput;
  }

  if (!write_trajectories(outputs.staging_dir(), trajectory, error)) return LocalizeStatus::kIoError;
  const std::vector<Pose2> final_set(mcl->particles(), mcl->particles() + mcl->particle_count());
  io::MapFigure figure;
  figure.title = options.have_start ? "Localization on the map (from the given start)" : "Localization on the map (global start)";
  figure.map = &image;
  figure.path = &trajectory;
  figure.points = &final_set;
  figure.points_label = "final particles";
  if (!options.painter.map(outputs.path("map.png"), figure, error)) return LocalizeStatus::kIoError;
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
  auto fixed = [](double v, int decimals) { return io::json_fixed(v, decimals); };
  io::Json js;
  js["mode"] = "localize";
  js["start"] = options.have_start ? "given" : "global";
  js["seed"] = options.seed;
  js["skipped_scans"] = skipped;
  js["scans"] = trajectory.size();
  js["filter_updates"] = st.filter_updates;
  js["converged_at_scan"] = session.converged_at();
  js["converged_spread_m"] = fixed(kConvergedSpreadM, 3);
  js["final_spread_m"] = fixed(mcl->spread_m(), 6);
  js["final_particles"] = mcl->particle_count();
  js["random_particles"] = st.random_particles;
  js["kld_capped"] = st.kld_capped;
  js["degenerate_weights"] = st.degenerate_weights;
  js["beams_weighed"] = st.beams_weighed;
  js["map"] = {{"width", map.width},
               {"height", map.height},
               {"resolution_m", fixed(map.resolution_m, 6)},
               {"free_cells", st.free_cells},
               {"occupied_cells", st.occupied_cells}};
  js["memory"] = {{"arena_bytes", arena_bytes},
                  {"arena_used_bytes", session.arena_used_bytes()},
                  {"min_particles", options.localizer.min_particles},
                  {"max_particles", options.localizer.max_particles}};
  js["timing"] = {{"cpu_ms_per_scan_mean", fixed(cpu_ms / static_cast<double>(trajectory.size()), 4)},
                  {"cpu_ms_per_update_p50", fixed(percentile(update_ms, 0.5), 4)},
                  {"cpu_ms_per_update_p99", fixed(percentile(update_ms, 0.99), 4)},
                  {"cpu_ms_per_update_max", fixed(percentile(update_ms, 1.0), 4)},
                  {"log_s", fixed(log_s, 3)},
                  {"localizer_cpu_s", fixed(cpu_ms * 1e-3, 3)},
                  {"peak_rss_kib", static_cast<std::uint64_t>(ru.ru_maxrss)}};
  if (!io::write_file_atomic(outputs.path("stats.json"), io::json_text(js), error)) return LocalizeStatus::kIoError;
  if (!outputs.commit(error)) return LocalizeStatus::kIoError;

  if (summary != nullptr) {
    summary->scans = trajectory.size();
    summary->updates = st.filter_updates;
    summary->converged_at_scan = session.converged_at();
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
