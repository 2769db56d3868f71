// sdpslamd's input recording: what SLAM is fed is exactly what the recording reads back
// as, lines are on disk as soon as the scan is fed, failures are reported, and the switch
// does not change what SLAM sees.
#include <CppUTest/TestHarness.h>

#include <unistd.h>

#include <csignal>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>

#include "sdpslam/daemon/daemon_config.h"
#include "sdpslam/daemon/input_recorder.h"
#include "sdpslam/io/log_reader.h"
#include "shared_data.h"

using namespace sdpslam;
using namespace sdpslam::daemon;

namespace {

// A scan as the URG driver hands it out, with values a CARMEN line cannot carry as they
// are: a range_min, NaN and +inf beams, a mounting whose compose/between loses bits.
RangeScan awkward_scan(std::int64_t stamp_us) {
  RangeScan s;
  s.stamp_us = stamp_us;
  s.beam_count = 682;
  s.geometry.angle_min_rad = -2.0862138F;
  s.geometry.angle_increment_rad = 0.0061359233F;
  s.geometry.range_min_m = 0.02F;
  s.geometry.range_max_m = 5.6F;
  s.geometry.laser_in_base = Pose2{0.145, 0.0123, 0.1};
  for (std::uint32_t i = 0; i < s.beam_count; ++i) s.ranges_m[i] = 0.1F + 0.0037F * static_cast<float>(i);
  s.ranges_m[3] = std::numeric_limits<float>::quiet_NaN();
  s.ranges_m[4] = std::numeric_limits<float>::infinity();
  s.ranges_m[5] = 0.0F;
  return s;
}

const OdometrySample kOdom{123456789012, Pose2{1.0 / 3.0, -2.718281828459045, 3.0}};

bool same_bits(const void* a, const void* b, std::size_t n) { return std::memcmp(a, b, n) == 0; }

// Bitwise equality of what SLAM got and what a reader gets from the recording.
void check_identical(const OdometrySample& od, const RangeScan& s, const io::LaserRecord& r) {
  LONGS_EQUAL(od.stamp_us, r.stamp_us);
  LONGS_EQUAL(s.stamp_us, r.scan.stamp_us);
  CHECK(same_bits(&od.pose, &r.odom_pose, sizeof(Pose2)));
  LONGS_EQUAL(s.beam_count, r.scan.beam_count);
  CHECK(same_bits(&s.geometry.angle_min_rad, &r.scan.geometry.angle_min_rad, sizeof(float)));
  CHECK(same_bits(&s.geometry.angle_increment_rad, &r.scan.geometry.angle_increment_rad, sizeof(float)));
  CHECK(same_bits(&s.geometry.range_min_m, &r.scan.geometry.range_min_m, sizeof(float)));
  CHECK(same_bits(&s.geometry.range_max_m, &r.scan.geometry.range_max_m, sizeof(float)));
  CHECK(same_bits(&s.geometry.laser_in_base, &r.scan.geometry.laser_in_base, sizeof(Pose2)));
  CHECK(same_bits(s.ranges_m, r.scan.ranges_m, sizeof(float) * s.beam_count));
}

std::string slurp(const std::string& path) {
  std::string out;
  std::FILE* f = std::fopen(path.c_str(), "r");
  if (f == nullptr) return out;
  char b[4096];
  for (std::size_t n; (n = std::fread(b, 1, sizeof b, f)) > 0;) out.append(b, n);
  std::fclose(f);
  return out;
}

}  // namespace

TEST_GROUP(SdpslamdInputRecorder){};

TEST(SdpslamdInputRecorder, values_fed_to_slam_are_bit_identical_to_the_recording_read_back) {
  const std::string path = test::make_temp_dir("input_recorder") + "/input.clf";
  auto rec = std::make_unique<InputRecorder>();
  std::string error;
  CHECK_TRUE_TEXT(rec->open(path, &error), error.c_str());
  auto in = std::make_unique<RangeScan>(awkward_scan(kOdom.stamp_us));
  auto out = std::make_unique<RangeScan>();
  OdometrySample od;
  CHECK_TRUE(rec->pass(kOdom, *in, kOdom.stamp_us + 4321, &od, out.get()));
  io::LogContents log;
  CHECK_TRUE_TEXT(io::read_whole_log(path, io::LogReaderOptions{}, &log, &error), error.c_str());
  LONGS_EQUAL(0, log.error_count);
  LONGS_EQUAL(1, log.lasers.size());
  check_identical(od, *out, log.lasers[0]);
  LONGS_EQUAL(kOdom.stamp_us + 4321, log.lasers[0].logger_stamp_us);
}

TEST(SdpslamdInputRecorder, round_trip_changes_are_counted_and_leave_ranges_and_pose_exact) {
  InputRecorder rec;
  auto in = std::make_unique<RangeScan>(awkward_scan(kOdom.stamp_us));
  auto out = std::make_unique<RangeScan>();
  OdometrySample od;
  rec.pass(kOdom, *in, 0, &od, out.get());
  LONGS_EQUAL(1, rec.stats().changed_count);  // range_min, NaN/inf beams cannot survive a CARMEN line
  CHECK(same_bits(&kOdom.pose, &od.pose, sizeof(Pose2)));
  CHECK(same_bits(in->ranges_m + 6, out->ranges_m + 6, sizeof(float) * (in->beam_count - 6U)));
  CHECK_EQUAL(0.0F, out->ranges_m[3]);                    // NaN: invalid beam
  CHECK_EQUAL(in->geometry.range_max_m, out->ranges_m[4]);  // +inf: no return
  LONGS_EQUAL(0, rec.stats().lines_written);              // nothing open: nothing written
}

TEST(SdpslamdInputRecorder, slam_sees_the_same_values_whether_or_not_it_records) {
  InputRecorder off;
  InputRecorder on;
  std::string error;
  CHECK_TRUE_TEXT(on.open(test::make_temp_dir("input_recorder") + "/input.clf", &error), error.c_str());
  auto in = std::make_unique<RangeScan>(awkward_scan(kOdom.stamp_us));
  auto a = std::make_unique<RangeScan>();
  auto b = std::make_unique<RangeScan>();
  OdometrySample oa, ob;
  off.pass(kOdom, *in, 7, &oa, a.get());
  on.pass(kOdom, *in, 7, &ob, b.get());
  CHECK(same_bits(&oa, &ob, sizeof oa));
  CHECK(same_bits(a.get(), b.get(), sizeof(RangeScan)));
}

TEST(SdpslamdInputRecorder, each_line_is_on_disk_when_pass_returns) {
  const std::string path = test::make_temp_dir("input_recorder") + "/input.clf";
  InputRecorder rec;
  std::string error;
  CHECK_TRUE_TEXT(rec.open(path, &error), error.c_str());
  auto in = std::make_unique<RangeScan>(awkward_scan(1000));
  auto out = std::make_unique<RangeScan>();
  OdometrySample od;
  for (int k = 0; k < 3; ++k) {
    rec.pass(OdometrySample{1000 + k, kOdom.pose}, *in, 0, &od, out.get());
    const std::string text = slurp(path);  // the recorder's file is still open
    std::size_t lines = 0;
    for (std::size_t p = 0; (p = text.find("\nROBOTLASER1 ", p)) != std::string::npos; ++p) ++lines;
    LONGS_EQUAL(k + 1, lines);
    CHECK_EQUAL('\n', text.back());
  }
  LONGS_EQUAL(3, rec.stats().lines_written);
  LONGS_EQUAL(slurp(path).size() - slurp(path).find("\nROBOTLASER1") - 1U, rec.stats().bytes_written);
}

TEST(SdpslamdInputRecorder, recording_that_cannot_be_created_is_refused_with_the_path) {
  InputRecorder rec;
  std::string error;
  const std::string path = test::make_temp_dir("input_recorder") + "/missing/dir/input.clf";
  CHECK_FALSE(rec.open(path, &error));
  CHECK_FALSE(rec.is_open());
  CHECK(error.find(path) != std::string::npos);
}

TEST(SdpslamdInputRecorder, failed_write_is_counted_and_slam_still_gets_the_scan) {
  // A pipe whose reader goes away after the header: the next write fails (EPIPE).
  int fds[2];
  CHECK_EQUAL(0, ::pipe(fds));
  void (*old)(int) = std::signal(SIGPIPE, SIG_IGN);
  InputRecorder rec;
  std::string error;
  const std::string path = "/proc/self/fd/" + std::to_string(fds[1]);
  CHECK_TRUE_TEXT(rec.open(path, &error), error.c_str());
  ::close(fds[0]);
  auto in = std::make_unique<RangeScan>(awkward_scan(1000));
  auto out = std::make_unique<RangeScan>();
  OdometrySample od;
  CHECK_FALSE(rec.pass(OdometrySample{1000, kOdom.pose}, *in, 0, &od, out.get()));
  LONGS_EQUAL(1, rec.stats().write_failures);
  LONGS_EQUAL(0, rec.stats().lines_written);
  CHECK(rec.last_error().find(path) != std::string::npos);
  LONGS_EQUAL(1000, od.stamp_us);
  LONGS_EQUAL(in->beam_count, out->beam_count);
  ::close(fds[1]);
  std::signal(SIGPIPE, old);
}

TEST(SdpslamdInputRecorder, input_log_key_is_read_and_a_bad_value_names_its_line) {
  const std::string dir = test::make_temp_dir("input_recorder");
  const std::string good = dir + "/good.ini";
  const std::string bad = dir + "/bad.ini";
  std::FILE* f = std::fopen(good.c_str(), "w");
  std::fputs("[output]\ninput_log = true\n", f);
  std::fclose(f);
  f = std::fopen(bad.c_str(), "w");
  std::fputs("[output]\nwrite_map = true\ninput_log = sometimes\n", f);
  std::fclose(f);
  DaemonConfig c;
  std::string error;
  CHECK_FALSE(c.input_log);
  CHECK_TRUE_TEXT(load_daemon_config(good, &c, &error), error.c_str());
  CHECK_TRUE(c.input_log);
  DaemonConfig d;
  CHECK_FALSE(load_daemon_config(bad, &d, &error));
  CHECK(error.rfind(bad + ":3:", 0) == 0);
  CHECK(error.find("input_log") != std::string::npos);
}
