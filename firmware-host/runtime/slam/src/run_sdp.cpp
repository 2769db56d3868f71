#include "sdpslam/slam/run_sdp.h"

#include <sys/resource.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <vector>

#include "sdpslam/core/sdp_slam.h"
#include "sdpslam/io/atomic_file.h"
#include "sdpslam/io/log_reader.h"
#include "sdpslam/io/map_image.h"
#include "sdpslam/io/output_set.h"
#include "sdpslam/io/snapshot_file.h"
#include "sdpslam/io/trajectory_io.h"
#include "sdpslam/io/json_text.h"
#include "sdpslam/slam/ini_document.h"
#include "sdpslam/slam/sdp_session.h"
#include "sdpslam/slam/session_continuation.h"
#include "sdpslam/slam/slam_outputs.h"
#include "run_common.h"

namespace sdpslam::slam {
namespace {

// ---- outputs ------------------------------------------------------------------------

using detail::percentile;
using detail::rusage_cpu_s;
using detail::thread_cpu_ms;

// The per-round ICP error over time: its mean, with a band of ± one standard deviation.
io::Chart error_chart(const std::vector<IcpRound>& rows, std::int64_t t0_us) {
  io::Chart chart;
  chart.title = "Top-level ICP error of the chosen segments";
  chart.x_label = "time since the first scan (s)";
  chart.y_label = "mean nearest-neighbour distance (m)";
  io::ChartSeries band =
      io::ChartSeries::named("mean ± 1 standard deviation", io::Rgb8{70, 110, 200}, io::ChartSeries::Style::kBand);
  io::ChartSeries mean = io::ChartSeries::named("mean", io::Rgb8{20, 50, 150});
  for (const IcpRound& r : rows) {
    const double t_s = static_cast<double>(r.stamp_us - t0_us) * 1e-6;
    band.x.push_back(t_s);
    band.y.push_back(std::max(0.0, r.mean_m - r.std_m));
    band.y_high.push_back(r.mean_m + r.std_m);
    mean.x.push_back(t_s);
    mean.y.push_back(r.mean_m);
  }
  chart.series.push_back(band);
  chart.series.push_back(mean);
  return chart;
}

}  // namespace

SdpKeyResult apply_sdp_key(SdpOptions* o, const std::string& key, const char* value, std::string* why) {
  const OptionSpec<SdpOptions>* row = SdpOptions::table().find("sdp", key.c_str());
  if (row == nullptr) return SdpKeyResult::kUnknown;
  std::string reason;
  if (set_option_text(*row, o, value, &reason)) return SdpKeyResult::kApplied;
  if (why != nullptr) *why = reason;
  return SdpKeyResult::kInvalid;
}

bool load_sdp_ini(const std::string& path, SdpOptions* options, std::string* error) {
  std::FILE* f = open_config_file(path, error);
  if (f == nullptr) return false;
  const bool ok = load_sdp_ini(f, path, options, error);
  std::fclose(f);
  return ok;
}

bool load_sdp_ini(std::FILE* stream, const std::string& name, SdpOptions* options, std::string* error) {
  IniDocument doc;
  return doc.read(stream, name, error) && apply_ini_table(doc, SdpOptions::table(), options, error);
}

std::size_t sdp_state_bytes(const SdpRunOptions& options) {
  return SdpSlam::required_arena_bytes(options.config.filter, options.sdp);
}

bool sdp_check_options(const SdpRunOptions& options, std::string* why) {
  char text[240];
  if (SdpSlam::check_options(options.config.filter, options.sdp, text, sizeof text)) return true;
  *why = text;
  return false;
}

namespace {

// The runner's part of a snapshot, before the engine's: what it has gathered from the
// scans so far.
constexpr char kRunnerPart[] = "sdpslam run sdp 1";

bool write_snapshot(const SdpRunOptions& options, SdpSession& session, std::uint64_t* file_bytes,
                    std::string* error) {
  io::SnapshotOut out;
  if (!out.open(options.snapshot_path, options.config_fingerprint, error)) return false;
  out.put_bytes(kRunnerPart, sizeof kRunnerPart);
  io::put_vector(out, session.records());
  io::put_vector(out, session.rounds());
  session.permanent().write_state(out);
  if (!session.slam().save_state(out)) {
    *error = options.snapshot_path + ": " + session.slam().why();
    return false;
  }
  if (!out.commit(error)) return false;
  *file_bytes = out.file_bytes();
  return true;
}

bool read_snapshot(const SdpRunOptions& options, const std::string& path, SdpSession& session, std::string* error) {
  io::SnapshotInfo info;
  if (!io::check_snapshot(path, options.config_fingerprint, &info, error)) return false;
  io::SnapshotIn in;
  if (!in.open(path, error)) return false;
  std::string part;
  if (!in.get_bytes(&part, 64U) || part != std::string(kRunnerPart, sizeof kRunnerPart)) {
    *error = path + ": not a snapshot of `sdpslam run` in sdp mode";
    return false;
  }
  if (!io::get_vector(in, &session.records()) || !io::get_vector(in, &session.rounds()) ||
      !session.permanent().read_state(in)) {
    *error = path + ": snapshot's runner part is damaged";
    return false;
  }
  if (!session.slam().load_state(in)) {
    *error = path + ": " + session.slam().why();
    return false;
  }
  if (!in.at_end()) {
    *error = path + ": snapshot holds more than this program reads";
    return false;
  }
  return true;
}

}  // namespace

SdpRunStatus run_sdp_offline(const std::string& log_path, const SdpRunOptions& options, const std::string& out_dir,
                             SdpRunSummary* summary, std::string* error) {
  const auto t_start = std::chrono::steady_clock::now();
  const DpSlamOptions& fo = options.config.filter;
  if (std::string why; !sdp_check_options(options, &why)) {
    *error = "invalid options: " + why;
    return SdpRunStatus::kBadInput;
  }
  io::LogReader reader;
  if (!reader.open(log_path, options.config.log, error)) return SdpRunStatus::kBadInput;
  // The output folder is made, cleaned of an interrupted run's leftovers and proven
  // writable before any work; every file is staged and delivered as one set at the end.
  io::OutputSet outputs;
  if (!outputs.begin(out_dir, error)) return SdpRunStatus::kIoError;

  // The whole state: one arena sized at init (the fixed memory budget).
  SdpSession session(options.extend_window_m);
  if (!session.create(fo, options.sdp, options.seed, true, error)) return SdpRunStatus::kInternal;
  SdpSlam& slam = session.slam();
  const std::vector<ScanRecord>& scans = session.records();

  if (!options.resume_path.empty() && !options.extend_path.empty()) {
    *error = "a run resumes its own log or extends a session with another, not both";
    return SdpRunStatus::kBadInput;
  }
  const std::string& saved_path = options.resume_path.empty() ? options.extend_path : options.resume_path;
  if (!saved_path.empty() && !read_snapshot(options, saved_path, session, error)) return SdpRunStatus::kBadInput;
  const std::size_t extended_after = options.extend_path.empty() ? 0U : scans.size();
  if (extended_after > 0U) session.continuation().begin(scans.back().odom, scans.back().stamp_us);
  const std::size_t resume_at = options.extend_path.empty() ? scans.size() : 0U;
  const SessionContinuation& continuation = session.continuation();
  std::uint64_t snapshots = 0U;
  std::uint64_t snapshot_bytes = 0U;
  double snapshot_ms_max = 0.0;
  // Log time of the last snapshot (or of the run's first scan).
  bool snapshot_clock_set = !scans.empty();
  std::int64_t last_snapshot_us = scans.empty() ? 0 : scans.back().stamp_us;
  auto snapshot = [&]() {
    const auto s0 = std::chrono::steady_clock::now();
    if (!write_snapshot(options, session, &snapshot_bytes, error)) return false;
    ++snapshots;
    snapshot_ms_max = std::max(
        snapshot_ms_max, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - s0).count());
    return true;
  };

  std::vector<double> scan_ms;
  std::vector<double> scan_cpu_ms;  // this thread's CPU time: robust on a loaded machine
  double cpu_max_by_kind[4] = {0.0, 0.0, 0.0, 0.0};
  // Split by whether the bottom filter processed the scan (top-level work alone or not),
  // and the scans over one 10 Hz scan period.
  double cpu_max_bottom_processed = 0.0;
  double cpu_max_bottom_idle = 0.0;
  std::uint64_t scans_cpu_over_100ms = 0U;
  std::vector<double> segment_ms;
  detail::ScanOdometryPairing pairing;
  OdometrySample od;
  std::size_t index = 0U;  // of the scan (with odometry) in the log
  while (pairing.next(reader, &od)) {
    const io::LaserRecord& rec = reader.laser();
    if (index < resume_at) {
      // Held by the snapshot: the log must be the one it was made from.
      if (rec.stamp_us != scans[index].stamp_us) {
        *error = options.resume_path + ": made from another log (scan " + std::to_string(index + 1U) + " of " +
                 log_path + " is stamped " + io::format_stamp_us(rec.stamp_us) + ", the snapshot's " +
                 io::format_stamp_us(scans[index].stamp_us) + ")";
        return SdpRunStatus::kBadInput;
      }
      ++index;
      if (options.progress) options.progress(reader.input_offset());
      continue;
    }
    ++index;
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = thread_cpu_ms();
    SdpStepResult r;
    if (!session.feed(od, rec.scan, &r)) {
      // Held back while an extension looks for the robot in the saved map.
      if (options.progress) options.progress(reader.input_offset());
      continue;
    }
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    scan_ms.push_back(ms);
    const double cpu = thread_cpu_ms() - c0;
    scan_cpu_ms.push_back(cpu);
    // Where the worst scans come from: segmentation, top-level evaluation, anchorage
    // work alone, or the bottom filter alone. Each is the scan's whole time, the bottom
    // filter's included when it processed the scan: a slow "evaluation" scan may be slow
    // for its bottom-level work (scan_cpu_ms_max_bottom_processed says how slow that got).
    const int kind = r.segmented != SegmentEnd::kNone ? 0 : (r.evaluations > 0U ? 1 : (r.work_cells > 0U ? 2 : 3));
    cpu_max_by_kind[kind] = std::max(cpu_max_by_kind[kind], cpu);
    double& split = r.bottom.status == StepResult::Status::kProcessed ? cpu_max_bottom_processed : cpu_max_bottom_idle;
    split = std::max(split, cpu);
    if (cpu > 100.0) ++scans_cpu_over_100ms;
    if (r.segmented != SegmentEnd::kNone) segment_ms.push_back(ms);
    if (options.progress) options.progress(reader.input_offset());
    const std::int64_t fed_stamp_us = scans.back().stamp_us;  // shifted by an extension
    if (!options.snapshot_path.empty() && options.snapshot_every_s > 0.0) {
      if (!snapshot_clock_set) {
        snapshot_clock_set = true;
        last_snapshot_us = fed_stamp_us;
      } else if (static_cast<double>(fed_stamp_us - last_snapshot_us) * 1e-6 >= options.snapshot_every_s) {
        if (!snapshot()) return SdpRunStatus::kIoError;
        last_snapshot_us = fed_stamp_us;
      }
    }
  }
  if (scans.empty()) {
    *error = log_path + ": no laser scan with odometry in the log";
    return SdpRunStatus::kBadInput;
  }
  if (index < resume_at) {
    *error = options.resume_path + ": holds " + std::to_string(resume_at) + " scans, " + log_path + " only " +
             std::to_string(index);
    return SdpRunStatus::kBadInput;
  }
  // The last one: the state before finish(), which only completes pending work.
  if (!options.snapshot_path.empty() && !snapshot()) return SdpRunStatus::kIoError;
  session.finish();

  // The best combination's path: permanent segments, then the live chain.
  std::uint64_t path_gaps = 0U;
  const std::vector<io::StampedPose> trajectory = session.trajectory(&path_gaps);

  io::OccupancyImage image;
  const std::uint32_t known_cells = session.map_image(&image);
  if (!write_trajectory_and_map(outputs.staging_dir(), trajectory, image, error, &options.painter)) {
    return SdpRunStatus::kIoError;
  }
  std::string csv = "stamp_s,mean_m,std_m,samples\n";
  for (const IcpRound& r : session.rounds()) {
    char line[128];
    std::snprintf(line, sizeof line, "%s,%.6f,%.6f,%u\n", io::format_stamp_us(r.stamp_us).c_str(), r.mean_m, r.std_m,
                  r.samples);
    csv += line;
  }
  if (!io::write_file_atomic(outputs.path("icp_error.csv"), csv, error)) return SdpRunStatus::kIoError;
  if (!io::write_file_atomic(outputs.path("loops.tsv"), sdp_loops_tsv(slam), error)) return SdpRunStatus::kIoError;
  if (!io::write_file_atomic(outputs.path("segments.tsv"), sdp_segments_tsv(slam), error)) return SdpRunStatus::kIoError;
  const io::Chart chart = error_chart(session.rounds(), scans.front().stamp_us);
  if (io::chart_has_data(chart) && !options.painter.chart(outputs.path("icp_error.png"), chart, error)) {
    return SdpRunStatus::kIoError;
  }

  // stats.json
  const DpSlamStats& bs = slam.bottom().stats();
  const SdpStats& st = slam.stats();
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  const SdpOptions& so = options.sdp;
  auto ms = [](double v) { return io::json_fixed(v, 3); };
  io::Json js;
  js["log"] = log_path;
  js["mode"] = "sdp";
  js["profile"] = to_string(options.profile);
  js["topology"] = so.topology == TopologyMode::kSdp ? "sdp" : "segslam";
  js["top_particles"] = so.top_particles;
  js["bottom_particles"] = fo.particle_count;
  js["seed"] = options.seed;
  js["scans"] = scans.size();
  js["processed_scans"] = bs.processed;
  js["scans_without_odometry"] = pairing.scans_without_odom();
  js["log_errors"] = reader.error_count();
  js["odometry_reversals_repaired"] = reader.odometry_reversals_repaired();
  js["odometry_jumps_removed"] = reader.odometry_jumps_removed();
  js["scans_stamped_backwards"] = reader.scans_stamped_backwards();
  js.update(session.state_json(path_gaps, known_cells));
  js["resumed_at_scan"] = resume_at;
  if (extended_after > 0U) {
    js["extended"] = continuation.report().json();
    js["extended"]["after_scan"] = extended_after;
  }
  if (!options.snapshot_path.empty()) {
    js["snapshots"] = {{"written", snapshots},
                       {"file_bytes", snapshot_bytes},
                       {"state_bytes", slam.state_bytes()},
                       {"write_ms_max", ms(snapshot_ms_max)}};
  }
  js["timing"] = {{"wall_time_s", ms(wall_s)},
                  {"extend_search_ms", ms(continuation.report().search_ms)},
                  {"scan_ms_p50", ms(percentile(scan_ms, 0.5))},
                  {"scan_ms_p99", ms(percentile(scan_ms, 0.99))},
                  {"scan_ms_max", ms(percentile(scan_ms, 1.0))},
                  {"segmentation_scan_ms_max", ms(percentile(segment_ms, 1.0))},
                  {"scan_cpu_ms_p50", ms(percentile(scan_cpu_ms, 0.5))},
                  {"scan_cpu_ms_p99", ms(percentile(scan_cpu_ms, 0.99))},
                  {"scan_cpu_ms_max", ms(percentile(scan_cpu_ms, 1.0))},
                  {"cpu_time_s", ms(rusage_cpu_s(ru))},
                  {"scan_cpu_ms_max_segmentation", ms(cpu_max_by_kind[0])},
                  {"scan_cpu_ms_max_evaluation", ms(cpu_max_by_kind[1])},
                  {"scan_cpu_ms_max_anchorage", ms(cpu_max_by_kind[2])},
                  {"scan_cpu_ms_max_bottom_only", ms(cpu_max_by_kind[3])},
                  {"scan_cpu_ms_max_bottom_processed", ms(cpu_max_bottom_processed)},
                  {"scan_cpu_ms_max_bottom_idle", ms(cpu_max_bottom_idle)},
                  {"scans_cpu_over_100ms", scans_cpu_over_100ms},
                  {"peak_rss_kib", static_cast<std::uint64_t>(ru.ru_maxrss)}};
  if (!io::write_file_atomic(outputs.path("stats.json"), io::json_text(js), error)) return SdpRunStatus::kIoError;
  if (!outputs.commit(error)) return SdpRunStatus::kIoError;

  if (summary != nullptr) {
    static_cast<RunSummary&>(*summary) = run_summary(reader, log_path, scans.size(), bs.processed, wall_s);
    summary->segments = st.segments;
    summary->icp_error_mean_m = st.error_mean_m();
    summary->icp_error_std_m = st.error_std_m();
    summary->icp_error_samples = st.error_samples;
    summary->resumed_at_scan = resume_at;
    summary->extended_after_scan = extended_after;
    if (extended_after > 0U) summary->extend_place = continuation.report().describe();
    summary->snapshots_written = snapshots;
    summary->snapshot_bytes = snapshot_bytes;
    summary->snapshot_write_ms_max = snapshot_ms_max;
  }
  return SdpRunStatus::kOk;
}

}  // namespace sdpslam::slam
