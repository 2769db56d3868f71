// CarmenWriter: round trips through LogReader, FLASER vs ROBOTLASER1, atomic output.
#include <CppUTest/TestHarness.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <string>

#include "log_test_util.h"
#include "sdpslam/io/carmen_writer.h"
#include "sdpslam/io/log_reader.h"

using sdpslam::Pose2;
using sdpslam::io::CarmenWriter;
using sdpslam::io::LaserRecord;
using sdpslam::io::LogContents;
using sdpslam::io::LogReaderOptions;
using sdpslam::io::OdomRecord;
using sdpslam::test::ScratchDir;

namespace {
constexpr double kPi = 3.14159265358979323846;

LaserRecord flaser_like(int n, std::int64_t stamp_us) {
  LaserRecord r;
  r.keyword = "FLASER";
  r.stamp_us = stamp_us;
  r.logger_stamp_us = stamp_us + 17;
  r.scan.stamp_us = stamp_us;
  r.scan.beam_count = static_cast<std::uint32_t>(n);
  r.scan.geometry.angle_min_rad = static_cast<float>(-kPi / 2);
  r.scan.geometry.angle_increment_rad = static_cast<float>(kPi / (n - 1));
  r.scan.geometry.range_max_m = 50.0F;
  for (int i = 0; i < n; ++i) r.scan.ranges_m[i] = 0.001F * static_cast<float>(i * 37 % 9000) + 0.0004F * static_cast<float>(i % 3);
  r.odom_pose = Pose2{12.345678901234, -0.1, 3.0};
  r.laser_pose = r.odom_pose;
  r.has_odom_pose = true;
  r.has_laser_pose = true;
  return r;
}

LogContents write_and_read(const ScratchDir& dir, const LaserRecord& laser, const OdomRecord* odom = nullptr) {
  const std::string path = dir.path() + "/out.clf";
  CarmenWriter w;
  std::string error;
  CHECK_TEXT(w.open(path, &error), error.c_str());
  w.comment("round trip\nsecond line");
  w.param("robot_name", "test robot");
  if (odom != nullptr) w.odom(*odom);
  w.laser(laser);
  CHECK_TEXT(w.close(&error), error.c_str());
  LogContents c;
  CHECK_TEXT(sdpslam::io::read_whole_log(path, LogReaderOptions{}, &c, &error), error.c_str());
  CHECK_EQUAL(0U, c.error_count);
  return c;
}

void check_same_ranges(const LaserRecord& a, const LaserRecord& b) {
  CHECK_EQUAL(a.scan.beam_count, b.scan.beam_count);
  for (std::uint32_t i = 0; i < a.scan.beam_count; ++i) {
    CHECK_EQUAL(a.scan.ranges_m[i], b.scan.ranges_m[i]);  // bit-exact, not just to the mm
  }
}
}  // namespace

TEST_GROUP(CarmenWriter){};

TEST(CarmenWriter, flaser_odom_and_param_round_trip_exactly) {
  ScratchDir dir("io-wr-flaser");
  const LaserRecord in = flaser_like(180, 976052857337530LL);
  OdomRecord od;
  od.stamp_us = 976052857337916LL;
  od.logger_stamp_us = 632;
  od.pose = Pose2{1.0 / 3.0, -2.5, 0.1};
  od.tv_mps = 0.25;
  od.rv_radps = -0.125;
  const LogContents c = write_and_read(dir, in, &od);
  CHECK_EQUAL(1U, c.params.size());
  STRCMP_EQUAL("test robot", c.params[0].value.c_str());
  CHECK_EQUAL(1U, c.odoms.size());
  CHECK_EQUAL(od.stamp_us, c.odoms[0].stamp_us);
  CHECK_EQUAL(od.logger_stamp_us, c.odoms[0].logger_stamp_us);
  DOUBLES_EQUAL(od.pose.x_m, c.odoms[0].pose.x_m, 0.0);
  DOUBLES_EQUAL(od.pose.heading_rad, c.odoms[0].pose.heading_rad, 0.0);
  DOUBLES_EQUAL(od.tv_mps, c.odoms[0].tv_mps, 0.0);
  DOUBLES_EQUAL(od.rv_radps, c.odoms[0].rv_radps, 0.0);
  CHECK_EQUAL(1U, c.lasers.size());
  const LaserRecord& out = c.lasers[0];
  STRCMP_EQUAL("FLASER", out.keyword.c_str());
  CHECK_EQUAL(in.stamp_us, out.stamp_us);
  CHECK_EQUAL(in.logger_stamp_us, out.logger_stamp_us);
  check_same_ranges(in, out);
  CHECK_EQUAL(in.scan.geometry.angle_min_rad, out.scan.geometry.angle_min_rad);
  CHECK_EQUAL(in.scan.geometry.angle_increment_rad, out.scan.geometry.angle_increment_rad);
  CHECK_EQUAL(in.scan.geometry.range_max_m, out.scan.geometry.range_max_m);
  DOUBLES_EQUAL(in.odom_pose.x_m, out.odom_pose.x_m, 0.0);
  DOUBLES_EQUAL(in.odom_pose.y_m, out.odom_pose.y_m, 0.0);
  DOUBLES_EQUAL(in.laser_pose.heading_rad, out.laser_pose.heading_rad, 0.0);
}

TEST(CarmenWriter, other_geometry_is_written_as_robotlaser1_and_round_trips) {
  ScratchDir dir("io-wr-robot");
  LaserRecord in = flaser_like(682, 361431443LL);
  in.keyword = "tinyslam";
  in.scan.geometry.angle_min_rad = static_cast<float>(-340.0 * 2 * kPi / 1024);
  in.scan.geometry.angle_increment_rad = static_cast<float>(2 * kPi / 1024);
  in.scan.geometry.range_max_m = 5.6F;
  in.scan.geometry.laser_in_base = Pose2{0.145, 0.0, 0.0};
  in.has_laser_pose = false;
  in.odom_pose = Pose2{0.5, 0.25, -1.0};
  const LogContents c = write_and_read(dir, in);
  CHECK_EQUAL(1U, c.lasers.size());
  const LaserRecord& out = c.lasers[0];
  STRCMP_EQUAL("ROBOTLASER1", out.keyword.c_str());
  check_same_ranges(in, out);
  CHECK_EQUAL(in.scan.geometry.angle_min_rad, out.scan.geometry.angle_min_rad);
  CHECK_EQUAL(in.scan.geometry.angle_increment_rad, out.scan.geometry.angle_increment_rad);
  CHECK_EQUAL(5.6F, out.scan.geometry.range_max_m);
  DOUBLES_EQUAL(0.145, out.scan.geometry.laser_in_base.x_m, 1e-12);
  DOUBLES_EQUAL(0.0, out.scan.geometry.laser_in_base.y_m, 1e-12);
  DOUBLES_EQUAL(0.0, out.scan.geometry.laser_in_base.heading_rad, 1e-12);
  DOUBLES_EQUAL(0.5, out.odom_pose.x_m, 0.0);
  DOUBLES_EQUAL(-1.0, out.odom_pose.heading_rad, 0.0);
  CHECK_EQUAL(361431443LL, out.stamp_us);
}

TEST(CarmenWriter, flaser_with_a_mounting_offset_becomes_robotlaser1) {
  ScratchDir dir("io-wr-offset");
  LaserRecord in = flaser_like(180, 5);
  in.scan.geometry.laser_in_base = Pose2{0.2, 0.0, 0.0};
  in.has_laser_pose = false;
  const LogContents c = write_and_read(dir, in);
  STRCMP_EQUAL("ROBOTLASER1", c.lasers[0].keyword.c_str());
  DOUBLES_EQUAL(0.2, c.lasers[0].scan.geometry.laser_in_base.x_m, 1e-12);
}

TEST(CarmenWriter, invalid_and_infinite_ranges_keep_their_meaning) {
  ScratchDir dir("io-wr-nan");
  LaserRecord in = flaser_like(180, 5);
  in.scan.ranges_m[0] = std::numeric_limits<float>::quiet_NaN();
  in.scan.ranges_m[1] = -1.0F;
  in.scan.ranges_m[2] = std::numeric_limits<float>::infinity();
  const LogContents c = write_and_read(dir, in);
  const sdpslam::RangeScan& s = c.lasers[0].scan;
  CHECK(s.classify(0) == sdpslam::RangeScan::Beam::kInvalid);
  CHECK(s.classify(1) == sdpslam::RangeScan::Beam::kInvalid);
  CHECK(s.classify(2) == sdpslam::RangeScan::Beam::kNoReturn);
}

TEST(CarmenWriter, negative_and_large_stamps_round_trip) {
  ScratchDir dir("io-wr-stamps");
  LaserRecord in = flaser_like(180, -1500001LL);
  in.logger_stamp_us = 999999999999999LL;
  const LogContents c = write_and_read(dir, in);
  CHECK_EQUAL(-1500001LL, c.lasers[0].stamp_us);
  CHECK_EQUAL(999999999999999LL, c.lasers[0].logger_stamp_us);
}

TEST(CarmenWriter, nothing_appears_at_the_target_before_close) {
  ScratchDir dir("io-wr-atomic");
  const std::string path = dir.path() + "/out.clf";
  CarmenWriter w;
  std::string error;
  CHECK(w.open(path, &error));
  w.laser(flaser_like(180, 1));
  CHECK(::access(path.c_str(), F_OK) != 0);
  CHECK(w.close(&error));
  CHECK(::access(path.c_str(), F_OK) == 0);
}

TEST(CarmenWriter, destroying_an_unclosed_writer_leaves_no_file) {
  ScratchDir dir("io-wr-abandon");
  const std::string path = dir.path() + "/out.clf";
  {
    CarmenWriter w;
    std::string error;
    CHECK(w.open(path, &error));
    w.laser(flaser_like(180, 1));
  }
  CHECK(::access(path.c_str(), F_OK) != 0);
  std::string listing;
  for (const auto& e : std::filesystem::directory_iterator(dir.path())) listing += e.path().string();
  STRCMP_EQUAL("", listing.c_str());
}

TEST(CarmenWriter, open_in_a_missing_directory_fails_with_a_reason) {
  CarmenWriter w;
  std::string error;
  CHECK_FALSE(w.open("/nonexistent/dir/out.clf", &error));
  CHECK_FALSE(error.empty());
}

TEST(CarmenWriter, close_without_open_fails) {
  CarmenWriter w;
  std::string error;
  CHECK_FALSE(w.close(&error));
  CHECK_FALSE(error.empty());
}
