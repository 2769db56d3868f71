// Replay on the shared real logs: the tinySLAM run's real wheel ticks through CANopen
// frames integrate to the same pose as the LogReader's own integration, and an Intel
// CARMEN log's odometry survives poses -> ticks -> frames -> odometry.
#include <cmath>
#include <cstdio>

#include "CppUTest/TestHarness.h"
#include "sdpslam/replay/encoder_frames.h"
#include "sdpslam/replay/replay_log.h"
#include "sdpslam/replay/tinyslam_ticks.h"
#include "shared_data.h"

using namespace sdpslam;
using namespace sdpslam::replay;

TEST_GROUP(ReplayRealLogs){};

TEST(ReplayRealLogs, tinyslam_real_ticks_through_canopen_frames_match_the_log_reader_odometry) {
  const std::string path = test::shared_path("datasets/tinyslam-exp2.dat");
  TinySlamTicks t;
  std::string error;
  CHECK_TRUE_TEXT(read_tinyslam_ticks(path, &t, &error), error.c_str());
  LONGS_EQUAL(0, t.errors.size());
  EncoderFrameOptions o;  // MinesRover defaults: 2000 ticks/rev, r 77 mm, axle 330 mm
  std::vector<drivers::CandumpRecord> frames;
  CHECK_TRUE(tick_track_to_frames(t.samples, o, &frames, &error));
  LONGS_EQUAL(3 * t.samples.size(), frames.size());
  Pose2 from_frames;
  LONGS_EQUAL(t.samples.size(), integrate_canopen_frames(frames, o.params, 1, 2, &from_frames));
  ReplayLog log;
  CHECK_TRUE(load_replay_log(path, &log, &error));
  LONGS_EQUAL(t.samples.size(), log.scans.size());
  const Pose2 reader = log.odometry.back().pose;
  const double d = std::hypot(from_frames.x_m - reader.x_m, from_frames.y_m - reader.y_m);
  std::printf("\ntinyslam-exp2: %zu samples, frames pose (%.4f %.4f %.4f), LogReader (%.4f %.4f %.4f), |d| %.2e m\n",
              t.samples.size(), from_frames.x_m, from_frames.y_m, from_frames.heading_rad, reader.x_m, reader.y_m,
              reader.heading_rad, d);
  CHECK_TRUE(d < 0.01);
  CHECK_TRUE(std::fabs(normalize_angle_rad(from_frames.heading_rad - reader.heading_rad)) < 0.01);
}

TEST(ReplayRealLogs, carmen_odometry_survives_ticks_and_frames_within_centimetres) {
  const std::string path = test::shared_path("datasets/aces.clf");
  ReplayLog log;
  std::string error;
  CHECK_TRUE(load_replay_log(path, &log, &error));
  std::vector<StampedPose> first(log.odometry.begin(), log.odometry.begin() + 600);  // ~1 min
  drivers::DiffDriveParams params;
  std::vector<TickSample> track;
  std::size_t dropped = 0;
  CHECK_TRUE(poses_to_tick_track(first, params, 10000, &track, &dropped, &error));
  EncoderFrameOptions o;
  std::vector<drivers::CandumpRecord> frames;
  CHECK_TRUE(tick_track_to_frames(track, o, &frames, &error));
  Pose2 p;
  integrate_canopen_frames(frames, params, 1, 2, &p);
  // The log's frame starts at its first pose; the odometry at (0,0,0).
  const Pose2 want = between(first.front().pose, interpolate_pose(first, track.back().stamp_us));
  const double d = std::hypot(p.x_m - want.x_m, p.y_m - want.y_m);
  std::printf("\naces.clf first %zu ODOM: %zu samples, dropped %zu, end error %.4f m, %.5f rad\n", first.size(),
              track.size(), dropped, d, normalize_angle_rad(p.heading_rad - want.heading_rad));
  CHECK_TRUE(d < 0.05);
}
