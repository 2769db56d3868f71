// Trajectory files: exact stamps, deterministic text, round trips, and errors that name
// file:line.
#include <CppUTest/TestHarness.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "sdpslam/io/atomic_file.h"
#include "sdpslam/io/trajectory_io.h"
#include "shared_data.h"

using sdpslam::io::StampedPose;

namespace {
std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}
std::int64_t parsed(const char* text) {
  std::int64_t v = 12345;
  CHECK_TRUE_TEXT(sdpslam::io::parse_stamp_us(text, &v), text);
  return v;
}
}  // namespace

TEST_GROUP(StampText){};

TEST(StampText, format_prints_six_decimals_exactly) {
  STRCMP_EQUAL("976052905.167303", sdpslam::io::format_stamp_us(976052905167303).c_str());
  STRCMP_EQUAL("0.000000", sdpslam::io::format_stamp_us(0).c_str());
  STRCMP_EQUAL("0.000001", sdpslam::io::format_stamp_us(1).c_str());
  STRCMP_EQUAL("90.239599", sdpslam::io::format_stamp_us(90239599).c_str());
}

TEST(StampText, format_of_negative_stamps_keeps_sign_before_whole_part) {
  STRCMP_EQUAL("-0.000001", sdpslam::io::format_stamp_us(-1).c_str());
  STRCMP_EQUAL("-1.500000", sdpslam::io::format_stamp_us(-1500000).c_str());
  STRCMP_EQUAL("-9223372036854.775808",
               sdpslam::io::format_stamp_us(std::numeric_limits<std::int64_t>::min()).c_str());
  STRCMP_EQUAL("9223372036854.775807",
               sdpslam::io::format_stamp_us(std::numeric_limits<std::int64_t>::max()).c_str());
}

TEST(StampText, parse_is_exact_where_double_would_not_be) {
  // 976052905.167303 is not representable as a double; going through one gives ...302.
  CHECK_EQUAL(976052905167303LL, parsed("976052905.167303"));
  CHECK_EQUAL(90239599LL, parsed("90.239599"));
  CHECK_EQUAL(5000000LL, parsed("5"));
  CHECK_EQUAL(5000000LL, parsed("5."));
  CHECK_EQUAL(500000LL, parsed(".5"));
  CHECK_EQUAL(120000LL, parsed("0.12"));
  CHECK_EQUAL(7000000LL, parsed("+7.0"));
}

TEST(StampText, parse_of_negative_stamps) {
  CHECK_EQUAL(-1LL, parsed("-0.000001"));
  CHECK_EQUAL(-1500000LL, parsed("-1.5"));
  CHECK_EQUAL(0LL, parsed("-0.0"));
  CHECK_EQUAL(std::numeric_limits<std::int64_t>::min(), parsed("-9223372036854.775808"));
}

TEST(StampText, parse_rounds_seventh_decimal_half_away_from_zero) {
  CHECK_EQUAL(1LL, parsed("0.0000005"));
  CHECK_EQUAL(0LL, parsed("0.0000004999"));
  CHECK_EQUAL(-1LL, parsed("-0.0000005"));
  CHECK_EQUAL(1000000LL, parsed("0.99999951"));
}

TEST(StampText, parse_rejects_non_numbers_and_overflow) {
  const char* bad[] = {"", "-", ".", "abc", "1.2.3", "1e6", " 1", "1 ", "0x10", "nan", "1,5",
                       "9223372036854.775808", "99999999999999999999"};
  for (const char* text : bad) {
    std::int64_t v = 42;
    CHECK_FALSE_TEXT(sdpslam::io::parse_stamp_us(text, &v), text);
    CHECK_EQUAL(42LL, v);
  }
}

TEST(StampText, format_then_parse_round_trips) {
  const std::int64_t stamps[] = {0, 1, -1, 999999, -999999, 1000000, 976052905167303LL,
                                 std::numeric_limits<std::int64_t>::max(), std::numeric_limits<std::int64_t>::min()};
  for (std::int64_t s : stamps) CHECK_EQUAL(s, parsed(sdpslam::io::format_stamp_us(s).c_str()));
}

TEST_GROUP(TrajectoryFile) {
  std::string dir;
  std::vector<std::string> files;
  void setup() override { dir = sdpslam::test::make_temp_dir("traj"); }
  void teardown() override {
    for (const auto& f : files) ::unlink(f.c_str());
    ::rmdir(dir.c_str());
  }
  std::string file(const std::string& name) {
    files.push_back(dir + "/" + name);
    return files.back();
  }
  std::string write_text(const std::string& name, const std::string& text) {
    const std::string p = file(name);
    std::string error;
    CHECK_TRUE(sdpslam::io::write_file_atomic(p, text, &error));
    return p;
  }
};

TEST(TrajectoryFile, writer_output_is_exact_text) {
  const std::string p = file("t.txt");
  std::vector<StampedPose> poses{{976052905167303LL, {1.5, -2.25, 0.123456789012}}, {-1, {0.0, 0.0, -3.0}}};
  std::string error;
  CHECK_TRUE(sdpslam::io::write_trajectory(p, poses, &error));
  STRCMP_EQUAL(
      "# t x y theta (s, m, m, rad)\n"
      "976052905.167303 1.500000 -2.250000 0.123456789\n"
      "-0.000001 0.000000 0.000000 -3.000000000\n",
      slurp(p).c_str());
}

TEST(TrajectoryFile, tum_writer_uses_yaw_only_quaternion_and_zero_z) {
  const std::string p = file("t.tum");
  const double pi = 3.14159265358979323846;
  std::vector<StampedPose> poses{{2000000, {1.0, 2.0, pi / 2.0}}};
  std::string error;
  CHECK_TRUE(sdpslam::io::write_trajectory_tum(p, poses, &error));
  STRCMP_EQUAL(
      "# timestamp tx ty tz qx qy qz qw\n"
      "2.000000 1.000000 2.000000 0.000000 0.000000000 0.000000000 0.707106781 0.707106781\n",
      slurp(p).c_str());
}

TEST(TrajectoryFile, write_then_read_round_trips_both_formats) {
  std::vector<StampedPose> poses;
  for (int i = 0; i < 50; ++i) {
    poses.push_back({976052905167303LL + i * 133333LL, {0.1 * i, -0.07 * i, 3.1 * std::sin(0.3 * i)}});
  }
  std::string error;
  const std::string a = file("a.txt");
  const std::string b = file("b.tum");
  CHECK_TRUE(sdpslam::io::write_trajectory(a, poses, &error));
  CHECK_TRUE(sdpslam::io::write_trajectory_tum(b, poses, &error));
  for (const std::string& p : {a, b}) {
    std::vector<StampedPose> back;
    CHECK_TRUE_TEXT(sdpslam::io::read_trajectory(p, &back, &error), error.c_str());
    LONGS_EQUAL(poses.size(), back.size());
    for (std::size_t i = 0; i < poses.size(); ++i) {
      CHECK_EQUAL(poses[i].stamp_us, back[i].stamp_us);
      DOUBLES_EQUAL(poses[i].pose.x_m, back[i].pose.x_m, 1e-6);
      DOUBLES_EQUAL(poses[i].pose.y_m, back[i].pose.y_m, 1e-6);
      DOUBLES_EQUAL(0.0, sdpslam::normalize_angle_rad(poses[i].pose.heading_rad - back[i].pose.heading_rad), 2e-8);
    }
  }
}

TEST(TrajectoryFile, writing_twice_gives_identical_bytes) {
  std::vector<StampedPose> poses{{1, {1.0 / 3.0, 2.0 / 3.0, 1.0 / 7.0}}};
  std::string error;
  const std::string a = file("x1");
  const std::string b = file("x2");
  CHECK_TRUE(sdpslam::io::write_trajectory(a, poses, &error));
  CHECK_TRUE(sdpslam::io::write_trajectory(b, poses, &error));
  CHECK(slurp(a) == slurp(b));
}

TEST(TrajectoryFile, non_finite_pose_is_refused_and_old_file_kept) {
  const std::string p = write_text("keep.txt", "old\n");
  std::vector<StampedPose> poses{{1, {0, 0, 0}}, {2, {std::nan(""), 0, 0}}};
  std::string error;
  CHECK_FALSE(sdpslam::io::write_trajectory(p, poses, &error));
  CHECK(error.find("pose 1") != std::string::npos);
  STRCMP_EQUAL("old\n", slurp(p).c_str());
}

TEST(TrajectoryFile, reader_skips_comments_and_blank_lines) {
  const std::string p = write_text("c.txt", "# header\n\n  \n1.0 2 3 0.5\r\n  # indented comment\n2.5 4 5 -0.5\n");
  std::vector<StampedPose> back;
  std::string error;
  CHECK_TRUE(sdpslam::io::read_trajectory(p, &back, &error));
  LONGS_EQUAL(2, back.size());
  CHECK_EQUAL(2500000LL, back[1].stamp_us);
  DOUBLES_EQUAL(-0.5, back[1].pose.heading_rad, 0.0);
}

TEST(TrajectoryFile, reader_reports_file_and_line_of_bad_number) {
  const std::string p = write_text("bad.txt", "1.0 2 3 0.5\n2.0 4 x 0.5\n");
  std::vector<StampedPose> back{{7, {}}};
  std::string error;
  CHECK_FALSE(sdpslam::io::read_trajectory(p, &back, &error));
  STRCMP_CONTAINS((p + ":2:").c_str(), error.c_str());
  STRCMP_CONTAINS("'x'", error.c_str());
  LONGS_EQUAL(1, back.size());  // output untouched on failure
}

TEST(TrajectoryFile, reader_reports_wrong_column_count) {
  const std::string p = write_text("cols.txt", "1.0 2 3\n");
  std::vector<StampedPose> back;
  std::string error;
  CHECK_FALSE(sdpslam::io::read_trajectory(p, &back, &error));
  STRCMP_CONTAINS((p + ":1:").c_str(), error.c_str());
  STRCMP_CONTAINS("found 3", error.c_str());
}

TEST(TrajectoryFile, reader_refuses_mixed_formats) {
  const std::string p = write_text("mixed.txt", "1 0 0 0\n2 0 0 0 0 0 0 1\n");
  std::vector<StampedPose> back;
  std::string error;
  CHECK_FALSE(sdpslam::io::read_trajectory(p, &back, &error));
  STRCMP_CONTAINS((p + ":2:").c_str(), error.c_str());
}

TEST(TrajectoryFile, reader_refuses_bad_stamp_and_non_finite_values) {
  std::string error;
  std::vector<StampedPose> back;
  CHECK_FALSE(sdpslam::io::read_trajectory(write_text("s.txt", "1e3 0 0 0\n"), &back, &error));
  STRCMP_CONTAINS("timestamp", error.c_str());
  CHECK_FALSE(sdpslam::io::read_trajectory(write_text("n.txt", "1 inf 0 0\n"), &back, &error));
  STRCMP_CONTAINS(":1:", error.c_str());
}

// Found by fuzz_trajectory: a sine of -0 (qw < 0) made atan2 give -pi, outside (-pi, pi].
TEST(TrajectoryFile, tum_heading_of_a_negative_zero_sine_is_pi) {
  std::istringstream in("-6 2930 8 00 -0 8 00 -1\n");
  std::vector<StampedPose> back;
  std::string error;
  CHECK_TRUE_TEXT(sdpslam::io::read_trajectory(in, "t.txt", &back, &error), error.c_str());
  LONGS_EQUAL(1, back.size());
  DOUBLES_EQUAL(3.14159265358979323846, back[0].pose.heading_rad, 0.0);
}

// Squares of huge components overflowed to inf - inf = NaN; tiny ones vanished into a
// "zero quaternion".
TEST(TrajectoryFile, tum_quaternion_of_huge_or_tiny_components_gives_its_yaw) {
  std::istringstream in("1 0 0 0 0 0 1e200 1e200\n2 0 0 0 0 0 1e-200 1e-200\n");
  std::vector<StampedPose> back;
  std::string error;
  CHECK_TRUE_TEXT(sdpslam::io::read_trajectory(in, "t.txt", &back, &error), error.c_str());
  LONGS_EQUAL(2, back.size());
  DOUBLES_EQUAL(3.14159265358979323846 / 2.0, back[0].pose.heading_rad, 1e-12);
  DOUBLES_EQUAL(3.14159265358979323846 / 2.0, back[1].pose.heading_rad, 1e-12);
}

TEST(TrajectoryFile, reader_of_missing_file_names_it) {
  std::vector<StampedPose> back;
  std::string error;
  CHECK_FALSE(sdpslam::io::read_trajectory(dir + "/none.txt", &back, &error));
  STRCMP_CONTAINS("none.txt", error.c_str());
  STRCMP_CONTAINS("No such file", error.c_str());
}
