// Encoder frames from logs: inverse kinematics round trip, candump output read back with
// CandumpReader and decoded, counter wrap, ODrive payloads, the tinySLAM tick reader.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "CppUTest/TestHarness.h"
#include "sdpslam/drivers/canopen_codec.h"
#include "sdpslam/drivers/odrive_codec.h"
#include "sdpslam/replay/encoder_frames.h"
#include "sdpslam/replay/tinyslam_ticks.h"
#include "shared_data.h"

using namespace sdpslam;
using namespace sdpslam::replay;

namespace {

constexpr double kPi = 3.14159265358979323846;

// A robot driving arcs and straights, one pose every 100 ms (like CARMEN ODOM at 10 Hz).
std::vector<StampedPose> arc_track(std::size_t n) {
  std::vector<StampedPose> v;
  Pose2 p;
  for (std::size_t i = 0; i < n; ++i) {
    v.push_back(StampedPose{1000000000 + static_cast<std::int64_t>(i) * 100000, p});
    const double v_mps = 0.5, w_radps = (i / 20) % 2 == 0 ? 0.6 : -0.3;
    const double dt = 0.1, th = p.heading_rad;
    p.x_m += v_mps * dt * std::cos(th + w_radps * dt / 2.0);
    p.y_m += v_mps * dt * std::sin(th + w_radps * dt / 2.0);
    p.heading_rad = normalize_angle_rad(th + w_radps * dt);
  }
  return v;
}

std::string temp_file(const char* name) { return test::make_temp_dir("replay") + "/" + name; }

}  // namespace

TEST_GROUP(ReplayFrames){};

TEST(ReplayFrames, ticks_from_poses_integrate_back_to_the_poses_within_a_tick) {
  const std::vector<StampedPose> poses = arc_track(100);
  drivers::DiffDriveParams params;
  std::vector<TickSample> track;
  std::size_t dropped = 9;
  std::string error;
  CHECK_TRUE(poses_to_tick_track(poses, params, 10000, &track, &dropped, &error));
  LONGS_EQUAL(0, dropped);
  LONGS_EQUAL(991, track.size());  // 9.9 s at 10 ms, both ends included
  drivers::DiffDriveOdometry odom(params);
  const double tick_m = 2.0 * kPi * params.left_radius_m / params.ticks_per_rev;
  double worst_m = 0.0, worst_rad = 0.0;
  for (const TickSample& s : track) {
    odom.update(static_cast<std::uint32_t>(s.left_ticks), static_cast<std::uint32_t>(s.right_ticks), s.stamp_us);
    const Pose2 want = interpolate_pose(poses, s.stamp_us);
    worst_m = std::fmax(worst_m, std::hypot(odom.pose().x_m - want.x_m, odom.pose().y_m - want.y_m));
    worst_rad = std::fmax(worst_rad, std::fabs(normalize_angle_rad(odom.pose().heading_rad - want.heading_rad)));
  }
  // Heading is held by the cumulative ticks to one tick per wheel; position within a few
  // ticks after 5 m of arcs (the interpolated track is not exactly arc-shaped).
  CHECK_TRUE(worst_rad <= 2.0 * tick_m / params.wheel_separation_m);
  CHECK_TRUE(worst_m < 10.0 * tick_m);
}

TEST(ReplayFrames, non_increasing_pose_stamps_are_dropped_and_counted) {
  std::vector<StampedPose> poses = arc_track(10);
  poses.insert(poses.begin() + 5, poses[4]);  // repeated stamp
  std::vector<TickSample> track;
  std::size_t dropped = 0;
  std::string error;
  CHECK_TRUE(poses_to_tick_track(poses, drivers::DiffDriveParams{}, 100000, &track, &dropped, &error));
  LONGS_EQUAL(1, dropped);
  LONGS_EQUAL(10, track.size());
}

TEST(ReplayFrames, invalid_wheel_parameters_are_refused_with_a_reason) {
  drivers::DiffDriveParams params;
  params.wheel_separation_m = 0.0;
  std::vector<TickSample> track;
  std::size_t dropped = 0;
  std::string error;
  CHECK_FALSE(poses_to_tick_track(arc_track(5), params, 10000, &track, &dropped, &error));
  CHECK_TRUE(error.find("wheel") != std::string::npos);
}

TEST(ReplayFrames, interpolation_takes_the_short_way_across_pi) {
  std::vector<StampedPose> poses = {{0, Pose2{0, 0, 3.0}}, {1000, Pose2{1, 0, -3.0}}};
  const Pose2 mid = interpolate_pose(poses, 500);
  DOUBLES_EQUAL(0.5, mid.x_m, 1e-12);
  DOUBLES_EQUAL(kPi, std::fabs(mid.heading_rad), 1e-9);
}

TEST(ReplayFrames, canopen_candump_reads_back_as_sync_then_both_positions_per_sample) {
  std::vector<TickSample> track = {{5000000, 0, 0}, {5010000, -3, 4}, {5020000, -7, 9}};
  EncoderFrameOptions o;
  std::vector<drivers::CandumpRecord> frames;
  std::string error;
  CHECK_TRUE(tick_track_to_frames(track, o, &frames, &error));
  const std::string path = temp_file("canopen.candump");
  CHECK_TRUE(write_candump_file(path, frames, &error));
  drivers::CandumpReader reader;
  CHECK_TRUE(reader.open(path.c_str()));
  drivers::CandumpRecord rec;
  for (const TickSample& s : track) {
    LONGS_EQUAL(1, reader.next(rec));
    CHECK_TRUE(drivers::canopen::decode_sync(rec.frame) == drivers::CanDecodeError::kOk);
    LONGS_EQUAL(s.stamp_us, rec.stamp_us);
    std::uint32_t pos = 0;
    LONGS_EQUAL(1, reader.next(rec));
    CHECK_TRUE(drivers::canopen::decode_tpdo1_position(rec.frame, 1, 4, pos) == drivers::CanDecodeError::kOk);
    LONGS_EQUAL(static_cast<std::uint32_t>(s.left_ticks), pos);  // negative ticks wrap modulo 2^32
    LONGS_EQUAL(1, reader.next(rec));
    CHECK_TRUE(drivers::canopen::decode_tpdo1_position(rec.frame, 2, 4, pos) == drivers::CanDecodeError::kOk);
    LONGS_EQUAL(static_cast<std::uint32_t>(s.right_ticks), pos);
    STRCMP_EQUAL("can0", rec.interface_name);
  }
  LONGS_EQUAL(0, reader.next(rec));
  LONGS_EQUAL(0, reader.errors());
}

TEST(ReplayFrames, wheel_motion_decoded_from_the_candump_equals_the_track_across_the_wrap) {
  const std::vector<StampedPose> poses = arc_track(60);
  drivers::DiffDriveParams params;
  std::vector<TickSample> track;
  std::size_t dropped = 0;
  std::string error;
  CHECK_TRUE(poses_to_tick_track(poses, params, 10000, &track, &dropped, &error));
  for (TickSample& s : track) {  // start just below the u32 wrap, as a long-running encoder
    s.left_ticks += 4294967000LL;
    s.right_ticks += 4294967000LL;
  }
  EncoderFrameOptions o;
  o.with_sync = false;
  std::vector<drivers::CandumpRecord> frames;
  CHECK_TRUE(tick_track_to_frames(track, o, &frames, &error));
  LONGS_EQUAL(2 * track.size(), frames.size());  // no SYNC
  Pose2 from_frames;
  LONGS_EQUAL(track.size(), integrate_canopen_frames(frames, params, 1, 2, &from_frames));
  drivers::DiffDriveOdometry direct(params);
  for (const TickSample& s : track) {
    direct.update(static_cast<std::uint32_t>(s.left_ticks), static_cast<std::uint32_t>(s.right_ticks), s.stamp_us);
  }
  DOUBLES_EQUAL(direct.pose().x_m, from_frames.x_m, 0.0);
  DOUBLES_EQUAL(direct.pose().heading_rad, from_frames.heading_rad, 0.0);
  const Pose2 end = poses.back().pose;
  CHECK_TRUE(std::hypot(from_frames.x_m - end.x_m, from_frames.y_m - end.y_m) < 0.003);
}

TEST(ReplayFrames, odrive_frames_carry_turns_and_turns_per_second) {
  std::vector<TickSample> track = {{0, 0, 0}, {10000, 200, -100}};
  EncoderFrameOptions o;
  o.protocol = drivers::EncoderProtocol::kODrive;
  o.left_node = 3;
  o.right_node = 4;
  std::vector<drivers::CandumpRecord> frames;
  std::string error;
  CHECK_TRUE(tick_track_to_frames(track, o, &frames, &error));
  LONGS_EQUAL(4, frames.size());
  drivers::odrive::EncoderEstimates e;
  CHECK_TRUE(drivers::odrive::decode_encoder_estimates(frames[2].frame, 3, e) == drivers::CanDecodeError::kOk);
  DOUBLES_EQUAL(0.1, e.pos_turns, 1e-7);
  DOUBLES_EQUAL(10.0, e.vel_turns_s, 1e-5);
  CHECK_TRUE(drivers::odrive::decode_encoder_estimates(frames[3].frame, 4, e) == drivers::CanDecodeError::kOk);
  DOUBLES_EQUAL(-0.05, e.pos_turns, 1e-7);
  DOUBLES_EQUAL(-5.0, e.vel_turns_s, 1e-5);
}

// Found by fuzz_tinyslam_ticks: raw counters INT64_MAX and INT64_MIN one sample apart
// overflowed their int64 difference (undefined behaviour; a wrapped +1 tick). Stamps near
// 5e18 lie 1024 µs apart in double: their step must be taken exactly.
TEST(ReplayFrames, odrive_velocity_of_counters_and_stamps_far_apart_is_finite_and_signed) {
  std::vector<TickSample> track = {{1, 9223372036854775807LL, -9223372036854775807LL - 1},
                                   {2, -9223372036854775807LL - 1, 9223372036854775807LL},
                                   {4963744073704775807LL, 0, 0},
                                   {4963744073704775824LL, 17, -17}};
  EncoderFrameOptions o;
  o.protocol = drivers::EncoderProtocol::kODrive;
  std::vector<drivers::CandumpRecord> frames;
  std::string error;
  CHECK_TRUE(tick_track_to_frames(track, o, &frames, &error));
  LONGS_EQUAL(8, frames.size());
  drivers::odrive::EncoderEstimates e;
  CHECK_TRUE(drivers::odrive::decode_encoder_estimates(frames[2].frame, o.left_node, e) == drivers::CanDecodeError::kOk);
  DOUBLES_EQUAL(-18446744073709551615.0 / 2000.0 / 1e-6, e.vel_turns_s, 1e16);
  CHECK_TRUE(drivers::odrive::decode_encoder_estimates(frames[3].frame, o.right_node, e) == drivers::CanDecodeError::kOk);
  DOUBLES_EQUAL(18446744073709551615.0 / 2000.0 / 1e-6, e.vel_turns_s, 1e16);
  CHECK_TRUE(drivers::odrive::decode_encoder_estimates(frames[6].frame, o.left_node, e) == drivers::CanDecodeError::kOk);
  DOUBLES_EQUAL(17.0 / 2000.0 / 17e-6, e.vel_turns_s, 1e-3);
  CHECK_TRUE(drivers::odrive::decode_encoder_estimates(frames[7].frame, o.right_node, e) == drivers::CanDecodeError::kOk);
  DOUBLES_EQUAL(-17.0 / 2000.0 / 17e-6, e.vel_turns_s, 1e-3);
}

TEST(ReplayFrames, out_of_range_or_equal_node_ids_are_refused) {
  std::vector<TickSample> track = {{0, 0, 0}};
  EncoderFrameOptions o;
  o.protocol = drivers::EncoderProtocol::kODrive;
  o.left_node = 64;  // ODrive ids have 6 bits
  std::vector<drivers::CandumpRecord> frames;
  std::string error;
  CHECK_FALSE(tick_track_to_frames(track, o, &frames, &error));
  o.left_node = o.right_node = 2;
  CHECK_FALSE(tick_track_to_frames(track, o, &frames, &error));
}

TEST(ReplayFrames, tinyslam_reader_keeps_good_lines_and_names_bad_ones) {
  const std::string path = temp_file("t.dat");
  {
    std::ofstream f(path);
    f << "100 7 10 20 0 0 5\n";
    f << "200 7 x 21 0\n";            // bad tick
    f << "300 7 15 30 1 2\n";
    f << "250 7 16 31 1 2\n";          // stamp goes back
    f << "\n";
    f << "400 7 4294967296 -5 1\n";
  }
  TinySlamTicks t;
  std::string error;
  CHECK_TRUE(read_tinyslam_ticks(path, &t, &error));
  LONGS_EQUAL(3, t.samples.size());
  LONGS_EQUAL(2, t.errors.size());
  CHECK_TRUE(t.errors[0].find(path + ":2:") == 0);
  CHECK_TRUE(t.errors[1].find(path + ":4:") == 0);
  LONGS_EQUAL(15, t.samples[1].left_ticks);
  LONGS_EQUAL(30, t.samples[1].right_ticks);
  CHECK_EQUAL(4294967296LL, t.samples[2].left_ticks);
  LONGS_EQUAL(-5, t.samples[2].right_ticks);
}

// Found by fuzz_tinyslam_ticks: the parser stops at a NUL byte, so a line holding one was
// read as what came before it (or, starting with one, skipped as blank, unreported).
TEST(ReplayFrames, tinyslam_reader_lists_a_line_holding_a_nul_byte_as_an_error) {
  const char text[] = "100 7 10 20 0 0\n200 7 11 21 0 3\x13\0\0p`\n\0 7 12 22\n300 7 13 23\n";
  std::string data(text, sizeof text - 1U);
  std::FILE* f = ::fmemopen(&data[0], data.size(), "r");
  CHECK(f != nullptr);
  TinySlamTicks t;
  std::string error;
  CHECK_TRUE_TEXT(read_tinyslam_ticks(f, "t.dat", &t, &error), error.c_str());
  std::fclose(f);
  LONGS_EQUAL(2, t.samples.size());
  LONGS_EQUAL(300, t.samples[1].stamp_us);
  LONGS_EQUAL(2, t.errors.size());
  STRCMP_EQUAL("t.dat:2: NUL byte in the line (not a text file?)", t.errors[0].c_str());
  STRCMP_EQUAL("t.dat:3: NUL byte in the line (not a text file?)", t.errors[1].c_str());
}

TEST(ReplayFrames, tinyslam_reader_fails_on_a_missing_file) {
  TinySlamTicks t;
  std::string error;
  CHECK_FALSE(read_tinyslam_ticks("/nonexistent/exp2.dat", &t, &error));
  CHECK_TRUE(error.find("/nonexistent/exp2.dat") != std::string::npos);
}
