// ROS 1 bags as logs (tools/bags/src/rosbag_source.h): bags written here with
// rosbag_storage, then read through LogReader. (The real ACES bag of ../shared is read
// against its CARMEN log in test_shared_logs.cpp.)
#include <CppUTest/TestHarness.h>

#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_msgs/TFMessage.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "sdpslam/io/bags.h"
#include "sdpslam/io/log_reader.h"
#include "shared_data.h"
#include "sdpslam/core/capacities.h"

using sdpslam::Pose2;
using sdpslam::io::LogContents;
using sdpslam::io::LogFormat;
using sdpslam::io::LogReader;
using sdpslam::io::LogReaderOptions;

namespace {

// The bag plugin is loaded before any test runs: the ROS libraries' statics it brings
// would otherwise be blamed on the first test that opens a bag.
const bool kBagsEnabled = [] {
  sdpslam::io::enable_bag_formats();
  std::string error;
  return sdpslam::io::load_bag_plugin(&error);
}();

// rosbag_storage keeps process-wide state allocated on its first use (its encryptor
// plugin loader's registries: some 500 blocks, reachable until exit, so no leak to the
// sanitizers). CppUTest's leak check would blame them on whichever test runs first: a
// bag is constructed during static initialisation, before any test.
const bool kRosbagStaticsAllocated = [] {
  rosbag::Bag warm_up;
  return true;
}();

ros::Time at(double t_s) { return ros::Time(t_s); }

geometry_msgs::Quaternion yaw_quaternion(double yaw) {
  geometry_msgs::Quaternion q;
  q.z = std::sin(0.5 * yaw);
  q.w = std::cos(0.5 * yaw);
  return q;
}

sensor_msgs::LaserScan scan_msg(double t_s, const std::string& frame, std::size_t beams, float value) {
  sensor_msgs::LaserScan s;
  s.header.stamp = at(t_s);
  s.header.frame_id = frame;
  s.angle_min = -1.5F;
  s.angle_max = 1.5F;
  s.angle_increment = 3.0F / static_cast<float>(beams - 1U);
  s.range_min = 0.1F;
  s.range_max = 20.0F;
  s.ranges.assign(beams, value);
  return s;
}

nav_msgs::Odometry odom_msg(double t_s, double x, double y, double yaw) {
  nav_msgs::Odometry o;
  o.header.stamp = at(t_s);
  o.header.frame_id = "odom";
  o.child_frame_id = "base_footprint";
  o.pose.pose.position.x = x;
  o.pose.pose.position.y = y;
  o.pose.pose.orientation = yaw_quaternion(yaw);
  return o;
}

geometry_msgs::TransformStamped transform(double t_s, const std::string& parent, const std::string& child, double x,
                                          double y, double yaw) {
  geometry_msgs::TransformStamped t;
  t.header.stamp = at(t_s);
  t.header.frame_id = parent;
  t.child_frame_id = child;
  t.transform.translation.x = x;
  t.transform.translation.y = y;
  t.transform.rotation = yaw_quaternion(yaw);
  return t;
}

LogContents read(const std::string& path, const LogReaderOptions& options = LogReaderOptions{}, bool ok = true,
                 std::string* error = nullptr) {
  LogContents c;
  std::string e;
  const bool opened = sdpslam::io::read_whole_log(path, options, &c, &e);
  if (ok) CHECK_TEXT(opened, e.c_str());
  else CHECK_FALSE(opened);
  if (error != nullptr) *error = e;
  return c;
}

}  // namespace

TEST_GROUP(RosBag) {
  std::string dir;
  void setup() override { dir = sdpslam::test::make_temp_dir("rosbag"); }
};

TEST(RosBag, odometry_topic_static_chain_and_ranges_as_rep_117_says) {
  const std::string path = dir + "/odom.bag";
  {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    tf2_msgs::TFMessage statics;
    // base_footprint -> mast -> laser: the laser 0.3 m ahead and 0.1 m left of the base,
    // turned by 0.2 rad, through two transforms.
    statics.transforms.push_back(transform(10.0, "base_footprint", "mast", 0.3, 0.0, 0.0));
    statics.transforms.push_back(transform(10.0, "/mast", "laser", 0.0, 0.1, 0.2));
    bag.write("/tf_static", at(10.0), statics);
    bag.write("/odom", at(10.0), odom_msg(10.0, 1.0, 2.0, 3.0));
    bag.write("/odom", at(10.2), odom_msg(10.2, 1.2, 2.4, -3.0));  // the turn wraps through pi
    sensor_msgs::LaserScan s = scan_msg(10.05, "laser", 5, 4.0F);
    s.ranges[1] = std::numeric_limits<float>::infinity();
    s.ranges[2] = std::numeric_limits<float>::quiet_NaN();
    s.ranges[3] = -std::numeric_limits<float>::infinity();
    bag.write("/base_scan", at(10.06), s);
    bag.write("/base_scan", at(10.2), scan_msg(10.2, "laser", 5, 3.0F));
    bag.write("/base_scan", at(10.3), scan_msg(10.3, "laser", 5, 3.0F));  // after the last odometry
  }
  LogReader reader;
  std::string error;
  CHECK_TEXT(reader.open(path, LogReaderOptions{}, &error), error.c_str());
  CHECK(reader.format() == LogFormat::kRosBag);
  STRCMP_EQUAL("scan /base_scan, odometry /odom, base frame base_footprint", reader.source_description().c_str());

  CHECK(reader.next() == LogReader::Next::kLaser);
  const auto& l = reader.laser();
  LONGS_EQUAL(10050000, l.stamp_us);
  LONGS_EQUAL(10060000, l.logger_stamp_us);
  LONGS_EQUAL(5, l.scan.beam_count);
  CHECK_EQUAL(4.0F, l.scan.ranges_m[0]);
  CHECK_EQUAL(20.0F, l.scan.ranges_m[1]);  // +inf: no return
  CHECK_EQUAL(0.0F, l.scan.ranges_m[2]);   // NaN: invalid
  CHECK_EQUAL(0.0F, l.scan.ranges_m[3]);   // -inf: invalid
  CHECK(l.scan.classify(1) == sdpslam::RangeScan::Beam::kNoReturn);
  CHECK(l.scan.classify(2) == sdpslam::RangeScan::Beam::kInvalid);
  CHECK(l.scan.classify(3) == sdpslam::RangeScan::Beam::kInvalid);
  CHECK_EQUAL(-1.5F, l.scan.geometry.angle_min_rad);
  CHECK_EQUAL(20.0F, l.scan.geometry.range_max_m);
  DOUBLES_EQUAL(0.3, l.scan.geometry.laser_in_base.x_m, 1e-12);
  DOUBLES_EQUAL(0.1, l.scan.geometry.laser_in_base.y_m, 1e-12);
  DOUBLES_EQUAL(0.2, l.scan.geometry.laser_in_base.heading_rad, 1e-12);
  // A quarter of the way from (1, 2, 3) to (1.2, 2.4, -3): the heading goes the short way
  // through pi (2*pi - 6 rad in all).
  CHECK_TRUE(l.has_odom_pose);
  DOUBLES_EQUAL(1.05, l.odom_pose.x_m, 1e-9);
  DOUBLES_EQUAL(2.1, l.odom_pose.y_m, 1e-9);
  const double expect = std::remainder(3.0 + 0.25 * (2.0 * M_PI - 6.0), 2.0 * M_PI);
  DOUBLES_EQUAL(expect, l.odom_pose.heading_rad, 1e-9);

  CHECK(reader.next() == LogReader::Next::kLaser);  // exactly at an odometry stamp
  CHECK_TRUE(reader.laser().has_odom_pose);
  DOUBLES_EQUAL(1.2, reader.laser().odom_pose.x_m, 0.0);
  DOUBLES_EQUAL(2.4, reader.laser().odom_pose.y_m, 0.0);

  CHECK(reader.next() == LogReader::Next::kLaser);  // beyond the odometry: none
  CHECK_FALSE(reader.laser().has_odom_pose);
  CHECK(reader.next() == LogReader::Next::kEnd);
  LONGS_EQUAL(0, reader.error_count());
}

TEST(RosBag, without_an_odometry_topic_the_tf_odometry_is_used) {
  const std::string path = dir + "/tf.bag";
  {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    for (int k = 0; k <= 4; ++k) {
      tf2_msgs::TFMessage tf;
      tf.transforms.push_back(transform(k * 0.1, "odom", "base_link", 0.5 * k, 0.0, 0.0));
      tf.transforms.push_back(transform(k * 0.1, "map", "odom", 100.0, 100.0, 1.0));  // not odometry
      bag.write("/tf", at(k * 0.1 + 1e-3), tf);
    }
    bag.write("/scan", at(0.25), scan_msg(0.25, "base_laser", 3, 2.0F));
  }
  const LogContents c = read(path);
  LONGS_EQUAL(1, c.lasers.size());
  CHECK_TRUE(c.lasers[0].has_odom_pose);
  DOUBLES_EQUAL(1.25, c.lasers[0].odom_pose.x_m, 1e-9);
  DOUBLES_EQUAL(0.0, c.lasers[0].odom_pose.y_m, 1e-12);
  // No /tf_static: the laser sits at the base's origin, and that is said once.
  DOUBLES_EQUAL(0.0, c.lasers[0].scan.geometry.laser_in_base.x_m, 0.0);
  LONGS_EQUAL(1, c.warning_count);
  CHECK(c.errors[0].reason.find("base_laser") != std::string::npos);
}

TEST(RosBag, topics_are_chosen_or_the_choice_is_asked_for) {
  const std::string path = dir + "/two.bag";
  {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    bag.write("/odom", at(1.0), odom_msg(1.0, 0.0, 0.0, 0.0));
    bag.write("/odom", at(2.0), odom_msg(2.0, 1.0, 0.0, 0.0));
    bag.write("/front", at(1.5), scan_msg(1.5, "base_footprint", 3, 2.0F));
    bag.write("/rear", at(1.5), scan_msg(1.5, "base_footprint", 3, 1.0F));
    bag.write("/rear", at(1.6), scan_msg(1.6, "base_footprint", 3, 1.0F));
  }
  std::string error;
  read(path, LogReaderOptions{}, false, &error);
  CHECK_TEXT(error.find("/front, /rear") != std::string::npos, error.c_str());
  CHECK_TEXT(error.find("--scan-topic") != std::string::npos, error.c_str());

  LogReaderOptions o;
  o.bag_scan_topic = "/rear";
  const LogContents c = read(path, o);
  LONGS_EQUAL(2, c.lasers.size());
  CHECK_EQUAL(1.0F, c.lasers[0].scan.ranges_m[0]);
  LONGS_EQUAL(0, c.error_count);

  o.bag_scan_topic = "/odom";
  read(path, o, false, &error);
  CHECK_TEXT(error.find("/odom is nav_msgs/Odometry") != std::string::npos, error.c_str());
  o.bag_scan_topic = "/front";
  o.bag_odom_topic = "/wheels";
  read(path, o, false, &error);
  CHECK_TEXT(error.find("no topic /wheels") != std::string::npos, error.c_str());
}

TEST(RosBag, a_scan_the_core_cannot_hold_is_skipped_and_named) {
  const std::string path = dir + "/wide.bag";
  {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    bag.write("/odom", at(1.0), odom_msg(1.0, 0.0, 0.0, 0.0));
    bag.write("/odom", at(2.0), odom_msg(2.0, 1.0, 0.0, 0.0));
    bag.write("/scan", at(1.1), scan_msg(1.1, "base_footprint", 3, 2.0F));
    bag.write("/scan", at(1.2), scan_msg(1.2, "base_footprint", sdpslam::capacity::kMaxBeams + 1U, 2.0F));
    bag.write("/scan", at(1.3), scan_msg(1.3, "base_footprint", 3, 2.0F));
  }
  const LogContents c = read(path);
  LONGS_EQUAL(2, c.lasers.size());
  LONGS_EQUAL(1, c.error_count);
  LONGS_EQUAL(2, c.errors[0].line);  // the second scan message
  CHECK_TEXT(c.errors[0].reason.find("ranges") != std::string::npos, c.errors[0].reason.c_str());
}

TEST(RosBag, a_cut_bag_is_refused_with_the_reason) {
  const std::string path = dir + "/cut.bag";
  {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    CHECK(f != nullptr);
    std::fputs("#ROSBAG V2.0\n", f);  // the magic, then nothing
    std::fclose(f);
  }
  std::string error;
  read(path, LogReaderOptions{}, false, &error);
  CHECK_TEXT(error.find("cannot read the ROS bag") != std::string::npos, error.c_str());
}
