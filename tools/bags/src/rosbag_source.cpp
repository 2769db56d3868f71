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
  BagScan scan;
};

RosBagSource::RosBagSource() : impl_(std::make_unique<Impl>()) {}
RosBagSource::~RosBagSource() = default;

bool RosBagSource::open(const std::string& path, const LogReaderOptions& options, std::string* error) {
  Impl& s = *impl_;
  try {
    s.bag.open(path, rosbag::bagmode::Read);
    {
      std::ifstream f(path, std::ios::binary | std::ios::ate);
      bag_bytes_ = f ? static_cast<std::uint64_t>(f.tellg()) : 0U;
    }
    std::vector<std::pair<std::string, std::string>> topics;  // (topic, type)
    {
      rosbag::View all(s.bag);
      for (const rosbag::ConnectionInfo* c : all.getConnections()) topics.emplace_back(c->topic, c->datatype);
    }
    std::string odom_topic;
    if (!choose_topics(topics, kLaserScanType, kOdometryType, options, path, &odom_topic, error)) return false;
    std::string why;
    if (!odom_topic.empty()) {
      odom_source_ = odom_topic;
      rosbag::View v(s.bag, rosbag::TopicQuery(odom_topic));
      bool child_named = false;
      for (const rosbag::MessageInstance& m : v) {
        nav_msgs::Odometry::ConstPtr o = m.instantiate<nav_msgs::Odometry>();
        if (o == nullptr) continue;
        if (!child_named && !o->child_frame_id.empty()) {
          assembler_.set_base_frame(o->child_frame_id);
          child_named = true;
        }
        const auto& q = o->pose.pose.orientation;
        assembler_.add_odometry(stamp_us(o->header.stamp), Pose2{o->pose.pose.position.x, o->pose.pose.position.y,
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
      odom_source_ = tf_topic + " (" + options.bag_odom_frame + " -> " + assembler_.base_frame() + ")";
      rosbag::View v(s.bag, rosbag::TopicQuery(tf_topic));
      for (const rosbag::MessageInstance& m : v) {
        tf2_msgs::TFMessage::ConstPtr t = m.instantiate<tf2_msgs::TFMessage>();
        if (t == nullptr) continue;
        for (const auto& x : t->transforms) {
          const BagTransform b = transform_of(x);
          if (frame_name(b.parent) == options.bag_odom_frame && frame_name(b.child) == assembler_.base_frame()) {
            assembler_.add_odometry(b.stamp_us, b.pose);
          }
        }
      }
    }
    if (!assembler_.finish_odometry()) {
      *error = path + ": no odometry messages in " + odom_source_;
      return false;
    }
    for (const auto& t : topics) {
      if (t.first != "/tf_static" || t.second != kTfType) continue;
      rosbag::View v(s.bag, rosbag::TopicQuery("/tf_static"));
      for (const rosbag::MessageInstance& m : v) {
        tf2_msgs::TFMessage::ConstPtr tf = m.instantiate<tf2_msgs::TFMessage>();
        if (tf == nullptr) continue;
        for (const auto& x : tf->transforms) assembler_.add_static(transform_of(x));
      }
      break;
    }
    s.scans = std::make_unique<rosbag::View>(s.bag, rosbag::TopicQuery(scan_topic_));
    scan_count_ = s.scans->size();
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
    ++scans_read_;
    *index = static_cast<std::int64_t>(scans_read_);
    sensor_msgs::LaserScan::ConstPtr msg = m.instantiate<sensor_msgs::LaserScan>();
    const std::int64_t receive_us = stamp_us(m.getTime());
    ++s.it;
    if (msg == nullptr) {
      *reason = "scan message " + std::to_string(*index) + " on " + scan_topic_ + " is not a " + kLaserScanType;
      return Got::kSkipped;
    }
    s.scan.stamp_us = stamp_us(msg->header.stamp);
    s.scan.frame = msg->header.frame_id;
    s.scan.angle_min = msg->angle_min;
    s.scan.angle_increment = msg->angle_increment;
    s.scan.range_min = msg->range_min;
    s.scan.range_max = msg->range_max;
    s.scan.ranges = msg->ranges;
    if (!assembler_.to_record(s.scan, receive_us, laser, reason, warning)) {
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

}  // namespace sdpslam::io::detail
