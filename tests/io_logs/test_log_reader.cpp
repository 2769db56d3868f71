// LogReader over crafted files: every defect between good lines, formats, .gz, errors.
#include <CppUTest/TestHarness.h>

#include <cmath>
#include <string>
#include <vector>

#include "log_test_util.h"
#include "sdpslam/io/log_reader.h"

using sdpslam::io::LogContents;
using sdpslam::io::LogFormat;
using sdpslam::io::LogReader;
using sdpslam::io::LogReaderOptions;
using sdpslam::test::flaser_line;
using sdpslam::test::ScratchDir;
using sdpslam::test::tinyslam_line;

namespace {
constexpr double kPi = 3.14159265358979323846;

// These crafted logs move metres in microseconds: the odometry plausibility checks are
// off except in the tests that are about them.
LogReaderOptions unchecked() {
  LogReaderOptions o;
  o.max_speed_mps = 0.0;
  o.max_turn_rate_radps = 0.0;
  return o;
}

LogContents read_all(const std::string& path, const LogReaderOptions& o = unchecked()) {
  LogContents c;
  std::string error;
  CHECK_TEXT(sdpslam::io::read_whole_log(path, o, &c, &error), error.c_str());
  return c;
}

// The error list holds exactly these lines (1-based) in order, each naming the file.
void check_error_lines(const LogContents& c, const std::string& path, const std::vector<std::int64_t>& lines) {
  CHECK_EQUAL(lines.size(), c.error_count);
  CHECK_EQUAL(lines.size(), c.errors.size());
  for (std::size_t i = 0; i < lines.size() && i < c.errors.size(); ++i) {
    CHECK_EQUAL(lines[i], c.errors[i].line);
    STRCMP_EQUAL(path.c_str(), c.errors[i].file.c_str());
    CHECK_FALSE(c.errors[i].reason.empty());
  }
}

std::string odom(int i) {
  return "ODOM " + std::to_string(i) + ".0 0 0 0 0 0 100." + std::to_string(100000 + i) + " nohost 0";
}
}  // namespace

TEST_GROUP(LogReader){};

TEST(LogReader, every_defect_is_reported_and_every_good_record_delivered) {
  ScratchDir dir("io-defects");
  std::string s;
  s += "# header comment\n";                                           // 1
  s += odom(1) + "\n";                                                 // 2 good
  s += flaser_line(180, "1.0", "0 0 0", "100.2") + "\n";               // 3 good
  s += flaser_line(179, "1.0", "0 0 0", "100.3").replace(7, 3, "180") + "\n";  // 4 count mismatch
  s += odom(2) + "\n";                                                 // 5 good
  s += "ODOM 1.0 abc 0 0 0 0 100.4 nohost 0\n";                        // 6 non-numeric
  s += flaser_line(5, "nan", "0 0 0", "100.5") + "\n";                 // 7 NaN
  s += flaser_line(5, "inf", "0 0 0", "100.5") + "\n";                 // 8 inf
  s += "FLASER -5 1 2 3\n";                                            // 9 negative count
  s += flaser_line(1082, "1.0", "0 0 0", "100.6") + "\n";              // 10 over capacity
  s += "FLASER 180 1.0 1.0 1.0\n";                                     // 11 truncated
  s += std::string("ODOM \x01\x7f\xfe garbage\n");                     // 12 garbage bytes
  s += "ODOM " + std::string(70000, '7') + "\n";                       // 13 over-long
  s += "SYNC tag 100.7 nohost 0\n";                                    // 14 ignored, no error
  s += "WHATEVER 1 2 3\n";                                             // 15 unknown type (warning)
  s += odom(3) + "\n";                                                 // 16 good
  s += flaser_line(180, "2.5", "1 2 3", "100.9") + "\n";               // 17 good
  s += "ODOM 7.0 0 0 0 0 0 101.0 nohost";                              // 18 truncated at EOF
  const std::string path = dir.write("defects.clf", s);

  const LogContents c = read_all(path);
  CHECK(c.format == LogFormat::kCarmen);
  check_error_lines(c, path, {4, 6, 7, 8, 9, 10, 11, 12, 13, 15, 18});
  CHECK_EQUAL(1U, c.warning_count);
  CHECK(c.errors[9].warning);
  STRCMP_CONTAINS("unknown message type 'WHATEVER'", c.errors[9].reason.c_str());
  STRCMP_CONTAINS("longer than", c.errors[8].reason.c_str());
  STRCMP_CONTAINS("non-text byte 0x01", c.errors[7].reason.c_str());
  CHECK_EQUAL(3U, c.odoms.size());
  CHECK_EQUAL(2U, c.lasers.size());
  CHECK_EQUAL(2LL, c.odoms[0].line);
  CHECK_EQUAL(5LL, c.odoms[1].line);
  CHECK_EQUAL(16LL, c.odoms[2].line);
  DOUBLES_EQUAL(3.0, c.odoms[2].pose.x_m, 0.0);
  CHECK_EQUAL(3LL, c.lasers[0].line);
  CHECK_EQUAL(17LL, c.lasers[1].line);
  CHECK_EQUAL(2.5F, c.lasers[1].scan.ranges_m[179]);
  CHECK_EQUAL(100900000LL, c.lasers[1].stamp_us);
}

TEST(LogReader, error_text_is_file_colon_line_colon_reason) {
  ScratchDir dir("io-errtext");
  const std::string path = dir.write("e.clf", odom(1) + "\nODOM 1\n");
  const LogContents c = read_all(path);
  CHECK_EQUAL(1U, c.errors.size());
  STRCMP_EQUAL((path + ":2: ODOM needs 10 fields, found 2").c_str(), c.errors[0].to_string().c_str());
}

TEST(LogReader, errors_beyond_the_kept_limit_are_still_counted) {
  ScratchDir dir("io-errcap");
  std::string s = odom(1) + "\n";
  for (int i = 0; i < 10; ++i) s += "ODOM bad\n";
  LogReaderOptions o;
  o.max_errors_kept = 3;
  const LogContents c = read_all(dir.write("e.clf", s), o);
  CHECK_EQUAL(10U, c.error_count);
  CHECK_EQUAL(3U, c.errors.size());
  CHECK_EQUAL(1U, c.odoms.size());
}

TEST(LogReader, log_without_odom_lines_fills_odometry_from_the_laser) {
  ScratchDir dir("io-noodom");
  const std::string path = dir.write("l.clf", flaser_line(180, "1.0", "1.5 -2 0.25", "5.0") + "\n");
  const LogContents c = read_all(path);
  CHECK_EQUAL(0U, c.odoms.size());
  CHECK_EQUAL(1U, c.lasers.size());
  CHECK(c.lasers[0].has_odom_pose);
  DOUBLES_EQUAL(1.5, c.lasers[0].odom_pose.x_m, 0.0);
  DOUBLES_EQUAL(0.25, c.lasers[0].odom_pose.heading_rad, 0.0);
}

TEST(LogReader, param_lines_set_laser_offset_and_max_for_later_scans) {
  ScratchDir dir("io-param");
  std::string s = flaser_line(180, "1.0", "0 0 0", "1.0") + "\n";
  s += "PARAM robot_frontlaser_offset 0.15 nohost 0\n";
  s += "PARAM robot_frontlaser_max 8.5 nohost 0\n";
  s += flaser_line(180, "1.0", "0 0 0", "2.0") + "\n";
  const LogContents c = read_all(dir.write("p.clf", s));
  CHECK_EQUAL(2U, c.params.size());
  CHECK_EQUAL(2U, c.lasers.size());
  DOUBLES_EQUAL(0.0, c.lasers[0].scan.geometry.laser_in_base.x_m, 0.0);
  CHECK_EQUAL(50.0F, c.lasers[0].scan.geometry.range_max_m);
  DOUBLES_EQUAL(0.15, c.lasers[1].scan.geometry.laser_in_base.x_m, 0.0);
  CHECK_EQUAL(8.5F, c.lasers[1].scan.geometry.range_max_m);
}

TEST(LogReader, gzip_input_reads_the_same_records) {
  ScratchDir dir("io-gz");
  const std::string s = odom(1) + "\n" + flaser_line(180, "1.25", "0 0 0", "3.5") + "\nODOM broken\n" + odom(2) + "\n";
  const LogContents plain = read_all(dir.write("a.clf", s));
  const LogContents gz = read_all(dir.write("a.clf.gz", s, true));
  CHECK_EQUAL(plain.odoms.size(), gz.odoms.size());
  CHECK_EQUAL(2U, gz.odoms.size());
  CHECK_EQUAL(1U, gz.lasers.size());
  CHECK_EQUAL(1.25F, gz.lasers[0].scan.ranges_m[17]);
  CHECK_EQUAL(1U, gz.error_count);
  CHECK_EQUAL(3LL, gz.errors[0].line);
}

TEST(LogReader, truncated_gzip_is_reported_after_the_records_before_the_cut) {
  ScratchDir dir("io-gzcut");
  std::string s;
  for (int i = 0; i < 2000; ++i) s += odom(i) + "\n";
  const std::string full = dir.write("a.clf.gz", s, true);
  const std::string bytes = sdpslam::test::read_file(full);
  const std::string cut = dir.write("cut.clf.gz", bytes.substr(0, bytes.size() / 2));
  LogContents c;
  std::string error;
  CHECK(sdpslam::io::read_whole_log(cut, unchecked(), &c, &error));
  CHECK(c.odoms.size() > 0U);
  CHECK(c.odoms.size() < 2000U);
  CHECK(c.error_count >= 1U);
  STRCMP_CONTAINS("truncated", c.errors.back().reason.c_str());
}

TEST(LogReader, missing_file_fails_to_open_naming_the_path) {
  LogReader r;
  std::string error;
  CHECK_FALSE(r.open("/nonexistent/dir/log.clf", LogReaderOptions{}, &error));
  STRCMP_CONTAINS("/nonexistent/dir/log.clf", error.c_str());
  CHECK(r.next() == LogReader::Next::kEnd);
}

TEST(LogReader, undetectable_format_fails_to_open) {
  ScratchDir dir("io-undetect");
  LogReader r;
  std::string error;
  CHECK_FALSE(r.open(dir.write("x.txt", "hello world\nthis is not a log\n"), LogReaderOptions{}, &error));
  STRCMP_CONTAINS("cannot detect", error.c_str());
}

TEST(LogReader, empty_file_fails_to_open) {
  ScratchDir dir("io-empty");
  LogReader r;
  std::string error;
  CHECK_FALSE(r.open(dir.write("x.clf", ""), LogReaderOptions{}, &error));
}

TEST(LogReader, forced_format_reads_a_file_that_detection_would_refuse) {
  ScratchDir dir("io-forced");
  LogReaderOptions o;
  o.format = LogFormat::kCarmen;
  LogReader r;
  std::string error;
  CHECK(r.open(dir.write("x.clf", "# only a comment\n"), o, &error));
  CHECK(r.next() == LogReader::Next::kEnd);
  CHECK_EQUAL(1LL, r.lines_read());
}

TEST(LogReader, crlf_line_endings_are_accepted) {
  ScratchDir dir("io-crlf");
  const LogContents c = read_all(dir.write("x.clf", odom(1) + "\r\n" + odom(2) + "\r\n"));
  CHECK_EQUAL(2U, c.odoms.size());
  CHECK_EQUAL(0U, c.error_count);
}

TEST(LogReader, robotlaser_log_is_detected_and_read) {
  ScratchDir dir("io-robotlaser");
  std::string line = "ROBOTLASER1 0 -1.5 3.0 0.5 20 0.01 0 7 1 2 3 4 5 6 7 0 0.1 0 0 0 0 0 0 0 0 0 0 12.5 h 12.6\n";
  const LogContents c = read_all(dir.write("x.clf", line));
  CHECK_EQUAL(1U, c.lasers.size());
  CHECK_EQUAL(7U, c.lasers[0].scan.beam_count);
  CHECK_EQUAL(12500000LL, c.lasers[0].stamp_us);
}

TEST(LogReader, tinyslam_is_detected_with_urg_geometry_and_error_codes_invalid) {
  ScratchDir dir("io-tiny");
  std::string s = tinyslam_line(361431443, 1000, 1000, 1500) + "\n";
  s += tinyslam_line(361531443, 1000, 1000, 7) + "\n";  // error code 7: invalid beams
  const LogContents c = read_all(dir.write("t.dat", s));
  CHECK(c.format == LogFormat::kTinySlam);
  CHECK_EQUAL(2U, c.lasers.size());
  CHECK_EQUAL(682U, c.lasers[0].scan.beam_count);
  CHECK_EQUAL(1.5F, c.lasers[0].scan.ranges_m[0]);
  CHECK_EQUAL(361431443LL, c.lasers[0].stamp_us);
  CHECK(c.lasers[1].scan.classify(100) == sdpslam::RangeScan::Beam::kInvalid);
  const auto& g = c.lasers[0].scan.geometry;
  DOUBLES_EQUAL(-340.0 * 2 * kPi / 1024, g.angle_min_rad, 1e-6);
  DOUBLES_EQUAL(2 * kPi / 1024, g.angle_increment_rad, 1e-7);
  CHECK_EQUAL(5.6F, g.range_max_m);
  CHECK_EQUAL(0.02F, g.range_min_m);
  DOUBLES_EQUAL(0.145, g.laser_in_base.x_m, 0.0);
}

TEST(LogReader, tinyslam_first_sample_is_latched_and_equal_ticks_drive_straight) {
  ScratchDir dir("io-tiny-straight");
  // 1000 ticks = half a revolution of a 77 mm wheel: pi * 0.077 m.
  std::string s = tinyslam_line(1, 5000, 7000, 1000) + "\n" + tinyslam_line(2, 6000, 8000, 1000) + "\n";
  const LogContents c = read_all(dir.write("t.dat", s));
  CHECK_EQUAL(2U, c.lasers.size());
  DOUBLES_EQUAL(0.0, c.lasers[0].odom_pose.x_m, 0.0);
  DOUBLES_EQUAL(kPi * 0.077, c.lasers[1].odom_pose.x_m, 1e-12);
  DOUBLES_EQUAL(0.0, c.lasers[1].odom_pose.y_m, 1e-12);
  DOUBLES_EQUAL(0.0, c.lasers[1].odom_pose.heading_rad, 1e-12);
}

TEST(LogReader, tinyslam_right_wheel_ahead_turns_left) {
  ScratchDir dir("io-tiny-turn");
  std::string s = tinyslam_line(1, 0, 0, 1000) + "\n" + tinyslam_line(2, -100, 100, 1000) + "\n";
  const LogContents c = read_all(dir.write("t.dat", s));
  const double wheel_m = 100.0 * 2 * kPi / 2000.0 * 0.077;
  DOUBLES_EQUAL(2 * wheel_m / 0.33, c.lasers[1].odom_pose.heading_rad, 1e-12);
  DOUBLES_EQUAL(0.0, c.lasers[1].odom_pose.x_m, 1e-12);
}

TEST(LogReader, tinyslam_wheel_params_come_from_options) {
  ScratchDir dir("io-tiny-params");
  LogReaderOptions o = unchecked();
  o.wheels.ticks_per_rev = 1000.0;
  o.wheels.wheel_radius_m = 0.1;
  std::string s = tinyslam_line(1, 0, 0, 1000) + "\n" + tinyslam_line(2, 1000, 1000, 1000) + "\n";
  const LogContents c = read_all(dir.write("t.dat", s), o);
  DOUBLES_EQUAL(2 * kPi * 0.1, c.lasers[1].odom_pose.x_m, 1e-12);
}

TEST(LogReader, tinyslam_bad_line_is_skipped_and_odometry_continues) {
  ScratchDir dir("io-tiny-bad");
  std::string bad = tinyslam_line(2, 500, 500, 1000);
  bad.replace(bad.rfind(" 1000 "), 6, " 10x0 ");
  std::string s = tinyslam_line(1, 0, 0, 1000) + "\n" + bad + "\n1 2 3\n" + tinyslam_line(3, 1000, 1000, 1000) + "\n";
  const LogContents c = read_all(dir.write("t.dat", s));
  CHECK_EQUAL(2U, c.lasers.size());
  CHECK_EQUAL(2U, c.error_count);
  CHECK_EQUAL(2LL, c.errors[0].line);
  STRCMP_CONTAINS("'10x0'", c.errors[0].reason.c_str());
  STRCMP_CONTAINS("fields, found 3", c.errors[1].reason.c_str());
  DOUBLES_EQUAL(kPi * 0.077, c.lasers[1].odom_pose.x_m, 1e-12);
}

TEST(LogReader, dpslam_scans_get_synthetic_stamps_and_the_latest_odometry) {
  ScratchDir dir("io-dp");
  std::string laser = "Laser 181";
  for (int i = 0; i < 181; ++i) laser += " 0.642000";
  std::string s = "Odometry -2.4 4.8 2.5 \n" + laser + "\nOdometry -2.3 4.9 2.6\n" + laser + "\n";
  const LogContents c = read_all(dir.write("d.log", s));
  CHECK(c.format == LogFormat::kDpSlam);
  CHECK_EQUAL(2U, c.lasers.size());
  CHECK_EQUAL(2U, c.odoms.size());
  CHECK_EQUAL(181U, c.lasers[0].scan.beam_count);
  CHECK_FALSE(c.lasers[0].has_stamp);
  CHECK_EQUAL(0LL, c.lasers[0].stamp_us);
  CHECK_EQUAL(100000LL, c.lasers[1].stamp_us);
  DOUBLES_EQUAL(-2.3, c.lasers[1].odom_pose.x_m, 0.0);
  CHECK_EQUAL(0.642F, c.lasers[1].scan.ranges_m[180]);
  CHECK_EQUAL(static_cast<float>(kPi / 180.0), c.lasers[0].scan.geometry.angle_increment_rad);
}

TEST(LogReader, dpslam_laser_with_wrong_count_is_skipped_without_consuming_a_stamp) {
  ScratchDir dir("io-dp-bad");
  std::string s = "Odometry 0 0 0\nLaser 3 1 2\nLaser 3 1 2 3\nOdometry 0 x 0\n";
  const LogContents c = read_all(dir.write("d.log", s));
  CHECK_EQUAL(1U, c.lasers.size());
  CHECK_EQUAL(0LL, c.lasers[0].stamp_us);
  CHECK_EQUAL(2U, c.error_count);
  CHECK_EQUAL(2LL, c.errors[0].line);
  CHECK_EQUAL(4LL, c.errors[1].line);
}

TEST(LogReader, reader_can_be_reopened_on_another_file) {
  ScratchDir dir("io-reopen");
  LogReader r;
  std::string error;
  CHECK(r.open(dir.write("a.clf", odom(1) + "\nODOM x\n"), LogReaderOptions{}, &error));
  while (r.next() != LogReader::Next::kEnd) {
  }
  CHECK_EQUAL(1U, r.error_count());
  CHECK(r.open(dir.write("b.clf", odom(1) + "\n"), LogReaderOptions{}, &error));
  CHECK(r.next() == LogReader::Next::kOdom);
  CHECK_EQUAL(0U, r.error_count());
}

namespace {
std::string odom_tv(const std::string& pose, const std::string& tv_mps, const std::string& stamp) {
  return "ODOM " + pose + " " + tv_mps + " 0 0 " + stamp + " nohost 0";
}
}  // namespace

// A base that integrates |v| reports a forward increment while its measured velocity
// says the robot reversed: the increment is mirrored, later poses follow the repaired
// chain, and a laser's odometry pose moves with the correction of the last ODOM.
TEST(LogReader, odometry_advancing_against_a_negative_velocity_is_mirrored) {
  ScratchDir dir("io-reverse");
  std::string s;
  s += odom_tv("0 0 0", "0.5", "100.0") + "\n";
  s += odom_tv("1 0 0", "0.5", "100.1") + "\n";    // forward, as measured
  s += odom_tv("2 0 0.1", "-0.5", "100.2") + "\n";  // "forward" while reversing: mirrored
  s += flaser_line(3, "1.0", "2.5 0 0.1", "100.25") + "\n";
  s += odom_tv("3 0 0.1", "-0.5", "100.3") + "\n";  // mirrored again (in the turned frame)
  s += odom_tv("4 0 0.1", "0.5", "100.4") + "\n";   // forward again, as measured
  const std::string path = dir.write("rev.clf", s);
  LogReader reader;
  std::string error;
  CHECK_TEXT(reader.open(path, unchecked(), &error), error.c_str());
  std::vector<sdpslam::Pose2> odoms;
  std::vector<sdpslam::Pose2> lasers;
  for (LogReader::Next n = reader.next(); n != LogReader::Next::kEnd; n = reader.next()) {
    if (n == LogReader::Next::kOdom) odoms.push_back(reader.odom().pose);
    if (n == LogReader::Next::kLaser) lasers.push_back(reader.laser().odom_pose);
  }
  CHECK_EQUAL(2U, reader.odometry_reversals_repaired());
  CHECK_EQUAL(0U, reader.error_count());
  CHECK_EQUAL(5U, odoms.size());
  CHECK_EQUAL(1U, lasers.size());
  DOUBLES_EQUAL(1.0, odoms[1].x_m, 1e-12);
  DOUBLES_EQUAL(0.0, odoms[2].x_m, 1e-12);  // 1 - 1
  DOUBLES_EQUAL(0.0, odoms[2].y_m, 1e-12);
  DOUBLES_EQUAL(0.1, odoms[2].heading_rad, 1e-12);
  // Step 3 is 1 m along x in the log's frame, i.e. (cos 0.1, -sin 0.1) in the frame of
  // the pose at 100.2; mirrored, it goes back along the same line.
  DOUBLES_EQUAL(-1.0, odoms[3].x_m, 1e-12);
  DOUBLES_EQUAL(0.0, odoms[3].y_m, 1e-12);
  DOUBLES_EQUAL(0.0, odoms[4].x_m, 1e-12);  // forward 1 m again
  DOUBLES_EQUAL(0.1, odoms[4].heading_rad, 1e-12);
  // The laser at 100.25: 0.5 m ahead of the raw ODOM at 100.2, kept as written, on the
  // repaired pose of that ODOM.
  DOUBLES_EQUAL(0.5, lasers[0].x_m, 1e-12);
  DOUBLES_EQUAL(0.0, lasers[0].y_m, 1e-12);
}

// Poses that agree with their velocity (or carry none: tv = 0, as in most converted
// logs) are returned exactly as written, bit for bit.
TEST(LogReader, self_consistent_odometry_is_returned_as_written) {
  ScratchDir dir("io-consistent");
  std::string s;
  s += odom_tv("0.3 0.7 0.2", "0.5", "100.0") + "\n";
  s += odom_tv("0.1 0.65 0.2", "-0.4", "100.1") + "\n";  // backwards, as measured
  s += odom_tv("1.1 0.9 0.3", "0", "100.2") + "\n";     // no velocity measured
  s += flaser_line(3, "1.0", "1.2 0.95 0.3", "100.25") + "\n";
  // In-place turns while a small velocity is reported, either sign: the position does
  // not change, so the forward component is exactly 0 and nothing contradicts it.
  // These headings are ones where a⁻¹ ⊕ b leaves a residue of ±1e-16 in x.
  s += odom_tv("1.1 0.9 0.8", "0.01", "100.3") + "\n";
  s += odom_tv("1.1 0.9 2.9", "-0.01", "100.4") + "\n";
  s += odom_tv("1.1 0.9 -2.2", "-0.01", "100.5") + "\n";
  const std::string path = dir.write("ok.clf", s);
  LogReader reader;
  std::string error;
  CHECK_TEXT(reader.open(path, unchecked(), &error), error.c_str());
  while (reader.next() != LogReader::Next::kEnd) {
  }
  CHECK_EQUAL(0U, reader.odometry_reversals_repaired());
  const LogContents c = read_all(path);
  CHECK_EQUAL(6U, c.odoms.size());
  CHECK_EQUAL(-2.2, c.odoms[5].pose.heading_rad);
  CHECK_EQUAL(1U, c.lasers.size());
  CHECK_EQUAL(0.1, c.odoms[1].pose.x_m);
  CHECK_EQUAL(0.65, c.odoms[1].pose.y_m);
  CHECK_EQUAL(1.1, c.odoms[2].pose.x_m);
  CHECK_EQUAL(1.2, c.lasers[0].odom_pose.x_m);
  CHECK_EQUAL(0.95, c.lasers[0].laser_pose.y_m);
}

// A 1 km odometry jump in 0.1 s (a reset, or a corrupt line) is no motion a wheeled
// robot makes: it is named and not applied; the increments after it are kept as written
// on the chain from the pose before it, for ODOM and the lasers' odometry alike.
TEST(LogReader, an_impossible_odometry_jump_is_named_and_not_applied) {
  ScratchDir dir("io-jump");
  std::string s;
  s += odom_tv("0 0 0", "0.5", "100.0") + "\n";
  s += flaser_line(3, "1.0", "0.05 0 0", "100.05") + "\n";
  s += odom_tv("0.1 0 0", "0.5", "100.1") + "\n";
  s += odom_tv("1000.1 0 0", "0.5", "100.2") + "\n";               // line 4: the jump
  s += flaser_line(3, "1.0", "1000.15 0 0", "100.25") + "\n";      // on the jumped chain: follows
  s += odom_tv("1000.2 0 0.05", "0.5", "100.3") + "\n";
  const std::string path = dir.write("jump.clf", s);
  LogReader reader;
  std::string error;
  CHECK_TEXT(reader.open(path, LogReaderOptions{}, &error), error.c_str());
  std::vector<sdpslam::Pose2> odoms;
  std::vector<sdpslam::Pose2> lasers;
  for (LogReader::Next n = reader.next(); n != LogReader::Next::kEnd; n = reader.next()) {
    if (n == LogReader::Next::kOdom) odoms.push_back(reader.odom().pose);
    if (n == LogReader::Next::kLaser) lasers.push_back(reader.laser().odom_pose);
  }
  CHECK_EQUAL(1U, reader.odometry_jumps_removed());
  CHECK_EQUAL(1U, reader.error_count());
  CHECK_EQUAL(4, reader.errors()[0].line);
  STRCMP_CONTAINS("odometry jumps 1000.000 m", reader.errors()[0].reason.c_str());
  STRCMP_CONTAINS("not applied", reader.errors()[0].reason.c_str());
  CHECK_EQUAL(4U, odoms.size());
  CHECK_EQUAL(2U, lasers.size());
  DOUBLES_EQUAL(0.1, odoms[2].x_m, 1e-9);   // the jump: no motion
  DOUBLES_EQUAL(0.15, lasers[1].x_m, 1e-9);  // later poses keep their increments
  DOUBLES_EQUAL(0.2, odoms[3].x_m, 1e-9);
  DOUBLES_EQUAL(0.05, odoms[3].heading_rad, 1e-12);
}

// Fast but possible motion (2 m/s and a 3 rad/s turn at 10 Hz), a turn on the spot and a
// three-second gap with its motion are not jumps: poses as written.
TEST(LogReader, fast_plausible_motion_is_not_a_jump) {
  ScratchDir dir("io-fast");
  std::string s;
  s += odom_tv("0 0 0", "2", "100.0") + "\n";
  s += odom_tv("0.2 0 0.3", "2", "100.1") + "\n";
  s += odom_tv("0.2 0 1.8", "0", "100.6") + "\n";
  s += odom_tv("0.2 0 0", "0", "101.1") + "\n";
  s += odom_tv("6.2 0 0", "2", "104.1") + "\n";
  const LogContents c = read_all(dir.write("fast.clf", s), LogReaderOptions{});
  CHECK_EQUAL(0U, c.error_count);
  CHECK_EQUAL(5U, c.odoms.size());
  DOUBLES_EQUAL(1.8, c.odoms[2].pose.heading_rad, 0.0);
  DOUBLES_EQUAL(6.2, c.odoms[4].pose.x_m, 0.0);
}

// Scans stamped before the scan they follow are counted with the first one's line and
// returned in file order, stamps as written (the order the laser delivered them).
TEST(LogReader, scans_stamped_backwards_are_counted_and_kept_in_file_order) {
  ScratchDir dir("io-backwards");
  std::string s;
  s += flaser_line(3, "1.0", "0 0 0", "100.0") + "\n";
  s += flaser_line(3, "1.0", "0.1 0 0", "100.7") + "\n";  // a stamp ahead of its time
  s += flaser_line(3, "1.0", "0.2 0 0", "100.2") + "\n";  // line 3: before 100.7
  s += flaser_line(3, "1.0", "0.3 0 0", "100.3") + "\n";
  const std::string path = dir.write("back.clf", s);
  LogReader reader;
  std::string error;
  CHECK_TEXT(reader.open(path, LogReaderOptions{}, &error), error.c_str());
  std::vector<std::int64_t> stamps;
  for (LogReader::Next n = reader.next(); n != LogReader::Next::kEnd; n = reader.next()) {
    if (n == LogReader::Next::kLaser) stamps.push_back(reader.laser().stamp_us);
  }
  CHECK_EQUAL(1U, reader.scans_stamped_backwards());
  CHECK_EQUAL(3, reader.first_backwards_line());
  CHECK_EQUAL(0U, reader.error_count());
  CHECK_EQUAL(4U, stamps.size());
  CHECK_EQUAL(100200000, stamps[2]);
}
