// ROS 2 bags (io/ros2_bag.h): written by Ros2BagWriter, read back through LogReader; the
// folder appears whole or not at all; damaged messages and ambiguous topics.
#include <CppUTest/TestHarness.h>
#include <sqlite3.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <string>

#include "sdpslam/io/log_reader.h"
#include "sdpslam/io/bags.h"
#include "shared_data.h"
#include "yaml_statics.h"  // reading a bag folder reads its metadata.yaml

using sdpslam::Pose2;
using sdpslam::io::LaserRecord;
using sdpslam::io::LogContents;
using sdpslam::io::LogFormat;
using sdpslam::io::LogReaderOptions;
using sdpslam::io::OdomRecord;
using sdpslam::io::Ros2BagWriter;

namespace {

// The bag plugin is loaded before any test runs: the ROS libraries' statics it brings
// would otherwise be blamed on the first test that opens a bag.
const bool kBagsEnabled = [] {
  sdpslam::io::enable_bag_formats();
  std::string error;
  return sdpslam::io::load_bag_plugin(&error);
}();

LaserRecord scan_at(std::int64_t stamp_us, float value, const Pose2& odom, const Pose2& mount) {
  LaserRecord r;
  r.stamp_us = stamp_us;
  r.scan.stamp_us = stamp_us;
  r.scan.geometry.angle_min_rad = -1.5F;
  r.scan.geometry.angle_increment_rad = 0.75F;
  r.scan.geometry.range_min_m = 0.1F;
  r.scan.geometry.range_max_m = 20.0F;
  r.scan.geometry.laser_in_base = mount;
  r.scan.beam_count = 5;
  for (std::uint32_t i = 0; i < 5; ++i) r.scan.ranges_m[i] = value + 0.1F * static_cast<float>(i);
  r.has_odom_pose = true;
  r.odom_pose = odom;
  return r;
}

LogContents read(const std::string& path, bool ok = true, std::string* error = nullptr,
                 const LogReaderOptions& options = LogReaderOptions{}) {
  LogContents c;
  std::string e;
  const bool opened = sdpslam::io::read_whole_log(path, options, &c, &e);
  if (ok) CHECK_TEXT(opened, e.c_str());
  else CHECK_FALSE(opened);
  if (error != nullptr) *error = e;
  return c;
}

void sql(const std::string& db_path, const char* statement) {
  sqlite3* db = nullptr;
  CHECK(sqlite3_open(db_path.c_str(), &db) == SQLITE_OK);
  char* message = nullptr;
  const int rc = sqlite3_exec(db, statement, nullptr, nullptr, &message);
  CHECK_TEXT(rc == SQLITE_OK, message != nullptr ? message : "");
  sqlite3_free(message);
  sqlite3_close(db);
}

}  // namespace

TEST_GROUP(Ros2Bag) {
  std::string dir;
  void setup() override { dir = sdpslam::test::make_temp_dir("ros2bag"); }

  // Three scans: odometry turning through pi, the laser remounted before the third.
  std::string write_three(const std::string& name) {
    const std::string bag = dir + "/" + name;
    Ros2BagWriter w;
    std::string error;
    CHECK_TEXT(w.open(bag, &error), error.c_str());
    LaserRecord no_odom = scan_at(900000, 1.0F, Pose2{}, Pose2{});
    no_odom.has_odom_pose = false;
    CHECK(w.laser(no_odom, &error));  // before any odometry: left out
    CHECK(w.laser(scan_at(1000000, 2.0F, Pose2{1.0, 2.0, 3.1}, Pose2{0.2, 0.0, 0.0}), &error));
    OdomRecord o;
    o.stamp_us = 1050000;
    o.pose = Pose2{1.5, 2.0, -3.1};
    w.odom(o);
    LaserRecord carried = scan_at(1100000, 3.0F, Pose2{}, Pose2{0.2, 0.0, 0.0});
    carried.has_odom_pose = false;  // takes the latest odometry record
    carried.scan.ranges_m[1] = std::numeric_limits<float>::infinity();
    CHECK(w.laser(carried, &error));
    CHECK(w.laser(scan_at(1200000, 4.0F, Pose2{2.0, 2.0, -3.0}, Pose2{-0.1, 0.05, 3.14159}), &error));
    LONGS_EQUAL(3, w.scans_written());
    LONGS_EQUAL(1, w.scans_without_odometry());
    CHECK_FALSE(std::filesystem::exists(bag));  // appears whole, at close
    CHECK_TEXT(w.close(&error), error.c_str());
    return bag;
  }
};

TEST(Ros2Bag, what_is_written_reads_back) {
  const std::string bag = write_three("three");
  CHECK(std::filesystem::exists(bag + "/metadata.yaml"));
  CHECK(std::filesystem::exists(bag + "/three_0.db3"));
  CHECK_FALSE(std::filesystem::exists(bag + ".partial"));
  const LogContents c = read(bag);
  CHECK(c.format == LogFormat::kRos2Bag);
  LONGS_EQUAL(0, c.error_count);
  LONGS_EQUAL(3, c.lasers.size());
  const Pose2 odoms[3] = {Pose2{1.0, 2.0, 3.1}, Pose2{1.5, 2.0, -3.1}, Pose2{2.0, 2.0, -3.0}};
  const Pose2 mounts[3] = {Pose2{0.2, 0.0, 0.0}, Pose2{0.2, 0.0, 0.0}, Pose2{-0.1, 0.05, 3.14159}};
  for (std::size_t k = 0; k < 3; ++k) {
    const LaserRecord& l = c.lasers[k];
    LONGS_EQUAL(1000000 + 100000 * static_cast<long>(k), l.stamp_us);
    LONGS_EQUAL(5, l.scan.beam_count);
    const LaserRecord expect = scan_at(l.stamp_us, 2.0F + static_cast<float>(k), Pose2{}, Pose2{});
    for (std::uint32_t i = 0; i < 5; ++i) {
      if (k == 1 && i == 1) continue;
      CHECK_EQUAL(expect.scan.ranges_m[i], l.scan.ranges_m[i]);
    }
    CHECK_EQUAL(-1.5F, l.scan.geometry.angle_min_rad);
    CHECK_EQUAL(0.75F, l.scan.geometry.angle_increment_rad);
    CHECK_EQUAL(20.0F, l.scan.geometry.range_max_m);
    CHECK_TRUE(l.has_odom_pose);
    DOUBLES_EQUAL(odoms[k].x_m, l.odom_pose.x_m, 1e-12);
    DOUBLES_EQUAL(odoms[k].y_m, l.odom_pose.y_m, 1e-12);
    DOUBLES_EQUAL(0.0, std::remainder(odoms[k].heading_rad - l.odom_pose.heading_rad, 2.0 * M_PI), 1e-12);
    DOUBLES_EQUAL(mounts[k].x_m, l.scan.geometry.laser_in_base.x_m, 1e-12);
    DOUBLES_EQUAL(mounts[k].y_m, l.scan.geometry.laser_in_base.y_m, 1e-12);
    DOUBLES_EQUAL(mounts[k].heading_rad, l.scan.geometry.laser_in_base.heading_rad, 1e-12);
  }
  CHECK(c.lasers[1].scan.classify(1) == sdpslam::RangeScan::Beam::kNoReturn);  // +inf
  // The .db3 file alone reads the same; so does a folder without its metadata.yaml.
  LONGS_EQUAL(3, read(bag + "/three_0.db3").lasers.size());
  std::filesystem::remove(bag + "/metadata.yaml");
  LONGS_EQUAL(3, read(bag).lasers.size());
}

TEST(Ros2Bag, an_existing_folder_is_refused_and_an_unclosed_bag_leaves_nothing) {
  std::string error;
  {
    Ros2BagWriter w;
    CHECK(w.open(dir + "/abandoned", &error));
    CHECK(w.laser(scan_at(1000000, 2.0F, Pose2{}, Pose2{}), &error));
  }
  CHECK_FALSE(std::filesystem::exists(dir + "/abandoned"));
  CHECK_FALSE(std::filesystem::exists(dir + "/abandoned.partial"));
  Ros2BagWriter w;
  CHECK_FALSE(w.open(dir, &error));
  CHECK_TEXT(error.find("exists already") != std::string::npos, error.c_str());
}

TEST(Ros2Bag, a_message_that_does_not_decode_is_named_and_skipped) {
  const std::string bag = write_three("damaged");
  // The second scan message cut to 20 bytes: its ranges are gone.
  sql(bag + "/damaged_0.db3",
      "UPDATE messages SET data = substr(data, 1, 20) WHERE id = "
      "(SELECT id FROM messages WHERE topic_id = 1 ORDER BY timestamp LIMIT 1 OFFSET 1)");
  const LogContents c = read(bag);
  LONGS_EQUAL(2, c.lasers.size());
  LONGS_EQUAL(1, c.error_count);
  LONGS_EQUAL(2, c.errors[0].line);
  CHECK_TEXT(c.errors[0].reason.find("does not decode") != std::string::npos, c.errors[0].reason.c_str());
}

TEST(Ros2Bag, among_several_scan_topics_scan_is_taken_else_one_must_be_chosen) {
  const std::string bag = write_three("two");
  sql(bag + "/two_0.db3",
      "INSERT INTO topics VALUES (5, '/rear_scan', 'sensor_msgs/msg/LaserScan', 'cdr', '');"
      "INSERT INTO messages (topic_id, timestamp, data) SELECT 5, timestamp, data FROM messages WHERE topic_id = 1 "
      "LIMIT 2");
  LONGS_EQUAL(3, read(bag).lasers.size());  // /scan
  LogReaderOptions o;
  o.bag_scan_topic = "/rear_scan";
  LONGS_EQUAL(2, read(bag, true, nullptr, o).lasers.size());
  sql(bag + "/two_0.db3", "UPDATE topics SET name = '/front_scan' WHERE id = 1");
  std::string error;
  read(bag, false, &error);
  CHECK_TEXT(error.find("/front_scan, /rear_scan") != std::string::npos, error.c_str());
  CHECK_TEXT(error.find("--scan-topic") != std::string::npos, error.c_str());
}
