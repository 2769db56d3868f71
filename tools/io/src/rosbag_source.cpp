// ROS 1 bag reading through rosbag_storage (see rosbag_source.h).
#include "rosbag_source.h"

#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_msgs/TFMessage.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <fstream>
#include <limits>
#include <map>
#include <utility>
#include <vector>

#include "sdpslam/core/capacities.h"
#include "sdpslam/core/det_math.h"

namespace sdpslam::io::detail {
namespace {

constexpr const char* kLaserScanType = "sensor_msgs/LaserScan";
constexpr const char* kOdometryType = "nav_msgs/Odometry";
constexpr const char* kTfType = "tf2_msgs/TFMessage";

std::int64_t stamp_us(const ros::Time& t) {
  return static_cast<std::int64_t>(t.sec) * 1000000 + static_cast<std::int64_t>(t.nsec / 1000U);
}

// Heading of a rotation about z (the yaw of a unit quaternion).
double yaw_of(double x, double y, double z, double w) {
  return std::atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z));
}

Pose2 pose_of(const geometry_msgs::Transform& t) {
  return Pose2{t.translation.x, t.translation.y, yaw_of(t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w)};
}

// The frame without a leading '/' (tf2 names frames without it; tf and old bags with).
std::string frame_name(const std::string& f) { return !f.empty() && f[0] == '/' ? f.substr(1) : f; }

// Topics of `type` in the bag; the chosen one is `wanted`, else the only one, else
// `preferred` among several. Empty with *error set when none can be chosen.
std::string choose_topic(const std::vector<std::pair<std::string, std::string>>& topics, const char* type,
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
    if (required) *error = std::string("the bag has no ") + type + " topic (" + what + ")";
    return std::string();
  }
  std::string names;
  for (const std::string& n : of_type) names += (names.empty() ? "" : ", ") + n;
  *error = std::string("the bag has several ") + type + " topics (" + names + "): choose the " + what + " with " +
           option;
  return std::string();
}

struct OdomSample {
  std::int64_t stamp_us;
  Pose2 pose;
};

}  // namespace

struct RosBagSource::Impl {
  rosbag::Bag bag;
  std::unique_ptr<rosbag::View> scans;
  rosbag::View::iterator it;
  std::string scan_topic;
  std::string odom_source;  // the topic, or "/tf (odom -> base_link)"
  std::string base_frame;
  std::vector<OdomSample> odometry;  // by stamp
  // Static transforms: child frame -> (parent frame, pose of the child in the parent).
  std::map<std::string, std::pair<std::string, Pose2>> statics;
  std::map<std::string, std::pair<bool, Pose2>> mounts;  // laser frame -> (found, pose in base)
  std::uint64_t file_bytes = 0U;
  std::uint64_t scan_count = 0U;
  std::uint64_t scans_read = 0U;

  // Pose of `frame` in the base frame through the static transforms.
  std::pair<bool, Pose2> mount(const std::string& frame) {
    auto known = mounts.find(frame);
    if (known != mounts.end()) return known->second;
    Pose2 in_base;  // frame in the current ancestor
    std::string at = frame;
    bool found = at == base_frame;
    for (std::size_t hops = 0; !found && hops < statics.size(); ++hops) {
      auto up = statics.find(at);
      if (up == statics.end()) break;
      in_base = up->second.second.compose(in_base);
      at = up->second.first;
      found = at == base_frame;
    }
    const auto result = std::make_pair(found, found ? in_base : Pose2{});
    mounts[frame] = result;
    return result;
  }

  bool odometry_at(std::int64_t t_us, Pose2* out) const {
    if (odometry.empty() || t_us < odometry.front().stamp_us || t_us > odometry.back().stamp_us) return false;
    auto hi = std::lower_bound(odometry.begin(), odometry.end(), t_us,
                               [](const OdomSample& s, std::int64_t t) { return s.stamp_us < t; });
    if (hi->stamp_us == t_us) {
      *out = hi->pose;
      return true;
    }
    const OdomSample& b = *hi;
    const OdomSample& a = *(hi - 1);
    const double f = static_cast<double>(t_us - a.stamp_us) / static_cast<double>(b.stamp_us - a.stamp_us);
    const double turn = det::wrap_angle(b.pose.heading_rad - a.pose.heading_rad);
    *out = Pose2{a.pose.x_m + f * (b.pose.x_m - a.pose.x_m), a.pose.y_m + f * (b.pose.y_m - a.pose.y_m),
                 det::wrap_angle(a.pose.heading_rad + f * turn)};
    return true;
  }
};

RosBagSource::RosBagSource() : impl_(std::make_unique<Impl>()) {}
RosBagSource::~RosBagSource() = default;

bool RosBagSource::open(const std::string& path, const LogReaderOptions& options, std::string* error) {
  Impl& s = *impl_;
  try {
    s.bag.open(path, rosbag::bagmode::Read);
    {
      std::ifstream f(path, std::ios::binary | std::ios::ate);
      s.file_bytes = f ? static_cast<std::uint64_t>(f.tellg()) : 0U;
    }
    std::vector<std::pair<std::string, std::string>> topics;  // (topic, type)
    {
      rosbag::View all(s.bag);
      for (const rosbag::ConnectionInfo* c : all.getConnections()) topics.emplace_back(c->topic, c->datatype);
    }
    std::string why;
    s.scan_topic = choose_topic(topics, kLaserScanType, options.bag_scan_topic, "/scan", "scan topic",
                                "--scan-topic", true, &why);
    if (s.scan_topic.empty()) {
      *error = path + ": " + why;
      return false;
    }
    const std::string odom_topic = choose_topic(topics, kOdometryType, options.bag_odom_topic, "/odom",
                                                "odometry topic", "--odom-topic", false, &why);
    if (odom_topic.empty() && !why.empty()) {
      *error = path + ": " + why;
      return false;
    }
    s.base_frame = options.bag_base_frame;
    if (!odom_topic.empty()) {
      s.odom_source = odom_topic;
      rosbag::View v(s.bag, rosbag::TopicQuery(odom_topic));
      bool child_named = false;
      for (const rosbag::MessageInstance& m : v) {
        nav_msgs::Odometry::ConstPtr o = m.instantiate<nav_msgs::Odometry>();
        if (o == nullptr) continue;
        if (!child_named && !o->child_frame_id.empty()) {
          s.base_frame = frame_name(o->child_frame_id);
          child_named = true;
        }
        const auto& q = o->pose.pose.orientation;
        s.odometry.push_back(OdomSample{stamp_us(o->header.stamp),
                                        Pose2{o->pose.pose.position.x, o->pose.pose.position.y,
                                              yaw_of(q.x, q.y, q.z, q.w)}});
      }
    } else {
      const std::string tf_topic = choose_topic(topics, kTfType, std::string(), "/tf", "odometry", "--odom-topic",
                                                false, &why);
      if (tf_topic.empty() || tf_topic == "/tf_static") {
        *error = path + ": the bag has neither a " + kOdometryType + " topic nor " + kTfType +
                 " odometry on /tf: no odometry";
        return false;
      }
      s.odom_source = tf_topic + " (" + options.bag_odom_frame + " -> " + s.base_frame + ")";
      rosbag::View v(s.bag, rosbag::TopicQuery(tf_topic));
      for (const rosbag::MessageInstance& m : v) {
        tf2_msgs::TFMessage::ConstPtr t = m.instantiate<tf2_msgs::TFMessage>();
        if (t == nullptr) continue;
        for (const auto& x : t->transforms) {
          if (frame_name(x.header.frame_id) != options.bag_odom_frame || frame_name(x.child_frame_id) != s.base_frame) {
            continue;
          }
          s.odometry.push_back(OdomSample{stamp_us(x.header.stamp), pose_of(x.transform)});
        }
      }
    }
    std::stable_sort(s.odometry.begin(), s.odometry.end(),
                     [](const OdomSample& a, const OdomSample& b) { return a.stamp_us < b.stamp_us; });
    // Equal stamps: the last message wins (one pose per instant keeps interpolation sane).
    std::vector<OdomSample> unique;
    for (const OdomSample& o : s.odometry) {
      if (!unique.empty() && unique.back().stamp_us == o.stamp_us) unique.back() = o;
      else unique.push_back(o);
    }
    s.odometry.swap(unique);
    if (s.odometry.empty()) {
      *error = path + ": no odometry messages in " + s.odom_source;
      return false;
    }
    for (const auto& t : topics) {
      if (t.first != "/tf_static" || t.second != kTfType) continue;
      rosbag::View v(s.bag, rosbag::TopicQuery("/tf_static"));
      for (const rosbag::MessageInstance& m : v) {
        tf2_msgs::TFMessage::ConstPtr tf = m.instantiate<tf2_msgs::TFMessage>();
        if (tf == nullptr) continue;
        for (const auto& x : tf->transforms) {
          s.statics[frame_name(x.child_frame_id)] = std::make_pair(frame_name(x.header.frame_id), pose_of(x.transform));
        }
      }
      break;
    }
    s.scans = std::make_unique<rosbag::View>(s.bag, rosbag::TopicQuery(s.scan_topic));
    s.scan_count = s.scans->size();
    s.it = s.scans->begin();
  } catch (const std::exception& e) {
    *error = path + ": cannot read the ROS bag: " + e.what();
    return false;
  }
  return true;
}

RosBagSource::Got RosBagSource::next(LaserRecord* laser, std::string* reason, bool* warning, std::int64_t* index) {
  Impl& s = *impl_;
  reason->clear();
  *warning = false;
  try {
    if (s.scans == nullptr || s.it == s.scans->end()) return Got::kEnd;
    const rosbag::MessageInstance& m = *s.it;
    ++s.scans_read;
    *index = static_cast<std::int64_t>(s.scans_read);
    sensor_msgs::LaserScan::ConstPtr scan = m.instantiate<sensor_msgs::LaserScan>();
    const std::int64_t receive_us = stamp_us(m.getTime());
    ++s.it;
    if (scan == nullptr) {
      *reason = "scan message " + std::to_string(*index) + " on " + s.scan_topic + " is not a " + kLaserScanType;
      return Got::kSkipped;
    }
    if (scan->ranges.size() < 2U || scan->ranges.size() > capacity::kMaxBeams) {
      *reason = "scan message " + std::to_string(*index) + " has " + std::to_string(scan->ranges.size()) +
                " ranges (this build takes 2 .. " + std::to_string(capacity::kMaxBeams) + ")";
      return Got::kSkipped;
    }
    if (!std::isfinite(scan->angle_min) || !std::isfinite(scan->angle_increment) || !(scan->range_max > 0.0F) ||
        !std::isfinite(scan->range_max) || !std::isfinite(scan->range_min)) {
      *reason = "scan message " + std::to_string(*index) + " has a non-finite or empty geometry";
      return Got::kSkipped;
    }
    *laser = LaserRecord{};
    laser->keyword = "LaserScan";
    laser->stamp_us = stamp_us(scan->header.stamp);
    laser->logger_stamp_us = receive_us;
    laser->has_stamp = true;
    RangeScan& r = laser->scan;
    r.stamp_us = laser->stamp_us;
    r.geometry.angle_min_rad = scan->angle_min;
    r.geometry.angle_increment_rad = scan->angle_increment;
    r.geometry.range_min_m = scan->range_min;
    r.geometry.range_max_m = scan->range_max;
    r.beam_count = static_cast<std::uint32_t>(scan->ranges.size());
    for (std::uint32_t i = 0; i < r.beam_count; ++i) {
      const float v = scan->ranges[i];
      r.ranges_m[i] = std::isnan(v) || v < 0.0F ? 0.0F : (std::isinf(v) ? scan->range_max : v);
    }
    const std::string frame = frame_name(scan->header.frame_id);
    const bool first_time = s.mounts.find(frame) == s.mounts.end();
    const auto mount = s.mount(frame);
    r.geometry.laser_in_base = mount.second;
    if (!mount.first && first_time) {
      *warning = true;
      *reason = "no /tf_static chain from " + s.base_frame + " to the scan's frame '" + frame +
                "': the laser is taken to sit at the base's origin";
    }
    laser->has_odom_pose = s.odometry_at(laser->stamp_us, &laser->odom_pose);
    return Got::kLaser;
  } catch (const std::exception& e) {
    *reason = std::string("cannot read the next scan message: ") + e.what();
    if (s.scans != nullptr) s.it = s.scans->end();
    return Got::kSkipped;
  }
}

std::uint64_t RosBagSource::offset() const {
  const Impl& s = *impl_;
  if (s.scan_count == 0U) return 0U;
  return static_cast<std::uint64_t>(static_cast<double>(s.file_bytes) * static_cast<double>(s.scans_read) /
                                    static_cast<double>(s.scan_count));
}

std::string RosBagSource::description() const {
  return "scan " + impl_->scan_topic + ", odometry " + impl_->odom_source + ", base frame " + impl_->base_frame;
}

}  // namespace sdpslam::io::detail
