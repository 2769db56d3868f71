#include "bag_common.h"

#include <algorithm>
#include <cmath>

#include "sdpslam/core/capacities.h"
#include "sdpslam/core/det_math.h"

namespace sdpslam::io::detail {

std::int64_t stamp_us_of(std::int64_t sec, std::uint32_t nanosec) {
  return sec * 1000000 + static_cast<std::int64_t>(nanosec / 1000U);
}

double yaw_of(double x, double y, double z, double w) {
  // A rotation about z alone (a planar robot's): twice the half angle, which a written
  // heading survives bit for bit (ros2_bag.cpp picks its quaternion so).
  if (x == 0.0 && y == 0.0) return det::wrap_angle(2.0 * std::atan2(z, w));
  return std::atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z));
}

std::string frame_name(const std::string& f) { return !f.empty() && f[0] == '/' ? f.substr(1) : f; }

std::string choose_topic(const std::vector<std::pair<std::string, std::string>>& topics, const std::string& type,
                         const std::string& wanted, const std::string& preferred, const char* what,
                         const char* option, bool required, std::string* error) {
  std::vector<std::string> of_type;
  for (const auto& t : topics) {
    if (t.second == type && std::find(of_type.begin(), of_type.end(), t.first) == of_type.end()) {
      of_type.push_back(t.first);
    }
  }
  if (!wanted.empty()) {
    for (const auto& t : topics) {
      if (t.first != wanted) continue;
      if (t.second == type) return wanted;
      *error = "topic " + wanted + " is " + t.second + ", not " + type;
      return std::string();
    }
    *error = "the bag has no topic " + wanted;
    return std::string();
  }
  if (of_type.size() == 1U) return of_type[0];
  if (std::find(of_type.begin(), of_type.end(), preferred) != of_type.end()) return preferred;
  if (of_type.empty()) {
    if (required) *error = "the bag has no " + type + " topic (" + what + ")";
    return std::string();
  }
  std::string names;
  for (const std::string& n : of_type) names += (names.empty() ? "" : ", ") + n;
  *error = "the bag has several " + type + " topics (" + names + "): choose the " + what + " with " + option;
  return std::string();
}

bool BagSource::choose_topics(const std::vector<std::pair<std::string, std::string>>& topics, const char* scan_type,
                              const char* odom_type, const LogReaderOptions& options, const std::string& path,
                              std::string* odom_topic, std::string* error) {
  std::string why;
  scan_topic_ =
      choose_topic(topics, scan_type, options.bag_scan_topic, "/scan", "scan topic", "--scan-topic", true, &why);
  if (scan_topic_.empty()) {
    *error = path + ": " + why;
    return false;
  }
  *odom_topic = choose_topic(topics, odom_type, options.bag_odom_topic, "/odom", "odometry topic", "--odom-topic",
                             false, &why);
  if (odom_topic->empty() && !why.empty()) {
    *error = path + ": " + why;
    return false;
  }
  assembler_.set_base_frame(options.bag_base_frame);
  return true;
}

std::uint64_t BagSource::offset() const {
  if (scan_count_ == 0U) return 0U;
  return static_cast<std::uint64_t>(static_cast<double>(bag_bytes_) * static_cast<double>(scans_read_) /
                                    static_cast<double>(scan_count_));
}

std::string BagSource::description() const {
  return scan_topic_.empty() ? std::string()
                             : "scan " + scan_topic_ + ", odometry " + odom_source_ + ", base frame " +
                                   assembler_.base_frame();
}

bool BagAssembler::finish_odometry() {
  std::stable_sort(odometry_.begin(), odometry_.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<std::pair<std::int64_t, Pose2>> unique;
  for (const auto& o : odometry_) {
    if (!unique.empty() && unique.back().first == o.first) unique.back() = o;
    else unique.push_back(o);
  }
  odometry_.swap(unique);
  return !odometry_.empty();
}

bool BagAssembler::odometry_at(std::int64_t t_us, Pose2* out) const {
  if (odometry_.empty() || t_us < odometry_.front().first || t_us > odometry_.back().first) return false;
  auto hi = std::lower_bound(odometry_.begin(), odometry_.end(), t_us,
                             [](const auto& s, std::int64_t t) { return s.first < t; });
  if (hi->first == t_us) {
    *out = hi->second;
    return true;
  }
  const auto& b = *hi;
  const auto& a = *(hi - 1);
  const double f = static_cast<double>(t_us - a.first) / static_cast<double>(b.first - a.first);
  const double turn = det::wrap_angle(b.second.heading_rad - a.second.heading_rad);
  *out = Pose2{a.second.x_m + f * (b.second.x_m - a.second.x_m), a.second.y_m + f * (b.second.y_m - a.second.y_m),
               det::wrap_angle(a.second.heading_rad + f * turn)};
  return true;
}

std::pair<bool, Pose2> BagAssembler::mount(const std::string& frame) {
  auto known = mounts_.find(frame);
  if (known != mounts_.end()) return known->second;
  Pose2 in_base;  // the frame in its current ancestor
  std::string at = frame;
  bool found = at == base_frame_;
  for (std::size_t hops = 0; !found && hops < statics_.size(); ++hops) {
    auto up = statics_.find(at);
    if (up == statics_.end()) break;
    in_base = up->second.second.compose(in_base);
    at = up->second.first;
    found = at == base_frame_;
  }
  const auto result = std::make_pair(found, found ? in_base : Pose2{});
  mounts_[frame] = result;
  return result;
}

bool BagAssembler::to_record(const BagScan& scan, std::int64_t receive_us, LaserRecord* out, std::string* reason,
                             bool* warning) {
  reason->clear();
  *warning = false;
  if (scan.ranges.size() < 2U || scan.ranges.size() > capacity::kMaxBeams) {
    *reason = "a scan of " + std::to_string(scan.ranges.size()) + " ranges (this build takes 2 .. " +
              std::to_string(capacity::kMaxBeams) + ")";
    return false;
  }
  if (!std::isfinite(scan.angle_min) || !std::isfinite(scan.angle_increment) || !std::isfinite(scan.range_min) ||
      !std::isfinite(scan.range_max) || !(scan.range_max > 0.0F)) {
    *reason = "a scan with a non-finite or empty geometry";
    return false;
  }
  *out = LaserRecord{};
  out->keyword = "LaserScan";
  out->stamp_us = scan.stamp_us;
  out->logger_stamp_us = receive_us;
  out->has_stamp = true;
  RangeScan& r = out->scan;
  r.stamp_us = scan.stamp_us;
  r.geometry.angle_min_rad = scan.angle_min;
  r.geometry.angle_increment_rad = scan.angle_increment;
  r.geometry.range_min_m = scan.range_min;
  r.geometry.range_max_m = scan.range_max;
  r.beam_count = static_cast<std::uint32_t>(scan.ranges.size());
  for (std::uint32_t i = 0; i < r.beam_count; ++i) {
    const float v = scan.ranges[i];
    r.ranges_m[i] = std::isnan(v) || v < 0.0F ? 0.0F : (std::isinf(v) ? scan.range_max : v);
  }
  const std::string frame = frame_name(scan.frame);
  const bool first_time = mounts_.find(frame) == mounts_.end();
  const auto m = mount(frame);
  r.geometry.laser_in_base = m.second;
  if (!m.first && first_time) {
    *warning = true;
    *reason = "no /tf_static chain from " + base_frame_ + " to the scan's frame '" + frame +
              "': the laser is taken to sit at the base's origin";
  }
  out->has_odom_pose = odometry_at(out->stamp_us, &out->odom_pose);
  return true;
}

}  // namespace sdpslam::io::detail
