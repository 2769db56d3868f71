#pragma once
// Offline localization on a saved map (`sdpslam localize LOG --map map.yaml --out D`):
// reads a robot log, feeds every laser scan with its odometry to the Monte Carlo
// localizer (core/localization/monte_carlo_localizer.h) on the map — this project's own
// map.yaml/.pgm or one map_server / nav2_map_server wrote — and writes into out_dir, as
// one output set (io::OutputSet):
//  - trajectory.txt / trajectory.tum: one pose per scan in the map's frame (the filter's
//    estimate at updates, moved with the odometry in between), as `sdpslam run` writes;
//  - map.png: the map with that path drawn on it, and the final particles (orange);
//  - particles.tsv: the final particle set ("x y theta", one per line);
//  - stats.json: scans, filter updates, when the estimate first converged (particle
//    spread below 0.2 m), particle counts, the arena's size, CPU per scan.
// Without a start pose the robot is localized globally (particles over every free cell).
// Same log, map, options and seed -> bit-identical trajectory.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "sdpslam/core/localization/monte_carlo_localizer.h"
#include "sdpslam/io/figures.h"
#include "sdpslam/io/map_image.h"
#include "sdpslam/io/log_reader.h"

namespace sdpslam::slam {

struct LocalizeRunOptions {
  LocalizerOptions localizer;
  io::LogReaderOptions log;
  std::uint64_t seed = 1U;
  bool have_start = false;           // false: global localization
  Pose2 start;                       // map frame
  double start_sigma_xy_m = 0.25;    // spread of the first particles around `start`
  double start_sigma_theta_rad = 0.15;
  std::uint64_t skip_scans = 0U;     // scans of the log left out before the first
  std::function<void(std::uint64_t input_bytes)> progress;
  // Draws map.png: the path and the final particles on the map (figures.h).
  io::Painter painter = io::plain_painter();
};

struct LocalizeSummary {
  std::uint64_t scans = 0U;
  std::uint64_t updates = 0U;
  std::int64_t converged_at_scan = -1;  // first scan whose spread was below 0.2 m; -1 never
  double final_spread_m = 0.0;
  std::uint32_t final_particles = 0U;
  std::size_t state_bytes = 0U;
  double cpu_ms_per_scan_mean = 0.0;
  double cpu_ms_per_update_p99 = 0.0;
  double log_seconds = 0.0;  // the log's time span of the scans used
  double cpu_seconds = 0.0;  // spent in the localizer
};

enum class LocalizeStatus { kOk, kBadInput, kIoError, kInternal };

// A saved map as the localizer takes it (`sdpslam localize`, sdpslamd [slam] mode =
// localize): the image read by io::read_map_yaml and its cells classed by the YAML's
// thresholds as map_server does. `map.cells` points into `cells`: keep the object alive
// (and unmoved) while the map is in use.
struct LocalizationMap {
  io::OccupancyImage image;
  std::vector<std::uint8_t> cells;
  LocalizerMap map;
};
// False, with "file[:line]: why", when the map cannot be read.
bool load_localization_map(const std::string& map_yaml, LocalizationMap* out, std::string* error);
// The same for a map already in out->image (e.g. a session's rendered global map), its
// cells classed by these thresholds (map.yaml's).
void localization_map_from_image(const io::MapWriteOptions& thresholds, LocalizationMap* out);

// "x,y,theta" (m, m, rad; spaces allowed around the commas) to a pose; false on anything
// else, a non-finite number included.
bool parse_start_pose(const std::string& text, Pose2* pose);

// The spread below which a run counts as converged (issue benchmark, stats.json).
inline constexpr double kConvergedSpreadM = 0.2;

LocalizeStatus run_localize(const std::string& log_path, const std::string& map_yaml, const LocalizeRunOptions& options,
                            const std::string& out_dir, LocalizeSummary* summary, std::string* error);

}  // namespace sdpslam::slam
