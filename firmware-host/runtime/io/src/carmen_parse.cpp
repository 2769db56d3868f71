// One CARMEN log line to a record. Field layouts: ../shared/datasets/README.md, the
// header comments of the Radish logs, and CARMEN's logger (logtools/writelog.c,
// carmen_logwrite_write_robot_laser) for ROBOTLASER1.
#include <cmath>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "carmen_parse.h"
#include "log_parse.h"
#include "sdpslam/io/log_reader.h"

namespace sdpslam::io {
namespace detail {
namespace {

constexpr double kPi = 3.14159265358979323846;

using Fields = std::vector<std::string_view>;

// Message types of CARMEN logs that carry nothing this reader uses.
bool is_ignored_type(std::string_view k) {
  static constexpr const char* kIgnored[] = {
      "SYNC",         "TRUEPOS",   "RAWLASER1", "RAWLASER2",  "RAWLASER3",      "RAWLASER4",
      "RAWLASER5",    "SONAR",     "BUMPER",    "SCANMARK",   "POSITIONLASER",  "IMU",
      "VECTORMOVE",   "ROBOTVELOCITY", "FOLLOWTRAJECTORY", "BASEVELOCITY", "ARM", "PANTILT",
      "GPSNMEA",      "REARLASER", "LOCALIZE",  "GLOBALPOS",  "ROBOTLASER3",    "ROBOTLASER4"};
  for (const char* name : kIgnored) {
    if (k == name) return true;
  }
  return k.rfind("NMEA-", 0) == 0;
}

std::string field_count_reason(std::string_view keyword, std::int64_t n, std::size_t want, std::size_t got) {
  return std::string(keyword) + " with " + std::to_string(n) + " readings needs " + std::to_string(want) +
         " fields, found " + std::to_string(got);
}

// Parses fields[i], i+1, i+2 as a pose.
bool parse_pose(const Fields& f, std::size_t i, Pose2* out, std::string* reason, const char* what) {
  double v[3];
  for (std::size_t k = 0; k < 3; ++k) {
    if (!parse_finite(f[i + k], &v[k])) {
      *reason = std::string(what) + " field " + std::to_string(i + k + 1) + " is not a finite number: " +
                quote(f[i + k]);
      return false;
    }
  }
  *out = Pose2{v[0], v[1], v[2]};
  return true;
}

// The trailing "ipc_timestamp ipc_hostname logger_timestamp" of every message.
bool parse_trailer(const Fields& f, std::int64_t* ipc_us, std::int64_t* logger_us, std::string* reason) {
  const std::size_t n = f.size();
  if (!parse_stamp_us(f[n - 3], ipc_us)) {
    *reason = "ipc_timestamp (field " + std::to_string(n - 2) + ") is not a decimal time: " + quote(f[n - 3]);
    return false;
  }
  if (!parse_stamp_us(f[n - 1], logger_us)) {
    *reason = "logger_timestamp (field " + std::to_string(n) + ") is not a decimal time: " + quote(f[n - 1]);
    return false;
  }
  return true;
}

bool parse_beam_count(const Fields& f, std::size_t i, std::int64_t* n, std::string* reason) {
  if (!parse_int(f[i], n)) {
    *reason = "beam count (field " + std::to_string(i + 1) + ") is not an integer: " + quote(f[i]);
    return false;
  }
  if (*n < 2) {
    *reason = "beam count " + std::to_string(*n) + " (field " + std::to_string(i + 1) + ") is below 2";
    return false;
  }
  if (*n > static_cast<std::int64_t>(capacity::kMaxBeams)) {
    *reason = "beam count " + std::to_string(*n) + " exceeds the capacity of " +
              std::to_string(capacity::kMaxBeams) + " beams";
    return false;
  }
  return true;
}

bool parse_ranges(const Fields& f, std::size_t first, std::int64_t n, RangeScan* scan, std::string* reason) {
  for (std::int64_t b = 0; b < n; ++b) {
    const std::size_t i = first + static_cast<std::size_t>(b);
    float r = 0.0F;
    if (!parse_finite(f[i], &r)) {
      *reason = "range " + std::to_string(b) + " (field " + std::to_string(i + 1) + ") is not a finite number: " +
                quote(f[i]);
      return false;
    }
    if (r < 0.0F) {
      *reason = "range " + std::to_string(b) + " (field " + std::to_string(i + 1) + ") is negative: " + quote(f[i]);
      return false;
    }
    scan->ranges_m[b] = r;
  }
  scan->beam_count = static_cast<std::uint32_t>(n);
  return true;
}

LogReader::Next parse_odom(const Fields& f, OdomRecord* odom, std::string* reason) {
  if (f.size() != 10) {
    *reason = "ODOM needs 10 fields, found " + std::to_string(f.size());
    return LogReader::Next::kEnd;
  }
  OdomRecord r;
  if (!parse_pose(f, 1, &r.pose, reason, "ODOM")) return LogReader::Next::kEnd;
  double accel = 0.0;
  if (!parse_finite(f[4], &r.tv_mps) || !parse_finite(f[5], &r.rv_radps) || !parse_finite(f[6], &accel)) {
    *reason = "ODOM tv/rv/accel (fields 5-7) are not finite numbers";
    return LogReader::Next::kEnd;
  }
  if (!parse_trailer(f, &r.stamp_us, &r.logger_stamp_us, reason)) return LogReader::Next::kEnd;
  *odom = r;
  return LogReader::Next::kOdom;
}

LogReader::Next parse_param(const Fields& f, ParamRecord* param, std::string* reason) {
  // CARMEN writes "PARAM name value ipc_ts host logger_ts"; the Radish logs have the older
  // "PARAM name value host logger_ts". A value may hold spaces. The ipc stamp is told
  // apart by being a decimal with a '.', as CARMEN's %f always prints one.
  if (f.size() < 3) {
    *reason = "PARAM needs a name and a value";
    return LogReader::Next::kEnd;
  }
  std::size_t value_end = f.size();
  std::int64_t ts = 0;
  if (f.size() >= 6 && f[f.size() - 3].find('.') != std::string_view::npos && parse_stamp_us(f[f.size() - 3], &ts) &&
      parse_stamp_us(f[f.size() - 1], &ts)) {
    value_end = f.size() - 3;
  } else if (f.size() >= 5 && parse_stamp_us(f[f.size() - 1], &ts)) {
    value_end = f.size() - 2;
  }
  ParamRecord r;
  r.name = std::string(f[1]);
  for (std::size_t i = 2; i < value_end; ++i) {
    if (i > 2) r.value += ' ';
    r.value += std::string(f[i]);
  }
  *param = r;
  return LogReader::Next::kParam;
}

LogReader::Next parse_flaser(const Fields& f, bool rear, const LogReaderOptions& opt, LaserRecord* laser,
                             std::string* reason) {
  if (f.size() < 2) {
    *reason = std::string(f[0]) + " has no beam count";
    return LogReader::Next::kEnd;
  }
  std::int64_t n = 0;
  if (!parse_beam_count(f, 1, &n, reason)) return LogReader::Next::kEnd;
  const std::size_t want = static_cast<std::size_t>(n) + 11U;
  if (f.size() != want) {
    *reason = field_count_reason(f[0], n, want, f.size());
    return LogReader::Next::kEnd;
  }
  RangeScan& scan = laser->scan;
  if (!parse_ranges(f, 2, n, &scan, reason)) return LogReader::Next::kEnd;
  const std::size_t p = 2U + static_cast<std::size_t>(n);
  if (!parse_pose(f, p, &laser->laser_pose, reason, "laser pose") ||
      !parse_pose(f, p + 3, &laser->odom_pose, reason, "odometry pose") ||
      !parse_trailer(f, &laser->stamp_us, &laser->logger_stamp_us, reason)) {
    return LogReader::Next::kEnd;
  }
  // Beams evenly over 180 deg from -90 deg (README "CARMEN line formats"). CARMEN's own
  // reader (src/logger/readlog.c, carmen_laser_guess_angle_increment) takes 1 deg for 180
  // beams and 0.5 deg for 360, the scanner's last beam dropped; tools/bench/laser_spacing.py
  // measures which spacing a log's scans agree with.
  scan.geometry.angle_min_rad = static_cast<float>(-kPi / 2.0);
  scan.geometry.angle_increment_rad = static_cast<float>(kPi / static_cast<double>(n - 1));
  scan.geometry.range_min_m = 0.0F;
  const float max_m = rear ? opt.rear_laser_max_m : opt.front_laser_max_m;
  scan.geometry.range_max_m = max_m > 0.0F ? max_m : opt.default_range_max_m;
  // The rear laser looks backwards from behind the axle (CARMEN robot: offset along -x).
  scan.geometry.laser_in_base =
      rear ? Pose2{-opt.rear_laser_offset_m, 0.0, kPi} : Pose2{opt.front_laser_offset_m, 0.0, 0.0};
  scan.stamp_us = laser->stamp_us;
  laser->keyword = std::string(f[0]);
  laser->has_stamp = true;
  laser->has_laser_pose = true;
  laser->has_odom_pose = true;
  laser->has_tv = false;  // FLASER/RLASER carry no velocity
  laser->tv_mps = 0.0;
  return LogReader::Next::kLaser;
}

// ROBOTLASER1 laser_type start_angle fov angular_resolution maximum_range accuracy
//   remission_mode n r1..rn m rem1..remm laser_x laser_y laser_theta robot_x robot_y
//   robot_theta tv rv forward_safety_dist side_safety_dist turn_axis ipc_ts host logger_ts
LogReader::Next parse_robotlaser(const Fields& f, LaserRecord* laser, std::string* reason) {
  if (f.size() < 9) {
    *reason = std::string(f[0]) + " is truncated before its beam count (field 9)";
    return LogReader::Next::kEnd;
  }
  float cfg[5];  // start_angle, fov, resolution, max range, accuracy
  for (std::size_t k = 0; k < 5; ++k) {
    if (!parse_finite(f[2 + k], &cfg[k])) {
      *reason = std::string(f[0]) + " laser configuration field " + std::to_string(3 + k) +
                " is not a finite number: " + quote(f[2 + k]);
      return LogReader::Next::kEnd;
    }
  }
  std::int64_t laser_type = 0;
  std::int64_t remission_mode = 0;
  if (!parse_int(f[1], &laser_type) || !parse_int(f[7], &remission_mode)) {
    *reason = std::string(f[0]) + " laser_type/remission_mode (fields 2, 8) are not integers";
    return LogReader::Next::kEnd;
  }
  if (!(cfg[3] > 0.0F)) {
    *reason = std::string(f[0]) + " maximum_range (field 6) is not positive: " + quote(f[5]);
    return LogReader::Next::kEnd;
  }
  std::int64_t n = 0;
  if (!parse_beam_count(f, 8, &n, reason)) return LogReader::Next::kEnd;
  const std::size_t m_index = 9U + static_cast<std::size_t>(n);
  if (f.size() <= m_index) {
    *reason = std::string(f[0]) + " with " + std::to_string(n) + " readings is truncated (" +
              std::to_string(f.size()) + " fields)";
    return LogReader::Next::kEnd;
  }
  std::int64_t m = 0;
  if (!parse_int(f[m_index], &m) || m < 0 || m > static_cast<std::int64_t>(capacity::kMaxBeams)) {
    *reason = std::string(f[0]) + " remission count (field " + std::to_string(m_index + 1) +
              ") is not an integer in [0, " + std::to_string(capacity::kMaxBeams) + "]: " + quote(f[m_index]);
    return LogReader::Next::kEnd;
  }
  const std::size_t want = static_cast<std::size_t>(n) + static_cast<std::size_t>(m) + 24U;
  if (f.size() != want) {
    *reason = std::string(f[0]) + " with " + std::to_string(n) + " readings and " + std::to_string(m) +
              " remissions needs " + std::to_string(want) + " fields, found " + std::to_string(f.size());
    return LogReader::Next::kEnd;
  }
  RangeScan& scan = laser->scan;
  if (!parse_ranges(f, 9, n, &scan, reason)) return LogReader::Next::kEnd;
  for (std::size_t i = m_index + 1; i < m_index + 1 + static_cast<std::size_t>(m); ++i) {
    double rem = 0.0;
    if (!parse_finite(f[i], &rem)) {
      *reason = "remission (field " + std::to_string(i + 1) + ") is not a finite number: " + quote(f[i]);
      return LogReader::Next::kEnd;
    }
  }
  const std::size_t p = m_index + 1 + static_cast<std::size_t>(m);
  if (!parse_pose(f, p, &laser->laser_pose, reason, "laser pose") ||
      !parse_pose(f, p + 3, &laser->odom_pose, reason, "robot pose")) {
    return LogReader::Next::kEnd;
  }
  for (std::size_t i = p + 6; i < p + 11; ++i) {
    double v = 0.0;
    if (!parse_finite(f[i], &v)) {
      *reason = "velocity/safety field " + std::to_string(i + 1) + " is not a finite number: " + quote(f[i]);
      return LogReader::Next::kEnd;
    }
    if (i == p + 6) laser->tv_mps = v;  // laser_tv
  }
  laser->has_tv = true;
  if (!parse_trailer(f, &laser->stamp_us, &laser->logger_stamp_us, reason)) return LogReader::Next::kEnd;
  scan.geometry.angle_min_rad = cfg[0];
  scan.geometry.angle_increment_rad = cfg[2];
  scan.geometry.range_min_m = 0.0F;
  scan.geometry.range_max_m = cfg[3];
  scan.geometry.laser_in_base = between(laser->odom_pose, laser->laser_pose);
  scan.stamp_us = laser->stamp_us;
  laser->keyword = std::string(f[0]);
  laser->has_stamp = true;
  laser->has_laser_pose = true;
  laser->has_odom_pose = true;
  return LogReader::Next::kLaser;
}

}  // namespace

LogReader::Next parse_carmen_fields(const std::vector<std::string_view>& f, const LogReaderOptions& options,
                                    LaserRecord* laser, OdomRecord* odom, ParamRecord* param, std::string* reason) {
  reason->clear();
  if (f.empty() || f[0][0] == '#') return LogReader::Next::kEnd;
  const std::string_view k = f[0];
  if (k == "ODOM") return parse_odom(f, odom, reason);
  if (k == "FLASER") return parse_flaser(f, false, options, laser, reason);
  if (k == "RLASER") return parse_flaser(f, true, options, laser, reason);
  if (k == "ROBOTLASER1" || k == "ROBOTLASER2") return parse_robotlaser(f, laser, reason);
  if (k == "PARAM") return parse_param(f, param, reason);
  if (is_ignored_type(k)) return LogReader::Next::kEnd;
  *reason = std::string(kUnknownTypePrefix) + quote(k);
  return LogReader::Next::kEnd;
}

}  // namespace detail

LogReader::Next parse_carmen_line(const std::string& line, const LogReaderOptions& options, LaserRecord* laser,
                                  OdomRecord* odom, ParamRecord* param, std::string* reason) {
  reason->clear();
  std::string_view view(line);
  while (!view.empty() && (view.back() == '\r' || view.back() == '\n')) view.remove_suffix(1);
  if (view.size() > detail::kMaxLineBytes) {
    *reason = "line longer than " + std::to_string(detail::kMaxLineBytes) + " bytes";
    return LogReader::Next::kEnd;
  }
  std::string bad = detail::check_text(view);
  if (!bad.empty()) {
    *reason = bad;
    return LogReader::Next::kEnd;
  }
  std::vector<std::string_view> fields;
  detail::split_fields(view, &fields);
  return detail::parse_carmen_fields(fields, options, laser, odom, param, reason);
}

}  // namespace sdpslam::io
