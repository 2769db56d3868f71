// `sdpslam evaluate`: accuracy of a trajectory.
//
//   sdpslam evaluate --log LOG --relations FILE (--trajectory TRAJ | --odometry)
//       relations metric (Kümmerle et al. 2009) against a Freiburg `.relations` file.
//       The log supplies the laser stamps and the odometry pose at every scan: scans the
//       trajectory has no pose for are filled with the last estimate composed with
//       odometry (tools/eval/include/sdpslam/eval/relations.h). --odometry evaluates the
//       log's own odometry poses (the "raw odometry" baseline). With --segments (a
//       run's segments.tsv) it also fits each segment's frame rigidly to the relations
//       and says how much of the error the frames' placement accounts for
//       (tools/eval/include/sdpslam/eval/frame_fit.h).
//   sdpslam evaluate --trajectory TRAJ --ground-truth GT [--rpe-m D] [--segments SEGMENTS.tsv]
//       absolute trajectory error after the best SE(2) alignment, and the relative
//       error over every D metres of the ground-truth path (default 10; 0 = not measured):
//       the local drift, with the along-track scale error (tools/eval/include/sdpslam/eval/rpe.h).
//       With --segments (a run's segments.tsv) also the error within the submaps: each
//       segment aligned on its own, and each segment's drift from its first scan to its
//       last (tools/eval/include/sdpslam/eval/segment_drift.h).
//   sdpslam evaluate --loops LOOPS.tsv --ground-truth GT
//       the loop constraints a run held (its loops.tsv) checked against the ground truth:
//       how many were right (< 0.5 m), wrong (>= 2 m) or between, per source (the wide
//       search, the top level's ICP) and among those used at the end
//       (tools/eval/include/sdpslam/eval/loops.h).
//   sdpslam evaluate --log LOG --trajectory TRAJ --map MAP.yaml
//       agreement of the map with the trajectory: the share of the log's laser returns,
//       cast from the trajectory's poses, that end within one cell of an occupied cell
//       (tools/eval/include/sdpslam/eval/map_agreement.h). No ground truth needed.
//
// Any of them can be asked for at once. --json FILE writes the figures as JSON (atomically).
// Exit codes (cli_common.h): bad or inconsistent input → kExitBadInput with file:line.
#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "cli_common.h"
#include "sdpslam/eval/ate.h"
#include "sdpslam/eval/frame_fit.h"
#include "sdpslam/eval/log_scans.h"
#include "sdpslam/eval/loops.h"
#include "sdpslam/eval/map_agreement.h"
#include "sdpslam/eval/relations.h"
#include "sdpslam/eval/rpe.h"
#include "sdpslam/eval/segment_drift.h"
#include "sdpslam/eval/stamp_match.h"
#include "sdpslam/io/atomic_file.h"
#include "sdpslam/io/json_text.h"
#include "sdpslam/io/map_image.h"
#include "sdpslam/io/map_read.h"
#include "sdpslam/io/trajectory_io.h"

namespace sdpslam::cli {
namespace {

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

// "2 s", "60 s", "0.5 s": seconds as a person writes them.
std::string format_seconds(double s) {
  char text[32];
  std::snprintf(text, sizeof text, "%g s", s);
  return text;
}

struct EvaluateArgs {
  std::string log_path;
  std::string relations_path;
  std::string trajectory_path;
  std::string ground_truth_path;
  std::string map_path;
  std::string loops_path;
  std::string json_path;
  std::string plot_path;
  std::string segments_path;
  bool odometry = false;
  double rpe_m = 10.0;
  std::int64_t tolerance_us = eval::kDefaultStampToleranceUs;
};

io::Json json_stats(const eval::ErrorStats& s) {
  return {{"mean", s.mean}, {"std", s.std_dev}, {"max", s.max}, {"count", s.count}};
}

// ---- inputs ------------------------------------------------------------------------------

int read_scan_odometry(const std::string& log_path, std::vector<io::StampedPose>* scans) {
  eval::LogScansReport rep;
  std::string error;
  const bool ok = eval::read_log_scan_odometry(log_path, scans, &rep, &error);
  if (rep.malformed_line_count > 0) {
    std::fprintf(stderr, "sdpslam evaluate: %zu malformed line(s) of %s skipped; first: %s\n", rep.malformed_line_count,
                 log_path.c_str(), rep.first_malformed.c_str());
  }
  if (!ok) {
    std::fprintf(stderr, "sdpslam evaluate: %s\n", error.c_str());
    return kExitBadInput;
  }
  if (rep.without_odometry_count > 0) {
    std::fprintf(stderr, "sdpslam evaluate: %s: %zu laser scan(s) carry no odometry pose and are left out\n",
                 log_path.c_str(), rep.without_odometry_count);
  }
  return kExitOk;
}

int read_trajectory_file(const std::string& path, std::vector<io::StampedPose>* poses) {
  std::string error;
  if (!io::read_trajectory(path, poses, &error)) {
    std::fprintf(stderr, "sdpslam evaluate: %s\n", error.c_str());
    return kExitBadInput;
  }
  if (poses->empty()) {
    std::fprintf(stderr, "sdpslam evaluate: %s: no poses\n", path.c_str());
    return kExitBadInput;
  }
  return kExitOk;
}

// ---- the evaluations --------------------------------------------------------------------

// Each used relation's translational error at the time its first stamp is from the
// first relation's, and their mean.
io::Chart relations_chart(const eval::RelationsResult& res, const std::string& source) {
  io::Chart chart;
  const std::size_t slash = source.find_last_of('/');
  chart.title = "Relations metric: translational error per relation (" +
                (slash == std::string::npos ? source : source.substr(slash + 1U)) + ")";
  chart.x_label = "relation start, time since the first relation (s)";
  chart.y_label = "translational error (m)";
  io::ChartSeries each = io::ChartSeries::named("one relation", io::Rgb8{40, 90, 180}, io::ChartSeries::Style::kPoints);
  char label[96];
  std::snprintf(label, sizeof label, "mean of %zu: %.4f m", res.per_relation.size(), res.translation_m.mean);
  io::ChartSeries mean = io::ChartSeries::named(label, io::Rgb8{200, 30, 30});
  std::int64_t t0_us = res.per_relation.empty() ? 0 : res.per_relation.front().relation.t1_us;
  for (const eval::RelationResult& r : res.per_relation) t0_us = std::min(t0_us, r.relation.t1_us);
  double t_end_s = 0.0;
  for (const eval::RelationResult& r : res.per_relation) {
    const double t_s = static_cast<double>(r.relation.t1_us - t0_us) * 1e-6;
    each.x.push_back(t_s);
    each.y.push_back(r.translation_error_m);
    t_end_s = std::max(t_end_s, t_s);
  }
  mean.x = {0.0, t_end_s};
  mean.y = {res.translation_m.mean, res.translation_m.mean};
  chart.series.push_back(each);
  chart.series.push_back(mean);
  return chart;
}

// A run's segments.tsv, not empty; kExitBadInput with file:line otherwise.
int read_segments_file(const std::string& path, std::vector<eval::SegmentStart>* segments) {
  std::string error;
  if (!eval::read_segments(path, segments, &error)) {
    std::fprintf(stderr, "sdpslam evaluate: %s\n", error.c_str());
    return kExitBadInput;
  }
  if (segments->empty()) {
    std::fprintf(stderr, "sdpslam evaluate: %s: no segments\n", path.c_str());
    return kExitBadInput;
  }
  return kExitOk;
}

int run_relations(const EvaluateArgs& a, io::Json* json) {
  std::vector<eval::Relation> relations;
  std::string error;
  if (!eval::read_relations(a.relations_path, &relations, &error)) {
    std::fprintf(stderr, "sdpslam evaluate: %s\n", error.c_str());
    return kExitBadInput;
  }
  if (relations.empty()) {
    std::fprintf(stderr, "sdpslam evaluate: %s: no relations\n", a.relations_path.c_str());
    return kExitBadInput;
  }
  std::vector<io::StampedPose> scans;
  if (const int rc = read_scan_odometry(a.log_path, &scans); rc != kExitOk) return rc;

  std::vector<io::StampedPose> per_scan;
  eval::FillReport fill;
  std::string source;
  if (a.odometry) {
    per_scan = scans;
    fill.scan_count = fill.estimated_count = scans.size();
    source = "odometry of " + a.log_path;
  } else {
    std::vector<io::StampedPose> estimate;
    if (const int rc = read_trajectory_file(a.trajectory_path, &estimate); rc != kExitOk) return rc;
    if (!eval::fill_with_odometry(estimate, scans, a.tolerance_us, &per_scan, &fill, &error)) {
      std::fprintf(stderr, "sdpslam evaluate: %s against %s: %s\n", a.trajectory_path.c_str(), a.log_path.c_str(),
                   error.c_str());
      return kExitBadInput;
    }
    source = a.trajectory_path;
  }

  const eval::RelationsResult res = eval::evaluate_relations(relations, per_scan, a.tolerance_us);
  for (const eval::Relation& r : res.unmatched) {
    std::fprintf(stderr, "sdpslam evaluate: %s:%" PRId64 ": relation %s -> %s: a stamp matches no laser scan within %" PRId64
                         " us; left out\n",
                 a.relations_path.c_str(), r.line, io::format_stamp_us(r.t1_us).c_str(),
                 io::format_stamp_us(r.t2_us).c_str(), a.tolerance_us);
  }
  if (res.unmatched_count > res.unmatched.size()) {
    std::fprintf(stderr, "sdpslam evaluate: ... and %zu more unmatched relations\n",
                 res.unmatched_count - res.unmatched.size());
  }

  std::printf("Relations metric (Kümmerle et al. 2009)\n");
  std::printf("  relations   %s: %zu, used %zu (%zu exact stamp matches), unmatched %zu\n", a.relations_path.c_str(),
              res.relation_count, res.used_count, res.exact_match_count, res.unmatched_count);
  std::printf("  trajectory  %s: %zu scans, %zu estimated, %zu filled from odometry", source.c_str(), fill.scan_count,
              fill.estimated_count, fill.filled_count);
  if (fill.unmatched_estimate_count > 0) std::printf(", %zu poses matched no scan", fill.unmatched_estimate_count);
  std::printf("\n");
  std::printf("  %-22s %12s %12s %12s\n", "error", "mean", "std", "max");
  const auto row = [](const char* name, const eval::ErrorStats& s) {
    std::printf("  %-22s %12.6f %12.6f %12.6f\n", name, s.mean, s.std_dev, s.max);
  };
  row("translation [m]", res.translation_m);
  row("translation^2 [m^2]", res.translation_m2);
  row("rotation [deg]", res.rotation_deg);
  row("rotation^2 [deg^2]", res.rotation_deg2);
  // Where it went wrong, worst first, one relation per event (a stretch and a revisit
  // of it err alike over many relations): the stamps to look at in the log.
  constexpr std::size_t kWorstShown = 5U;
  constexpr std::int64_t kSameEventUs = 60000000;
  io::Json worst = io::Json::array();
  for (std::size_t i : eval::worst_relations(res, kWorstShown, kSameEventUs)) {
    const eval::RelationResult& w = res.per_relation[i];
    const double apart_m = std::hypot(w.relation.expected.x_m, w.relation.expected.y_m);
    std::printf("  worst       stamps %.1f s and %.1f s (%.2f m apart): %.3f m, %.2f deg off\n",
                static_cast<double>(w.relation.t1_us) * 1e-6, static_cast<double>(w.relation.t2_us) * 1e-6, apart_m,
                w.translation_error_m, w.rotation_error_rad * kRadToDeg);
    worst.push_back(io::Json{{"t1_us", w.relation.t1_us},
                             {"t2_us", w.relation.t2_us},
                             {"apart_m", apart_m},
                             {"translation_m", w.translation_error_m},
                             {"rotation_deg", w.rotation_error_rad * kRadToDeg}});
  }

  // Local error or revisits: relations between scans under 2 s apart measure the step
  // by step error (the same split with --odometry gives the odometry's); a minute and
  // more, as for the worst events, the revisits.
  io::Json by_span = io::Json::array();
  for (const eval::SpanClass& c : eval::relations_by_span(res, {2000000, kSameEventUs})) {
    const double from_s = static_cast<double>(c.from_us) * 1e-6;
    const double to_s = static_cast<double>(c.to_us) * 1e-6;
    std::string range = c.to_us < 0 ? format_seconds(from_s) + " and over"
                        : c.from_us == 0 ? "under " + format_seconds(to_s)
                                         : format_seconds(from_s) + " to " + format_seconds(to_s);
    std::printf("  span        %s: %zu relations, mean %.3f m, max %.3f m (%.0f %% of the error)", range.c_str(),
                c.translation_m.count, c.translation_m.mean, c.translation_m.max, 100.0 * c.share);
    if (c.scale_measured) std::printf(", along-track scale %+.3f %%", 100.0 * c.scale_error);
    std::printf("\n");
    by_span.push_back(io::Json{{"from_s", from_s},
                               {"to_s", c.to_us < 0 ? io::Json(nullptr) : io::Json(to_s)},
                               {"count", c.translation_m.count},
                               {"translation_mean_m", c.translation_m.mean},
                               {"translation_max_m", c.translation_m.max},
                               {"share", c.share},
                               {"scale_error", c.scale_measured ? io::Json(c.scale_error) : io::Json(nullptr)}});
  }

  io::Json frame_fit = nullptr;
  if (!a.segments_path.empty()) {
    std::vector<eval::SegmentStart> segments;
    if (const int rc = read_segments_file(a.segments_path, &segments); rc != kExitOk) return rc;
    const eval::FrameFitResult f = eval::fit_segment_frames(relations, per_scan, segments, a.tolerance_us);
    std::printf("  segments    %s: %zu; each segment's frame fitted rigidly to the relations (%zu moved)\n",
                a.segments_path.c_str(), segments.size(), f.segments_moved);
    const auto part = [](const char* name, const eval::FrameFitPart& p) {
      std::printf("  %-22s %zu relations, mean %.3f m as estimated, %.3f m with the fitted frames\n", name, p.count,
                  p.mean_m, p.fitted_mean_m);
    };
    part("  all", f.all);
    part("  within a segment", f.within);
    part("  across segments", f.across);
    std::printf("  frame fit   the frames' placement accounts for %.3f m of the mean (%u steps%s)\n",
                f.all.mean_m - f.all.fitted_mean_m, f.steps, f.converged ? "" : ", not converged: the best placement may do better");
    const auto part_json = [](const eval::FrameFitPart& p) {
      return io::Json{{"count", p.count}, {"mean_m", p.mean_m}, {"fitted_mean_m", p.fitted_mean_m}};
    };
    frame_fit = io::Json{{"segments_file", a.segments_path},
                         {"segment_count", segments.size()},
                         {"segments_moved", f.segments_moved},
                         {"all", part_json(f.all)},
                         {"within", part_json(f.within)},
                         {"across", part_json(f.across)},
                         {"steps", f.steps},
                         {"converged", f.converged}};
  }

  (*json)["relations"] = {{"file", a.relations_path},
                          {"log", a.log_path},
                          {"trajectory", a.odometry ? std::string("odometry") : a.trajectory_path},
                          {"relation_count", res.relation_count},
                          {"used_count", res.used_count},
                          {"exact_match_count", res.exact_match_count},
                          {"unmatched_count", res.unmatched_count},
                          {"scan_count", fill.scan_count},
                          {"filled_scan_count", fill.filled_count},
                          {"stamp_tolerance_us", a.tolerance_us},
                          {"translation_m", json_stats(res.translation_m)},
                          {"translation_m2", json_stats(res.translation_m2)},
                          {"rotation_deg", json_stats(res.rotation_deg)},
                          {"rotation_deg2", json_stats(res.rotation_deg2)},
                          {"worst", worst},
                          {"by_span", by_span},
                          {"frame_fit", frame_fit}};
  if (res.used_count == 0) {
    std::fprintf(stderr, "sdpslam evaluate: no relation of %s matches the scans of %s\n", a.relations_path.c_str(),
                 a.log_path.c_str());
    return kExitBadInput;
  }
  if (!a.plot_path.empty()) {
    std::string plot_error;
    if (!figure_painter().chart(a.plot_path, relations_chart(res, source), &plot_error)) {
      std::fprintf(stderr, "sdpslam evaluate: %s\n", plot_error.c_str());
      return kExitIo;
    }
  }
  return kExitOk;
}

int run_ate(const EvaluateArgs& a, io::Json* json) {
  std::vector<io::StampedPose> estimate;
  std::vector<io::StampedPose> truth;
  if (const int rc = read_trajectory_file(a.trajectory_path, &estimate); rc != kExitOk) return rc;
  if (const int rc = read_trajectory_file(a.ground_truth_path, &truth); rc != kExitOk) return rc;
  eval::AteResult r;
  if (!eval::compute_ate(estimate, truth, a.tolerance_us, &r)) {
    std::fprintf(stderr, "sdpslam evaluate: no pose of %s has a ground-truth pose in %s within %" PRId64 " us\n",
                 a.trajectory_path.c_str(), a.ground_truth_path.c_str(), a.tolerance_us);
    return kExitBadInput;
  }
  if (r.unmatched_estimate_count > 0) {
    std::fprintf(stderr, "sdpslam evaluate: %zu pose(s) of %s have no ground truth within %" PRId64 " us; left out\n",
                 r.unmatched_estimate_count, a.trajectory_path.c_str(), a.tolerance_us);
  }
  std::printf("Absolute trajectory error (after SE(2) alignment)\n");
  std::printf("  trajectory  %s: %zu poses, %zu matched to %s (%zu poses)\n", a.trajectory_path.c_str(),
              r.estimate_count, r.matched_count, a.ground_truth_path.c_str(), r.ground_truth_count);
  std::printf("  alignment   x %.6f m, y %.6f m, theta %.6f deg\n", r.alignment.x_m, r.alignment.y_m,
              r.alignment.heading_rad * kRadToDeg);
  std::printf("  position    rmse %.6f m, mean %.6f m, max %.6f m\n", r.rmse_m, r.mean_m, r.max_m);
  std::printf("  heading     rmse %.6f deg\n", r.heading_rmse_rad * kRadToDeg);
  io::Json& ate = (*json)["ate"];
  ate = {{"trajectory", a.trajectory_path},
         {"ground_truth", a.ground_truth_path},
         {"estimate_count", r.estimate_count},
         {"ground_truth_count", r.ground_truth_count},
         {"matched_count", r.matched_count},
         {"unmatched_estimate_count", r.unmatched_estimate_count},
         {"rmse_m", r.rmse_m},
         {"mean_m", r.mean_m},
         {"max_m", r.max_m},
         {"heading_rmse_deg", r.heading_rmse_rad * kRadToDeg},
         {"alignment", {{"x_m", r.alignment.x_m}, {"y_m", r.alignment.y_m}, {"heading_rad", r.alignment.heading_rad}}}};
  eval::RpeResult q;
  if (!(a.rpe_m > 0.0)) {
    // not asked for
  } else if (!eval::compute_rpe(estimate, truth, a.tolerance_us, a.rpe_m, &q)) {
    std::printf("  relative    not measured: the ground-truth path is shorter than %.3f m\n", a.rpe_m);
  } else {
    std::printf("  relative    over %zu stretches of %.3f m: mean %.6f m, rmse %.6f m, max %.6f m, heading %.6f deg, "
                "along-track scale %+.3f %%\n",
                q.stretch_count, q.distance_m, q.mean_m, q.rmse_m, q.max_m, q.heading_mean_rad * kRadToDeg,
                100.0 * q.scale_error);
    (*json)["rpe"] = {{"distance_m", q.distance_m},
                      {"stretch_count", q.stretch_count},
                      {"mean_m", q.mean_m},
                      {"rmse_m", q.rmse_m},
                      {"max_m", q.max_m},
                      {"heading_mean_deg", q.heading_mean_rad * kRadToDeg},
                      {"scale_error", q.scale_error}};
  }
  if (a.segments_path.empty()) return kExitOk;
  std::vector<eval::SegmentStart> segments;
  if (const int rc = read_segments_file(a.segments_path, &segments); rc != kExitOk) return rc;
  eval::SegmentDriftResult d;
  if (!eval::measure_segment_drift(estimate, truth, segments, a.tolerance_us, &d)) {
    std::printf("  segments    %s: %zu; not measured: no segment has two scans with ground truth\n",
                a.segments_path.c_str(), segments.size());
    (*json)["segment_drift"] = nullptr;
    return kExitOk;
  }
  std::printf("  segments    %s: %zu, %zu measured over %.1f m of path; each segment aligned on its own\n",
              a.segments_path.c_str(), segments.size(), d.segments_measured, d.path_m);
  std::printf("  within      position rmse %.6f m, mean %.6f m (the placement of the segments accounts for the rest)\n",
              d.aligned_rmse_m, d.aligned_mean_m);
  std::printf("  drift       first to last scan of a segment: mean %.6f m, max %.6f m, %.6f m per 10 m of path, "
              "heading %.6f deg, along-track scale %+.3f %% (%zu chords of %.0f m or more)\n",
              d.endpoint_mean_m, d.endpoint_max_m, d.drift_per_10m_m, d.heading_mean_rad * kRadToDeg,
              100.0 * d.along_track_scale, d.chords_measured, eval::kMinDriftChordM);
  (*json)["segment_drift"] = {{"segments_file", a.segments_path},
                              {"segment_count", segments.size()},
                              {"segments_measured", d.segments_measured},
                              {"scans_matched", d.scans_matched},
                              {"path_m", d.path_m},
                              {"aligned_rmse_m", d.aligned_rmse_m},
                              {"aligned_mean_m", d.aligned_mean_m},
                              {"endpoint_mean_m", d.endpoint_mean_m},
                              {"endpoint_max_m", d.endpoint_max_m},
                              {"drift_per_10m_m", d.drift_per_10m_m},
                              {"heading_mean_deg", d.heading_mean_rad * kRadToDeg},
                              {"chords_measured", d.chords_measured},
                              {"along_track_scale", d.along_track_scale}};
  return kExitOk;
}

io::Json json_bins(const eval::LoopBins& b) {
  return {{"count", b.count}, {"right", b.right}, {"between", b.between}, {"wrong", b.wrong}, {"max_m", b.max_m}};
}

int run_loops(const EvaluateArgs& a, io::Json* json) {
  std::vector<eval::LoopLine> lines;
  std::string error;
  if (!eval::read_loops(a.loops_path, &lines, &error)) {
    std::fprintf(stderr, "sdpslam evaluate: %s\n", error.c_str());
    return kExitBadInput;
  }
  std::vector<io::StampedPose> truth;
  if (const int rc = read_trajectory_file(a.ground_truth_path, &truth); rc != kExitOk) return rc;
  const eval::LoopsResult r = eval::check_loops(lines, truth, a.tolerance_us);
  auto row = [](const char* what, const eval::LoopBins& b) {
    std::printf("  %-10s  %zu: right %zu, between %zu, wrong %zu, largest error %.3f m\n", what, b.count, b.right,
                b.between, b.wrong, b.max_m);
  };
  std::printf("Loop constraints against the ground truth (right: within %.1f m, wrong: %.1f m or more)\n",
              eval::kLoopRightM, eval::kLoopWrongM);
  std::printf("  loops       %zu in %s, %zu without a ground-truth origin\n", r.count, a.loops_path.c_str(),
              r.unmatched);
  row("search", r.search);
  row("icp", r.icp);
  row("used", r.used);
  // The wrong ones by name, worst first, so that a run can be looked into where it went
  // wrong (levels and stamps as in loops.tsv).
  std::vector<std::size_t> wrong;
  for (std::size_t i = 0; i < r.checks.size() && i < lines.size(); ++i) {
    if (r.checks[i].matched && r.checks[i].error_m >= eval::kLoopWrongM) wrong.push_back(i);
  }
  std::stable_sort(wrong.begin(), wrong.end(),
                   [&r](std::size_t x, std::size_t y) { return r.checks[x].error_m > r.checks[y].error_m; });
  constexpr std::size_t kWrongShown = 20U;
  for (std::size_t k = 0; k < wrong.size() && k < kWrongShown; ++k) {
    const eval::LoopLine& l = lines[wrong[k]];
    std::printf("  wrong       levels %u-%u (%s%s, stamps %.1f s and %.1f s): %.3f m, %.2f deg off\n", l.older_level,
                l.newer_level, l.searched ? "search" : "icp", l.used ? ", used" : "",
                static_cast<double>(l.older_stamp_us) * 1e-6, static_cast<double>(l.newer_stamp_us) * 1e-6,
                r.checks[wrong[k]].error_m, r.checks[wrong[k]].heading_error_rad * 180.0 / 3.14159265358979323846);
  }
  if (wrong.size() > kWrongShown) std::printf("  wrong       ... and %zu more\n", wrong.size() - kWrongShown);
  (*json)["loops"] = {{"file", a.loops_path},
                      {"count", r.count},
                      {"unmatched", r.unmatched},
                      {"search", json_bins(r.search)},
                      {"icp", json_bins(r.icp)},
                      {"used", json_bins(r.used)}};
  return kExitOk;
}

int run_map_agreement(const EvaluateArgs& a, io::Json* json) {
  std::vector<io::StampedPose> estimate;
  if (const int rc = read_trajectory_file(a.trajectory_path, &estimate); rc != kExitOk) return rc;
  // Logs are not always in time order (intel.clf), and trajectories follow the log.
  estimate = eval::sorted_by_stamp(std::move(estimate));
  io::OccupancyImage map;
  io::MapWriteOptions thresholds;
  std::string error;
  if (!io::read_map_yaml(a.map_path, &map, &thresholds, &error)) {
    std::fprintf(stderr, "sdpslam evaluate: %s\n", error.c_str());
    return kExitBadInput;
  }
  eval::MapAgreementResult r;
  if (!eval::evaluate_map_agreement(a.log_path, estimate, map, thresholds.occupied_thresh, a.tolerance_us, &r, &error)) {
    std::fprintf(stderr, "sdpslam evaluate: %s\n", error.c_str());
    return kExitBadInput;
  }
  std::printf("Map agreement (laser returns cast from the trajectory, ending within one cell of an occupied cell)\n");
  std::printf("  map         %s: %u x %u cells of %.3f m\n", a.map_path.c_str(), map.width, map.height, map.resolution_m);
  std::printf("  scans       %zu of %zu cast from %s\n", r.scans_cast, r.scan_count, a.trajectory_path.c_str());
  std::printf("  on walls    %zu of %zu returns = %.4f\n", r.on_wall_count, r.return_count, r.share());
  (*json)["map_agreement"] = {{"map", a.map_path},
                              {"trajectory", a.trajectory_path},
                              {"scan_count", r.scan_count},
                              {"scans_cast", r.scans_cast},
                              {"return_count", r.return_count},
                              {"on_wall_count", r.on_wall_count},
                              {"share", r.share()}};
  if (r.scans_cast == 0U) {
    std::fprintf(stderr, "sdpslam evaluate: no scan of %s has a pose in %s\n", a.log_path.c_str(),
                 a.trajectory_path.c_str());
    return kExitBadInput;
  }
  return kExitOk;
}

int run_evaluate(const EvaluateArgs& a) {
  const bool want_relations = !a.relations_path.empty();
  const bool want_ate = !a.ground_truth_path.empty();
  const bool want_map = !a.map_path.empty();
  const bool want_loops = !a.loops_path.empty();
  if (!want_relations && !want_ate && !want_map && !want_loops) {
    std::fprintf(stderr,
                 "sdpslam evaluate: give --relations (with --log), --ground-truth (with --trajectory), --loops (with "
                 "--ground-truth) or --map (with --log and --trajectory)\n");
    return kExitUsage;
  }
  if (want_loops && a.ground_truth_path.empty()) {
    std::fprintf(stderr, "sdpslam evaluate: --loops needs --ground-truth\n");
    return kExitUsage;
  }
  if (want_map && (a.log_path.empty() || a.trajectory_path.empty())) {
    std::fprintf(stderr, "sdpslam evaluate: --map needs --log and --trajectory\n");
    return kExitUsage;
  }
  if (want_relations && (a.log_path.empty() || (a.trajectory_path.empty() == !a.odometry))) {
    std::fprintf(stderr, "sdpslam evaluate: --relations needs --log and exactly one of --trajectory, --odometry\n");
    return kExitUsage;
  }
  if (want_ate && a.trajectory_path.empty() && !want_loops) {
    std::fprintf(stderr, "sdpslam evaluate: --ground-truth needs --trajectory\n");
    return kExitUsage;
  }
  if (!(a.rpe_m >= 0.0) || a.rpe_m > 1.0e6) {
    std::fprintf(stderr, "sdpslam evaluate: --rpe-m must be a distance in metres, 0 .. 1e6 (0: not measured)\n");
    return kExitUsage;
  }
  if (!a.segments_path.empty() && ((!want_relations && !want_ate) || a.trajectory_path.empty())) {
    std::fprintf(stderr, "sdpslam evaluate: --segments needs --trajectory and --relations or --ground-truth\n");
    return kExitUsage;
  }
  if (!a.plot_path.empty() && !want_relations) {
    std::fprintf(stderr, "sdpslam evaluate: --plot needs --relations\n");
    return kExitUsage;
  }
  if (a.tolerance_us < 0) {
    std::fprintf(stderr, "sdpslam evaluate: --stamp-tolerance-us must not be negative\n");
    return kExitUsage;
  }
  io::Json json = io::Json::object();
  if (want_relations) {
    if (const int rc = run_relations(a, &json); rc != kExitOk) return rc;
  }
  if (want_ate && !a.trajectory_path.empty()) {
    if (!json.empty()) std::printf("\n");
    if (const int rc = run_ate(a, &json); rc != kExitOk) return rc;
  }
  if (want_loops) {
    if (!json.empty()) std::printf("\n");
    if (const int rc = run_loops(a, &json); rc != kExitOk) return rc;
  }
  if (want_map) {
    if (!json.empty()) std::printf("\n");
    if (const int rc = run_map_agreement(a, &json); rc != kExitOk) return rc;
  }
  if (!a.json_path.empty()) {
    std::string error;
    if (!io::write_file_atomic(a.json_path, io::json_text(json), &error)) {
      std::fprintf(stderr, "sdpslam evaluate: %s\n", error.c_str());
      return kExitIo;
    }
  }
  return kExitOk;
}

std::function<int()> setup_evaluate(CLI::App& app) {
  auto args = std::make_shared<EvaluateArgs>();
  app.add_option("--log", args->log_path, "robot log whose laser stamps and odometry the relations refer to");
  app.add_option("--relations", args->relations_path, "ground-truth relations file (t1 t2 x y z roll pitch yaw)");
  auto* traj = app.add_option("--trajectory", args->trajectory_path, "estimated trajectory (t x y theta, or TUM)");
  app.add_flag("--odometry", args->odometry, "evaluate the log's own odometry poses (raw-odometry baseline)")
      ->excludes(traj);
  app.add_option("--ground-truth", args->ground_truth_path, "ground-truth trajectory for the absolute error");
  app.add_option("--rpe-m", args->rpe_m,
                 "with --ground-truth: also the relative error over every stretch of this many metres (default 10, "
                 "0 = not measured)");
  app.add_option("--map", args->map_path, "map (map_server YAML + PGM) whose agreement with --trajectory to measure");
  app.add_option("--loops", args->loops_path,
                 "with --ground-truth: check the loop constraints of a run (its loops.tsv) against it");
  app.add_option("--json", args->json_path, "also write the figures to this JSON file");
  app.add_option("--plot", args->plot_path,
                 "with --relations: draw each relation's translational error over time into this PNG file");
  app.add_option("--segments", args->segments_path,
                 "with --trajectory: the run's segments.tsv; with --relations, fit each segment's frame to the "
                 "relations (how much of the error lies in the frames' placement, how much within the submaps); with "
                 "--ground-truth, align each segment on its own and measure its drift from first to last scan");
  app.add_option("--stamp-tolerance-us", args->tolerance_us,
                 "stamps closer than this name the same scan when not equal (default 1000)");
  return [args] { return run_evaluate(*args); };
}

}  // namespace

SDPSLAM_REGISTER_COMMAND(evaluate, "evaluate", "accuracy of a trajectory (relations metric, ATE) and its map's agreement with it", 40,
                         setup_evaluate);

}  // namespace sdpslam::cli
