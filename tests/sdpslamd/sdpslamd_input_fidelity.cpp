// How faithfully the replay reached sdpslamd: its input recording (input.clf, [output]
// input_log) against the original log the replay served.
//
//   sdpslamd_input_fidelity ORIGINAL_LOG INPUT_CLF PLAY_START_US LOG_START_US SPEED
//
// Each recorded scan's stamp (monotonic) is mapped back to log time,
//   t_log = LOG_START + (t − PLAY_START) · SPEED,
// and matched with the original scan nearest in time. Printed: stamp offsets; odometry
// differences, each side taken relative to its first matched scan (the two odometry
// frames start at different instants); range differences beam by beam; the largest
// geometry difference. A figure, not a verdict: exit 0 iff both logs read without error
// and every recorded scan matched an original one within 20 ms of log time.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "sdpslam/io/log_reader.h"

int main(int argc, char** argv) {
  using namespace sdpslam;
  if (argc != 6) {
    std::fprintf(stderr, "usage: sdpslamd_input_fidelity ORIGINAL_LOG INPUT_CLF PLAY_START_US LOG_START_US SPEED\n");
    return 2;
  }
  const std::int64_t play_us = std::strtoll(argv[3], nullptr, 10);
  const std::int64_t log_start_us = std::strtoll(argv[4], nullptr, 10);
  const double speed = std::strtod(argv[5], nullptr);
  io::LogContents orig;
  io::LogContents rec;
  std::string error;
  const io::LogReaderOptions opt;
  if (!io::read_whole_log(argv[1], opt, &orig, &error) || !io::read_whole_log(argv[2], opt, &rec, &error)) {
    std::fprintf(stderr, "sdpslamd_input_fidelity: %s\n", error.c_str());
    return 3;
  }
  for (const io::LogContents* c : {&orig, &rec}) {
    if (c->error_count > 0U) {
      std::fprintf(stderr, "sdpslamd_input_fidelity: %zu bad lines, first: %s\n", c->error_count,
                   c->errors.empty() ? "?" : c->errors.front().to_string().c_str());
      return 3;
    }
  }
  if (rec.lasers.empty() || orig.lasers.empty()) {
    std::fprintf(stderr, "sdpslamd_input_fidelity: no scans\n");
    return 3;
  }
  std::size_t j = 0U;
  std::size_t matched = 0U, unmatched = 0U, beam_count_mismatch = 0U;
  double dt_max = 0.0, dt_sum = 0.0;
  double pos_max = 0.0, pos_sum = 0.0, head_max = 0.0, head_sum = 0.0;
  double range_max = 0.0, range_sum = 0.0;
  std::uint64_t beams = 0U, beams_same = 0U;
  double geo_max = 0.0;
  bool have_first = false;
  Pose2 rec0, orig0;
  for (const io::LaserRecord& r : rec.lasers) {
    const double t_log = static_cast<double>(log_start_us) + static_cast<double>(r.stamp_us - play_us) * speed;
    while (j + 1U < orig.lasers.size() && static_cast<double>(orig.lasers[j + 1U].stamp_us) <= t_log) ++j;
    std::size_t k = j;
    if (j + 1U < orig.lasers.size() &&
        std::fabs(static_cast<double>(orig.lasers[j + 1U].stamp_us) - t_log) <
            std::fabs(static_cast<double>(orig.lasers[j].stamp_us) - t_log)) {
      k = j + 1U;
    }
    const io::LaserRecord& o = orig.lasers[k];
    const double dt_ms = std::fabs(static_cast<double>(o.stamp_us) - t_log) / 1000.0;
    if (dt_ms > 20.0) {
      ++unmatched;
      continue;
    }
    ++matched;
    dt_max = std::fmax(dt_max, dt_ms);
    dt_sum += dt_ms;
    if (!have_first) {
      rec0 = r.odom_pose;
      orig0 = o.odom_pose;
      have_first = true;
    }
    const Pose2 a = between(rec0, r.odom_pose);
    const Pose2 b = between(orig0, o.odom_pose);
    const double dp = std::hypot(a.x_m - b.x_m, a.y_m - b.y_m);
    const double dh = std::fabs(normalize_angle_rad(a.heading_rad - b.heading_rad));
    pos_max = std::fmax(pos_max, dp);
    pos_sum += dp;
    head_max = std::fmax(head_max, dh);
    head_sum += dh;
    const ScanGeometry& g = r.scan.geometry;
    const ScanGeometry& h = o.scan.geometry;
    for (double d : {static_cast<double>(g.angle_min_rad - h.angle_min_rad),
                     static_cast<double>(g.angle_increment_rad - h.angle_increment_rad),
                     static_cast<double>(g.range_max_m - h.range_max_m), g.laser_in_base.x_m - h.laser_in_base.x_m,
                     g.laser_in_base.y_m - h.laser_in_base.y_m, g.laser_in_base.heading_rad - h.laser_in_base.heading_rad}) {
      geo_max = std::fmax(geo_max, std::fabs(d));
    }
    if (r.scan.beam_count != o.scan.beam_count) {
      ++beam_count_mismatch;
      continue;
    }
    for (std::uint32_t i = 0; i < r.scan.beam_count; ++i) {
      const double d = std::fabs(static_cast<double>(r.scan.ranges_m[i]) - static_cast<double>(o.scan.ranges_m[i]));
      range_max = std::fmax(range_max, d);
      range_sum += d;
      ++beams;
      if (r.scan.ranges_m[i] == o.scan.ranges_m[i]) ++beams_same;
    }
  }
  const double m = matched > 0U ? static_cast<double>(matched) : 1.0;
  std::printf(
      "replay fidelity: %zu recorded scans, %zu matched (stamp offset max %.3f ms mean %.3f ms), %zu unmatched\n"
      "  odometry vs log (relative to the first scan): position max %.6f m mean %.6f m, heading max %.6f rad mean "
      "%.6f rad\n"
      "  ranges vs log: %llu beams, %llu identical, diff max %.6f m mean %.6f m; beam-count mismatches %zu; "
      "geometry diff max %.3g\n",
      rec.lasers.size(), matched, dt_max, dt_sum / m, unmatched, pos_max, pos_sum / m, head_max, head_sum / m,
      static_cast<unsigned long long>(beams), static_cast<unsigned long long>(beams_same), range_max,
      beams > 0U ? range_sum / static_cast<double>(beams) : 0.0, beam_count_mismatch, geo_max);
  return unmatched == 0U && matched > 0U ? 0 : 1;
}
