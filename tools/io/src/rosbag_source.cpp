// ROS 1 bag reading through rosbag_storage (see rosbag_source.h).
#include "rosbag_source.h"

#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_msgs/TFMessage.h>

#include <exception>
#include <fstream>
#include <utility>
#include <vector>

#include "bag_common.h"

namespace sdpslam::io::detail {
namespace {

constexpr const char* kLaserScanType = "sensor_msgs/LaserScan";
constexpr const char* kOdometryType = "nav_msgs/Odometry";
constexpr const char* kTfType = "tf2_msgs/TFMessage";

std::int64_t stamp_us(const ros::Time& t) { return stamp_us_of(t.sec, t.nsec); }

BagTransform transform_of(const geometry_msgs::TransformStamped& x) {
  const auto& q = x.transform.rotation;
  return BagTransform{stamp_us(x.header.stamp), x.header.frame_id, x.child_frame_id,
                      Pose2{x.transform.translation.x, x.transform.translation.y, yaw_of(q.x, q.y, q.z, q.w)}};
}

}  // namespace

struct RosBagSource::Impl {
  rosbag::Bag bag;
  std::unique_ptr<rosbag::View> scans;
  rosbag::View::iterator it;
  std::string scan_topic;
  std::string odom_source;  // the topic, or "/tf (odom -> base_link)"
  BagAssembler assembler;
  BagScan scan;
  std::uint64_t file_bytes = 0U;
  std::uint64_t scan_count = 0U;
  std::uint64_t scans_read = 0U;
};

bool ros1_bags_supported_here() { return true; }

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
    s.assembler.set_base_frame(options.bag_base_frame);
    if (!odom_topic.empty()) {
      s.odom_source = odom_topic;
      rosbag::View v(s.bag, rosbag::TopicQuery(odom_topic));
      bool child_named = false;
      for (const rosbag::MessageInstance& m : v) {
        nav_msgs::Odometry::ConstPtr o = m.instantiate<nav_msgs::Odometry>();
        if (o == nullptr) continue;
        if (!child_named && !o->child_frame_id.empty()) {
          s.assembler.set_base_frame(o->child_frame_id);
          child_named = true;
        }
        const auto& q = o->pose.pose.orientation;
        s.assembler.add_odometry(stamp_us(o->header.stamp), Pose2{o->pose.pose.position.x, o->pose.pose.position.y,
                                                                 yaw_of(q.x, q.y, q.z, q.w)});
      }
    } else {
      const std::string tf_topic = choose_topic(topics, kTfType, std::string(), "/tf", "odometry", "--odom-topic",
                                                false, &why);
      if (tf_topic.empty() || tf_topic == "/tf_static") {
        *error = path + ": the bag has neither a " + kOdometryType + " topic nor " + kTfType +
                 " odometry on /tf: no odometry";
        return false;
      }
      s.odom_source = tf_topic + " (" + options.bag_odom_frame + " -> " + s.assembler.base_frame() + ")";
      rosbag::View v(s.bag, rosbag::TopicQuery(tf_topic));
      for (const rosbag::MessageInstance& m : v) {
        tf2_msgs::TFMessage::ConstPtr t = m.instantiate<tf2_msgs::TFMessage>();
        if (t == nullptr) continue;
        for (const auto& x : t->transforms) {
          const BagTransform b = transform_of(x);
          if (frame_name(b.parent) == options.bag_odom_frame && frame_name(b.child) == s.assembler.base_frame()) {
            s.assembler.add_odometry(b.stamp_us, b.pose);
          }
        }
      }
    }
    if (!s.assembler.finish_odometry()) {
      *error = path + ": no odometry messages in " + s.odom_source;
      return false;
    }
    for (const auto& t : topics) {
      if (t.first != "/tf_static" || t.second != kTfType) continue;
      rosbag::View v(s.bag, rosbag::TopicQuery("/tf_static"));
      for (const rosbag::MessageInstance& m : v) {
        tf2_msgs::TFMessage::ConstPtr tf = m.instantiate<tf2_msgs::TFMessage>();
        if (tf == nullptr) continue;
        for (const auto& x : tf->transforms) s.assembler.add_static(transform_of(x));
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
    sensor_msgs::LaserScan::ConstPtr msg = m.instantiate<sensor_msgs::LaserScan>();
    const std::int64_t receive_us = stamp_us(m.getTime());
    ++s.it;
    if (msg == nullptr) {
      *reason = "scan message " + std::to_string(*index) + " on " + s.scan_topic + " is not a " + kLaserScanType;
      return Got::kSkipped;
    }
    s.scan.stamp_us = stamp_us(msg->header.stamp);
    s.scan.frame = msg->header.frame_id;
    s.scan.angle_min = msg->angle_min;
    s.scan.angle_increment = msg->angle_increment;
    s.scan.range_min = msg->range_min;
    s.scan.range_max = msg->range_max;
    s.scan.ranges = msg->ranges;
    if (!s.assembler.to_record(s.scan, receive_us, laser, reason, warning)) {
      *reason = "scan message " + std::to_string(*index) + ": " + *reason;
      return Got::kSkipped;
    }
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
  return "scan " + impl_->scan_topic + ", odometry " + impl_->odom_source + ", base frame " +
         impl_->assembler.base_frame();
}

}  // namespace sdpslam::io::detail
