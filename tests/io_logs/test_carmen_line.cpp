// parse_carmen_line: one CARMEN line in isolation, good and malformed.
#include <CppUTest/TestHarness.h>

#include <cmath>
#include <string>

#include "log_test_util.h"
#include "sdpslam/io/log_reader.h"

using sdpslam::io::LaserRecord;
using sdpslam::io::LogReader;
using sdpslam::io::LogReaderOptions;
using sdpslam::io::OdomRecord;
using sdpslam::io::ParamRecord;

namespace {
constexpr double kPi = 3.14159265358979323846;

struct Parsed {
  LaserRecord laser;
  OdomRecord odom;
  ParamRecord param;
  std::string reason;
  LogReader::Next kind = LogReader::Next::kEnd;
};

Parsed parse(const std::string& line, const LogReaderOptions& options = LogReaderOptions{}) {
  Parsed p;
  p.kind = sdpslam::io::parse_carmen_line(line, options, &p.laser, &p.odom, &p.param, &p.reason);
  return p;
}

// The reason names the defect (a substring check keeps the tests readable).
void check_rejected(const std::string& line, const char* reason_part) {
  const Parsed p = parse(line);
  CHECK(p.kind == LogReader::Next::kEnd);
  CHECK_TEXT(p.reason.find(reason_part) != std::string::npos, (p.reason + " <- " + line.substr(0, 60)).c_str());
}

std::string robotlaser1(int n, int m, const std::string& tail_override = "") {
  std::string s = "ROBOTLASER1 0 -2.0 4.0 0.01 30.0 0.01 0 " + std::to_string(n);
  for (int i = 0; i < n; ++i) s += " " + std::to_string(1 + i % 7) + ".25";
  s += " " + std::to_string(m);
  for (int i = 0; i < m; ++i) s += " 100";
  s += tail_override.empty() ? " 1.08775825619 2.04794255386 0.5 1.0 2.0 0.5 0.3 0.1 0.5 0.2 0.6 1234.000001 host 1234.5" : tail_override;
  return s;
}
}  // namespace

TEST_GROUP(CarmenLine){};

TEST(CarmenLine, odom_line_gives_pose_velocities_and_exact_stamps) {
  const Parsed p = parse("ODOM 1.5 -2.25 0.125 0.3 -0.1 0.0 976052857.337916 nohost 0.000632");
  CHECK(p.kind == LogReader::Next::kOdom);
  CHECK(p.reason.empty());
  DOUBLES_EQUAL(1.5, p.odom.pose.x_m, 0.0);
  DOUBLES_EQUAL(-2.25, p.odom.pose.y_m, 0.0);
  DOUBLES_EQUAL(0.125, p.odom.pose.heading_rad, 0.0);
  DOUBLES_EQUAL(0.3, p.odom.tv_mps, 0.0);
  DOUBLES_EQUAL(-0.1, p.odom.rv_radps, 0.0);
  CHECK_EQUAL(976052857337916LL, p.odom.stamp_us);
  CHECK_EQUAL(632LL, p.odom.logger_stamp_us);
}

TEST(CarmenLine, stamp_digits_beyond_microseconds_round_half_away_from_zero) {
  CHECK_EQUAL(1000001LL, parse("ODOM 0 0 0 0 0 0 1.0000005 h 0").odom.stamp_us);
  CHECK_EQUAL(1000000LL, parse("ODOM 0 0 0 0 0 0 1.00000049 h 0").odom.stamp_us);
  CHECK_EQUAL(-500000LL, parse("ODOM 0 0 0 0 0 0 -0.5 h 0").odom.stamp_us);
  CHECK_EQUAL(12000000LL, parse("ODOM 0 0 0 0 0 0 12 h 0").odom.stamp_us);
}

TEST(CarmenLine, stamp_in_exponent_form_is_rejected) {
  check_rejected("ODOM 0 0 0 0 0 0 9.7e8 nohost 0", "ipc_timestamp");
}

TEST(CarmenLine, flaser_gives_ranges_half_circle_geometry_and_both_poses) {
  const std::string line =
      "FLASER 3 1.07 81.83 0.5 1.0 2.0 0.1 1.5 2.5 0.2 976052857.337530 nohost 0.000246";
  const Parsed p = parse(line);
  CHECK(p.kind == LogReader::Next::kLaser);
  CHECK_EQUAL(3U, p.laser.scan.beam_count);
  CHECK_EQUAL(1.07F, p.laser.scan.ranges_m[0]);
  CHECK_EQUAL(81.83F, p.laser.scan.ranges_m[1]);
  CHECK_EQUAL(static_cast<float>(-kPi / 2), p.laser.scan.geometry.angle_min_rad);
  CHECK_EQUAL(static_cast<float>(kPi / 2), p.laser.scan.geometry.angle_increment_rad);
  CHECK_EQUAL(50.0F, p.laser.scan.geometry.range_max_m);
  CHECK(p.laser.scan.classify(1) == sdpslam::RangeScan::Beam::kNoReturn);
  DOUBLES_EQUAL(1.0, p.laser.laser_pose.x_m, 0.0);
  DOUBLES_EQUAL(2.5, p.laser.odom_pose.y_m, 0.0);
  CHECK(p.laser.has_laser_pose && p.laser.has_odom_pose && p.laser.has_stamp);
  CHECK_EQUAL(976052857337530LL, p.laser.stamp_us);
  CHECK_EQUAL(976052857337530LL, p.laser.scan.stamp_us);
  CHECK_EQUAL(246LL, p.laser.logger_stamp_us);
  STRCMP_EQUAL("FLASER", p.laser.keyword.c_str());
}

TEST(CarmenLine, flaser_uses_front_laser_offset_and_max_from_options) {
  LogReaderOptions o;
  o.front_laser_offset_m = 0.2;
  o.front_laser_max_m = 8.0F;
  const Parsed p = parse(sdpslam::test::flaser_line(180, "1.0", "0 0 0", "1.0"), o);
  CHECK(p.kind == LogReader::Next::kLaser);
  DOUBLES_EQUAL(0.2, p.laser.scan.geometry.laser_in_base.x_m, 0.0);
  CHECK_EQUAL(8.0F, p.laser.scan.geometry.range_max_m);
  CHECK_EQUAL(static_cast<float>(kPi / 179.0), p.laser.scan.geometry.angle_increment_rad);
}

TEST(CarmenLine, rlaser_looks_backwards) {
  std::string line = sdpslam::test::flaser_line(4, "2.0", "0 0 0", "5.0");
  line.replace(0, 6, "RLASER");
  const Parsed p = parse(line);
  CHECK(p.kind == LogReader::Next::kLaser);
  DOUBLES_EQUAL(kPi, p.laser.scan.geometry.laser_in_base.heading_rad, 1e-12);
  STRCMP_EQUAL("RLASER", p.laser.keyword.c_str());
}

TEST(CarmenLine, robotlaser1_carries_its_own_geometry_and_laser_offset) {
  const Parsed p = parse(robotlaser1(5, 0));
  CHECK_TEXT(p.kind == LogReader::Next::kLaser, p.reason.c_str());
  CHECK_EQUAL(5U, p.laser.scan.beam_count);
  CHECK_EQUAL(-2.0F, p.laser.scan.geometry.angle_min_rad);
  CHECK_EQUAL(0.01F, p.laser.scan.geometry.angle_increment_rad);
  CHECK_EQUAL(30.0F, p.laser.scan.geometry.range_max_m);
  CHECK_EQUAL(3.25F, p.laser.scan.ranges_m[2]);
  // Robot at (1, 2) heading 0.5; the laser 0.1 m ahead of it along that heading.
  DOUBLES_EQUAL(0.1, p.laser.scan.geometry.laser_in_base.x_m, 1e-9);
  DOUBLES_EQUAL(0.0, p.laser.scan.geometry.laser_in_base.y_m, 1e-9);
  DOUBLES_EQUAL(0.0, p.laser.scan.geometry.laser_in_base.heading_rad, 1e-12);
  DOUBLES_EQUAL(1.0, p.laser.odom_pose.x_m, 0.0);
  CHECK_EQUAL(1234000001LL, p.laser.stamp_us);
  CHECK_EQUAL(1234500000LL, p.laser.logger_stamp_us);
}

TEST(CarmenLine, robotlaser1_with_remissions_is_parsed) {
  const Parsed p = parse(robotlaser1(4, 4));
  CHECK_TEXT(p.kind == LogReader::Next::kLaser, p.reason.c_str());
  CHECK_EQUAL(4U, p.laser.scan.beam_count);
}

TEST(CarmenLine, robotlaser1_missing_a_trailing_field_is_rejected) {
  check_rejected(robotlaser1(4, 0, " 1.1 2.0 0.5 1.0 2.0 0.5 0.3 0.1 0.5 0.2 1234.0 host 1234.5"), "needs 28 fields");
}

TEST(CarmenLine, robotlaser1_truncated_inside_ranges_is_rejected) {
  check_rejected("ROBOTLASER1 0 -2.0 4.0 0.01 30.0 0.01 0 100 1.0 2.0", "truncated");
}

TEST(CarmenLine, robotlaser1_with_zero_maximum_range_is_rejected) {
  std::string line = robotlaser1(3, 0);
  line.replace(line.find("30.0"), 4, "0.0");
  check_rejected(line, "maximum_range");
}

TEST(CarmenLine, param_line_old_style_without_ipc_stamp) {
  const Parsed p = parse("PARAM robot_frontlaser_offset 0.0 nohost 0");
  CHECK(p.kind == LogReader::Next::kParam);
  STRCMP_EQUAL("robot_frontlaser_offset", p.param.name.c_str());
  STRCMP_EQUAL("0.0", p.param.value.c_str());
}

TEST(CarmenLine, param_line_new_style_with_spaces_in_value) {
  const Parsed p = parse("PARAM robot_name big red robot 12.000000 host 12.5");
  CHECK(p.kind == LogReader::Next::kParam);
  STRCMP_EQUAL("big red robot", p.param.value.c_str());
}

TEST(CarmenLine, param_without_value_is_rejected) { check_rejected("PARAM lonely", "name and a value"); }

TEST(CarmenLine, comments_and_blank_lines_are_not_records) {
  CHECK(parse("# ODOM x y theta").kind == LogReader::Next::kEnd);
  CHECK(parse("   \t ").kind == LogReader::Next::kEnd);
  CHECK(parse("").kind == LogReader::Next::kEnd);
  CHECK(parse("# comment").reason.empty());
}

TEST(CarmenLine, sync_truepos_and_nmea_are_ignored_without_error) {
  for (const char* line : {"SYNC tag 1.0 host 1.0", "TRUEPOS 1 2 3 1 2 3 1.0 host 1.0",
                           "NMEA-GGA 1 2 N 3 E 1 5 0.9 100 100 0 0 1.0 host 1.0"}) {
    const Parsed p = parse(line);
    CHECK(p.kind == LogReader::Next::kEnd);
    CHECK_TEXT(p.reason.empty(), line);
  }
}

TEST(CarmenLine, unknown_message_type_is_reported_by_name) {
  check_rejected("FROBNICATE 1 2 3", "unknown message type 'FROBNICATE'");
}

TEST(CarmenLine, flaser_with_one_range_missing_is_rejected) {
  std::string line = sdpslam::test::flaser_line(180, "1.0", "0 0 0", "1.0");
  line.erase(10, 4);  // one " 1.0" fewer
  check_rejected(line, "FLASER with 180 readings needs 191 fields, found 190");
}

TEST(CarmenLine, flaser_with_an_extra_field_is_rejected) {
  check_rejected(sdpslam::test::flaser_line(5, "1.0", "0 0 0", "1.0") + " 7", "needs 16 fields, found 17");
}

TEST(CarmenLine, nan_range_is_rejected) {
  check_rejected(sdpslam::test::flaser_line(5, "nan", "0 0 0", "1.0"), "range 0 (field 3) is not a finite number");
}

TEST(CarmenLine, infinite_range_is_rejected) {
  check_rejected(sdpslam::test::flaser_line(5, "inf", "0 0 0", "1.0"), "not a finite number");
}

TEST(CarmenLine, negative_range_is_rejected) {
  check_rejected(sdpslam::test::flaser_line(5, "-1.0", "0 0 0", "1.0"), "negative");
}

TEST(CarmenLine, non_numeric_pose_is_rejected) {
  check_rejected(sdpslam::test::flaser_line(5, "1.0", "0 zero 0", "1.0"), "laser pose field 9");
}

TEST(CarmenLine, nan_pose_is_rejected) { check_rejected("ODOM 0 nan 0 0 0 0 1.0 h 1.0", "ODOM field 3"); }

TEST(CarmenLine, range_with_trailing_garbage_is_rejected) {
  check_rejected(sdpslam::test::flaser_line(5, "1.0x", "0 0 0", "1.0"), "'1.0x'");
}

TEST(CarmenLine, negative_beam_count_is_rejected) { check_rejected("FLASER -3 1 2 3", "below 2"); }

TEST(CarmenLine, non_integer_beam_count_is_rejected) { check_rejected("FLASER 3.5 1 2 3", "not an integer"); }

TEST(CarmenLine, beam_count_above_capacity_is_rejected) {
  check_rejected(sdpslam::test::flaser_line(1082, "1.0", "0 0 0", "1.0"), "exceeds the capacity of 1081");
}

TEST(CarmenLine, beam_count_at_capacity_is_accepted) {
  const Parsed p = parse(sdpslam::test::flaser_line(1081, "1.0", "0 0 0", "1.0"));
  CHECK_TEXT(p.kind == LogReader::Next::kLaser, p.reason.c_str());
  CHECK_EQUAL(1081U, p.laser.scan.beam_count);
}

TEST(CarmenLine, huge_beam_count_does_not_overflow) {
  check_rejected("FLASER 99999999999999999999 1 2", "not an integer");
  check_rejected("FLASER 9223372036854775807 1 2", "exceeds the capacity");
}

TEST(CarmenLine, truncated_odom_is_rejected) { check_rejected("ODOM 0.1 0.2", "ODOM needs 10 fields, found 3"); }

TEST(CarmenLine, garbage_bytes_are_rejected_with_their_column) {
  check_rejected(std::string("ODOM 0 0 \x01 0 0 0 1.0 h 1.0"), "non-text byte 0x01 at column 10");
  check_rejected(std::string("ODOM 0 0 \xff"), "non-text byte 0xff");
  check_rejected(std::string("ODOM 0\0 0", 9), "non-text byte 0x00 at column 7");
}

TEST(CarmenLine, over_long_line_is_rejected) {
  check_rejected("ODOM " + std::string(70000, '1'), "line longer than 65536 bytes");
}

TEST(CarmenLine, crlf_line_ending_is_accepted) {
  const Parsed p = parse("ODOM 1 2 3 0 0 0 1.0 h 1.0\r\n");
  CHECK(p.kind == LogReader::Next::kOdom);
}
