#include "sdpslam/slam/run_offline.h"

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cinttypes>
#include <cstdio>
#include <memory>
#include <utility>
#include <vector>

#include "sdpslam/core/bottom/dpslam_filter.h"
#include "sdpslam/io/atomic_file.h"
#include "sdpslam/io/map_image.h"
#include "sdpslam/io/output_set.h"
#include "sdpslam/io/trajectory_io.h"
#include "sdpslam/io/json_text.h"
#include "sdpslam/slam/dpslam_session.h"
#include "sdpslam/slam/slam_outputs.h"
#include "run_common.h"

namespace sdpslam::slam {
namespace {

using detail::percentile;
using detail::rusage_cpu_s;
using detail::thread_cpu_ms;

}  // namespace

std::size_t dpslam_state_bytes(const RunOptions& options) {
  return DpSlamFilter::required_arena_bytes(options.config.filter);
}

RunStatus run_offline(const std::string& log_path, const RunOptions& options, const std::string& out_dir,
                      RunSummary* summary, std::string* error) {
  const auto t_start = std::chrono::steady_clock::now();
  const DpSlamOptions& fo = options.config.filter;
  char why[200];
  if (!fo.validate(why, sizeof why)) {
    *error = std::string("invalid options: ") + why;
    return RunStatus::kBadInput;
  }
  io::LogReader reader;
  if (!reader.open(log_path, options.config.log, error)) return RunStatus::kBadInput;
  // The output folder is made, cleaned of an interrupted run's leftovers and proven
  // writable before any work; every file is staged and delivered as one set at the end.
  io::OutputSet outputs;
  if (!outputs.begin(out_dir, error)) return RunStatus::kIoError;

  DpSlamSession session;
  if (!session.create(fo, options.seed, error)) return RunStatus::kInternal;
  const DpSlamFilter* filter = &session.filter();
  const std::size_t arena_bytes = session.arena_bytes();
  const std::vector<ScanRecord>& scans = session.records();
  std::vector<double> scan_ms;
  std::vector<double> processed_ms;
  std::vector<double> scan_cpu_ms;  // this thread's CPU time: robust on a loaded machine
  detail::ScanOdometryPairing pairing;
  OdometrySample od;
  while (pairing.next(reader, &od)) {
    const io::LaserRecord& rec = reader.laser();
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = thread_cpu_ms();
    const StepResult r = session.feed(od, rec.scan);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    scan_cpu_ms.push_back(thread_cpu_ms() - c0);
    const bool processed = r.status == StepResult::Status::kProcessed;
    scan_ms.push_back(ms);
    if (processed) processed_ms.push_back(ms);
    if (options.progress) options.progress(reader.input_offset());
  }
  if (scans.empty()) {
    *error = log_path + ": no laser scan with odometry in the log";
    return RunStatus::kBadInput;
  }

  // The final best particle's path: committed poses, then its own uncommitted ones.
  std::uint64_t path_gaps = 0U;
  const std::vector<io::StampedPose> trajectory = session.trajectory(&path_gaps);

  // The best particle's map.
  const DpMap& map = filter->map();
  io::OccupancyImage image;
  const std::uint32_t known_cells = session.map_image(&image);
  if (!write_trajectory_and_map(outputs.staging_dir(), trajectory, image, error, &options.painter)) {
    return RunStatus::kIoError;
  }

  // stats.json: deterministic fields first, timing apart.
  const AncestryTree& tree = filter->tree();
  const DpSlamStats& st = filter->stats();
  constexpr std::size_t kObservationBytes = DpMap::kObservationBytes;
  constexpr std::size_t kTileBytes = (capacity::kDpTileCells + 2U) * sizeof(std::uint32_t);
  constexpr std::size_t kPathEntryBytes = 40U;    // stamp + Pose2 + link, padded
  const std::size_t node_bytes = tree.capacity() > 0U ? (tree.footprint_bytes() - tree.path_entry_capacity() * kPathEntryBytes) / tree.capacity() : 0U;
  const std::size_t state_bytes = static_cast<std::size_t>(tree.peak_used()) * node_bytes +
                                  static_cast<std::size_t>(tree.path_entries_peak()) * kPathEntryBytes +
                                  static_cast<std::size_t>(map.observations_peak()) * kObservationBytes +
                                  static_cast<std::size_t>(map.tiles_peak()) * kTileBytes;
  const std::size_t naive_bytes = static_cast<std::size_t>(fo.particle_count) * known_cells * sizeof(CellObservation);
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  auto ms = [](double v) { return io::json_fixed(v, 3); };
  io::Json js;
  js["log"] = log_path;
  js["mode"] = "dpslam";
  js["particles"] = fo.particle_count;
  js["seed"] = options.seed;
  js["scans"] = scans.size();
  js["processed_scans"] = st.processed;
  js["scans_without_odometry"] = pairing.scans_without_odom();
  js["log_errors"] = reader.error_count();
  js["odometry_reversals_repaired"] = reader.odometry_reversals_repaired();
  js["odometry_jumps_removed"] = reader.odometry_jumps_removed();
  js["scans_stamped_backwards"] = reader.scans_stamped_backwards();
  js["resamplings"] = st.resamplings;
  js["proposal"] = proposal_json(st);
  io::Json pools = filter_pools_json(*filter);
  pools["map_updates_dropped"] = st.map_updates_dropped;
  pools["out_of_map_updates"] = map.out_of_bounds_count();
  pools["trajectory_gaps_filled_from_odometry"] = path_gaps;
  js["pools"] = std::move(pools);
  js["memory"] = {{"arena_bytes", arena_bytes},
                  {"state_bytes_peak", state_bytes},
                  {"best_map_known_cells", known_cells},
                  {"naive_copy_bytes", naive_bytes}};
  js["timing"] = {{"wall_time_s", ms(wall_s)},
                  {"scan_ms_p50", ms(percentile(scan_ms, 0.5))},
                  {"scan_ms_p99", ms(percentile(scan_ms, 0.99))},
                  {"scan_ms_max", ms(percentile(scan_ms, 1.0))},
                  {"processed_ms_p50", ms(percentile(processed_ms, 0.5))},
                  {"processed_ms_p99", ms(percentile(processed_ms, 0.99))},
                  {"processed_ms_max", ms(percentile(processed_ms, 1.0))},
                  {"scan_cpu_ms_p50", ms(percentile(scan_cpu_ms, 0.5))},
                  {"scan_cpu_ms_p99", ms(percentile(scan_cpu_ms, 0.99))},
                  {"scan_cpu_ms_max", ms(percentile(scan_cpu_ms, 1.0))},
                  {"cpu_time_s", ms(rusage_cpu_s(ru))},
                  {"peak_rss_kib", static_cast<std::uint64_t>(ru.ru_maxrss)}};
  if (!io::write_file_atomic(outputs.path("stats.json"), io::json_text(js), error)) return RunStatus::kIoError;
  if (!outputs.commit(error)) return RunStatus::kIoError;

  if (summary != nullptr) *summary = run_summary(reader, log_path, scans.size(), st.processed, wall_s);
  return RunStatus::kOk;
}

}  // namespace sdpslam::slam
