// The real logs in ../shared/datasets: record counts from its README, exact stamps,
// a plausible tinySLAM odometry path, and the reader's throughput on intel.clf; and the
// ROS 1 bag made from aces.clf (../shared/testdata/bags), read as that log; and aces.clf
// written as a ROS 2 bag and read back.
#include <CppUTest/TestHarness.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

#include "shared_data.h"
#include "sdpslam/io/log_reader.h"
#include "sdpslam/io/bags.h"
#include "yaml_statics.h"  // reading a ROS 2 bag folder reads its metadata.yaml

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

LogContents read_shared(const std::string& name) {
  LogContents c;
  std::string error;
  CHECK_TEXT(sdpslam::io::read_whole_log(sdpslam::test::shared_path(name), LogReaderOptions{}, &c, &error),
             error.c_str());
  for (const auto& e : c.errors) std::fprintf(stderr, "%s\n", e.to_string().c_str());
  return c;
}

bool all_have_beams(const LogContents& c, std::uint32_t n) {
  return std::all_of(c.lasers.begin(), c.lasers.end(), [n](const auto& l) { return l.scan.beam_count == n; });
}
}  // namespace

TEST_GROUP(SharedLogs){};

TEST(SharedLogs, intel_has_the_readme_counts_and_no_errors) {
  const LogContents c = read_shared("datasets/intel.clf");
  CHECK(c.format == LogFormat::kCarmen);
  CHECK_EQUAL(0U, c.error_count);
  CHECK_EQUAL(26915U, c.odoms.size());
  CHECK_EQUAL(13631U, c.lasers.size());
  CHECK(all_have_beams(c, 180));
  // First FLASER line of the file: "... 976052857.337530 nohost 0.000246".
  CHECK_EQUAL(976052857337530LL, c.lasers.front().stamp_us);
  CHECK_EQUAL(246LL, c.lasers.front().logger_stamp_us);
  CHECK_EQUAL(1.07F, c.lasers.front().scan.ranges_m[0]);
  // The raw log's ipc stamps step back now and then (by up to ~0.6 s); the README's
  // 2691 s span is what holds.
  const double span_s = static_cast<double>(c.lasers.back().stamp_us - c.lasers.front().stamp_us) * 1e-6;
  CHECK(span_s > 2680.0 && span_s < 2700.0);
}

TEST(SharedLogs, aces_has_the_readme_counts_and_no_errors) {
  const LogContents c = read_shared("datasets/aces.clf");
  CHECK_EQUAL(0U, c.error_count);
  CHECK_EQUAL(7375U, c.odoms.size());
  CHECK_EQUAL(7374U, c.lasers.size());
  CHECK(all_have_beams(c, 180));
  CHECK_EQUAL(4U, c.params.size());
}

TEST(SharedLogs, tinyslam_exp2_has_one_scan_per_line_and_a_plausible_indoor_path) {
  const LogContents c = read_shared("datasets/tinyslam-exp2.dat");
  CHECK(c.format == LogFormat::kTinySlam);
  CHECK_EQUAL(0U, c.error_count);
  CHECK_EQUAL(641U, c.lasers.size());
  CHECK(all_have_beams(c, 682));
  double dist_m = 0.0;
  double min_x = 0.0, max_x = 0.0, min_y = 0.0, max_y = 0.0;
  for (std::size_t i = 1; i < c.lasers.size(); ++i) {
    const auto& a = c.lasers[i - 1].odom_pose;
    const auto& b = c.lasers[i].odom_pose;
    dist_m += std::hypot(b.x_m - a.x_m, b.y_m - a.y_m);
    min_x = std::min(min_x, b.x_m);
    max_x = std::max(max_x, b.x_m);
    min_y = std::min(min_y, b.y_m);
    max_y = std::max(max_y, b.y_m);
  }
  const double duration_s = static_cast<double>(c.lasers.back().stamp_us - c.lasers.front().stamp_us) * 1e-6;
  std::fprintf(stderr, "tinyslam-exp2: %zu scans, %.1f s, odometry path %.2f m, bbox x [%.2f, %.2f] y [%.2f, %.2f] m\n",
               c.lasers.size(), duration_s, dist_m, min_x, max_x, min_y, max_y);
  // A small indoor robot: tens of metres in about a minute, inside a building-sized box.
  CHECK(dist_m > 5.0 && dist_m < 100.0);
  CHECK(max_x - min_x < 50.0 && max_y - min_y < 50.0);
}

TEST(SharedLogs, dpslam_loop5_has_551_scans_of_181_beams) {
  const LogContents c = read_shared("datasets/dpslam-loop5.log");
  CHECK(c.format == LogFormat::kDpSlam);
  CHECK_EQUAL(0U, c.error_count);
  CHECK_EQUAL(551U, c.lasers.size());
  CHECK(all_have_beams(c, 181));
  CHECK(std::all_of(c.lasers.begin(), c.lasers.end(), [](const auto& l) { return l.has_odom_pose && !l.has_stamp; }));
  CHECK_EQUAL(550LL * 100000LL, c.lasers.back().stamp_us);
}

TEST(SharedLogs, intel_streaming_read_throughput) {
  const std::string path = sdpslam::test::shared_path("datasets/intel.clf");
  LogReader r;
  std::string error;
  const auto t0 = std::chrono::steady_clock::now();
  CHECK_TEXT(r.open(path, LogReaderOptions{}, &error), error.c_str());
  std::size_t records = 0;
  while (r.next() != LogReader::Next::kEnd) ++records;
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double mb = static_cast<double>(r.input_offset()) / 1e6;
  std::fprintf(stderr, "intel.clf: %lld lines, %zu records, %.1f MB in %.3f s: %.0f lines/s, %.1f MB/s\n",
               static_cast<long long>(r.lines_read()), records, mb, s, static_cast<double>(r.lines_read()) / s, mb / s);
  CHECK_EQUAL(40557LL, r.lines_read());
}

// ../shared/testdata/bags/aces.clf2bag.bag was made from ../shared/datasets/aces.clf
// (its README): scan i of the bag is FLASER line i of the log, stamped 1e9 s + i x 0.1 s.
#if SDPSLAM_TEST_ROSBAG
namespace {
// rosbag_storage allocates process-wide state on its first use (see test_rosbag.cpp): the
// bag is opened once during static initialisation, before any test.
const bool kRosbagStaticsAllocated = [] {
  const std::string bag = sdpslam::test::find_shared("testdata/bags/aces.clf2bag.bag");
  if (!bag.empty()) {
    LogReader reader;
    std::string error;
    (void)reader.open(bag, LogReaderOptions{}, &error);
  }
  return true;
}();
}  // namespace

TEST(SharedLogs, the_aces_bag_reads_as_the_aces_log_scan_by_scan) {
  const LogContents bag = read_shared("testdata/bags/aces.clf2bag.bag");
  const LogContents clf = read_shared("datasets/aces.clf");
  CHECK(bag.format == LogFormat::kRosBag);
  LONGS_EQUAL(0, bag.error_count);
  LONGS_EQUAL(7374, bag.lasers.size());
  LONGS_EQUAL(clf.lasers.size(), bag.lasers.size());
  for (std::size_t i = 0; i < bag.lasers.size(); ++i) {
    const auto& b = bag.lasers[i];
    const auto& c = clf.lasers[i];
    LONGS_EQUAL(1000000000000000LL + static_cast<long long>(i) * 100000LL, b.stamp_us);
    LONGS_EQUAL(c.scan.beam_count, b.scan.beam_count);
    // The ranges are the log's, bit for bit; the geometry the same to float precision.
    CHECK(std::memcmp(c.scan.ranges_m, b.scan.ranges_m, sizeof(float) * c.scan.beam_count) == 0);
    DOUBLES_EQUAL(c.scan.geometry.angle_min_rad, b.scan.geometry.angle_min_rad, 1e-6);
    DOUBLES_EQUAL(c.scan.geometry.angle_increment_rad, b.scan.geometry.angle_increment_rad, 1e-7);
    CHECK_EQUAL(c.scan.geometry.range_max_m, b.scan.geometry.range_max_m);
    CHECK_TRUE(b.has_odom_pose);
    // The odometry as the log wrote it, through a quaternion (heading to ~1e-15 rad).
    DOUBLES_EQUAL(c.odom_pose.x_m, b.odom_pose.x_m, 1e-12);
    DOUBLES_EQUAL(c.odom_pose.y_m, b.odom_pose.y_m, 1e-12);
    DOUBLES_EQUAL(0.0, std::remainder(c.odom_pose.heading_rad - b.odom_pose.heading_rad, 2.0 * M_PI), 1e-12);
    DOUBLES_EQUAL(0.0, b.scan.geometry.laser_in_base.x_m, 0.0);
    DOUBLES_EQUAL(0.0, b.scan.geometry.laser_in_base.heading_rad, 0.0);
  }
}
#else
// A build without ROS bag support recognises the bag and says what it lacks.
TEST(SharedLogs, the_aces_bag_is_refused_with_what_to_install) {
  LogContents c;
  std::string error;
  CHECK_FALSE(sdpslam::io::read_whole_log(sdpslam::test::shared_path("testdata/bags/aces.clf2bag.bag"),
                                          LogReaderOptions{}, &c, &error));
  CHECK_TEXT(error.find("without ROS bag support") != std::string::npos, error.c_str());
  CHECK_TEXT(error.find("librosbag-storage-dev") != std::string::npos, error.c_str());
}
#endif

#if SDPSLAM_TEST_ROS2BAG
TEST(SharedLogs, aces_written_as_a_ros2_bag_reads_back_as_the_log) {
  const std::string dir = sdpslam::test::make_temp_dir("aces-ros2");
  const LogContents clf = read_shared("datasets/aces.clf");
  {
    sdpslam::io::Ros2BagWriter w;
    std::string error;
    CHECK_TEXT(w.open(dir + "/aces", &error), error.c_str());
    for (const auto& l : clf.lasers) CHECK_TEXT(w.laser(l, &error), error.c_str());
    CHECK_TEXT(w.close(&error), error.c_str());
  }
  LogContents bag;
  std::string error;
  CHECK_TEXT(sdpslam::io::read_whole_log(dir + "/aces", LogReaderOptions{}, &bag, &error), error.c_str());
  CHECK(bag.format == LogFormat::kRos2Bag);
  LONGS_EQUAL(0, bag.error_count);
  LONGS_EQUAL(clf.lasers.size(), bag.lasers.size());
  for (std::size_t i = 0; i < bag.lasers.size(); ++i) {
    const auto& b = bag.lasers[i];
    const auto& c = clf.lasers[i];
    LONGS_EQUAL(c.stamp_us, b.stamp_us);
    LONGS_EQUAL(c.scan.beam_count, b.scan.beam_count);
    CHECK(std::memcmp(c.scan.ranges_m, b.scan.ranges_m, sizeof(float) * c.scan.beam_count) == 0);
    CHECK(std::memcmp(&c.scan.geometry, &b.scan.geometry, sizeof c.scan.geometry) == 0);
    CHECK_TRUE(b.has_odom_pose);
    DOUBLES_EQUAL(c.odom_pose.x_m, b.odom_pose.x_m, 0.0);
    DOUBLES_EQUAL(c.odom_pose.y_m, b.odom_pose.y_m, 0.0);
    DOUBLES_EQUAL(0.0, std::remainder(c.odom_pose.heading_rad - b.odom_pose.heading_rad, 2.0 * M_PI), 1e-15);
  }
}
#endif
