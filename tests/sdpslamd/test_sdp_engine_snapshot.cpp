// sdpslamd's snapshots (SlamEngine::save_snapshot / resume_snapshot, Daemon's
// resume_from_snapshot): a restarted daemon continues the session it saved, its encoders'
// odometry starting again from zero; a snapshot of another configuration or a damaged one
// is moved aside and the map starts anew.
#include <CppUTest/TestHarness.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "box_world.h"
#include "sdpslam/daemon/daemon.h"
#include "sdpslam/daemon/slam_engine.h"
#include "shared_data.h"

using sdpslam::daemon::DaemonConfig;

namespace {

using sdpslam::test::box_scan;

DaemonConfig sdp_config(const std::string& dir) {
  DaemonConfig c = sdpslam::test::small_sdp_config();
  c.output_directory = dir;
  c.snapshot_interval_us = 1000000;
  c.slam_fingerprint = 42U;
  return c;
}

// The robot at x = 2 + 0.05 k for k < 60, then standing for a moment (the restart), then
// on along x.
double truth_x(int k) { return 2.0 + 0.05 * (k < 60 ? k : k - 1); }

// Scans `from` .. `to` - 1; the odometry counts from zero again at scan `restart`, as the
// encoders of a restarted daemon do. With clock_restarts, so do the stamps (a power loss:
// the monotonic clock starts again).
void feed(sdpslam::daemon::SlamEngine& e, int from, int to, int restart, bool clock_restarts = false) {
  static sdpslam::RangeScan scan;
  for (int k = from; k < to; ++k) {
    const double x = truth_x(k);
    box_scan(x, 3.0, 1000000 + 100000LL * (clock_restarts && k >= restart ? k - restart : k), &scan);
    const double odom_x = k >= restart ? x - truth_x(restart) : x - 2.0;
    const sdpslam::OdometrySample odom{scan.stamp_us, sdpslam::Pose2{odom_x, 0.0, 0.0}};
    e.process(odom, scan);
  }
}

class NullClock final : public sdpslam::hal::MonotonicClock {
 public:
  std::int64_t now_us() const override { return 0; }
};

bool exists(const std::string& p) {
  std::FILE* f = std::fopen(p.c_str(), "rb");
  if (f != nullptr) std::fclose(f);
  return f != nullptr;
}

// A session of scans 0 .. 59 saved by one engine and resumed by a new one (a restart).
std::unique_ptr<sdpslam::daemon::SlamEngine> resumed_session(const DaemonConfig& c) {
  std::string error;
  {
    auto first = sdpslam::daemon::make_engine(c, &error);
    CHECK_TRUE_TEXT(first != nullptr, error.c_str());
    feed(*first, 0, 60, 1000);
    std::uint64_t bytes = 0U;
    CHECK_TRUE_TEXT(first->save_snapshot(sdpslam::daemon::snapshot_path(c), c.slam_fingerprint, &bytes, &error),
                    error.c_str());
  }
  auto second = sdpslam::daemon::make_engine(c, &error);
  CHECK_TRUE_TEXT(second != nullptr, error.c_str());
  std::uint64_t scans = 0U;
  CHECK_TRUE_TEXT(second->resume_snapshot(sdpslam::daemon::snapshot_path(c), c.slam_fingerprint, &scans, &error),
                  error.c_str());
  LONGS_EQUAL(60, static_cast<long>(scans));
  return second;
}

// The largest position difference between two trajectories of the same scans.
double worst_difference(const std::vector<sdpslam::io::StampedPose>& a, const std::vector<sdpslam::io::StampedPose>& b) {
  LONGS_EQUAL(a.size(), b.size());
  double worst = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    worst = std::fmax(worst, std::hypot(a[k].pose.x_m - b[k].pose.x_m, a[k].pose.y_m - b[k].pose.y_m));
  }
  return worst;
}

}  // namespace

TEST_GROUP(SdpEngineSnapshot){};

// Stopped after 60 scans and started again: the new engine holds the first 60 poses as
// they were, and the robot's next poses continue from where it stood, although the
// encoders count from zero again.
TEST(SdpEngineSnapshot, a_restarted_engine_continues_the_session_from_where_the_robot_stood) {
  const std::string dir = sdpslam::test::make_temp_dir("sdp_engine_snapshot");
  const DaemonConfig c = sdp_config(dir);
  std::string error;
  std::vector<sdpslam::io::StampedPose> before;
  {
    auto first = sdpslam::daemon::make_engine(c, &error);
    CHECK_TRUE_TEXT(first != nullptr, error.c_str());
    CHECK_TRUE(first->has_snapshots());
    feed(*first, 0, 60, 1000);
    before = first->trajectory();
    std::uint64_t bytes = 0U;
    CHECK_TRUE_TEXT(first->save_snapshot(sdpslam::daemon::snapshot_path(c), c.slam_fingerprint, &bytes, &error),
                    error.c_str());
    CHECK(bytes > 1000U);
  }
  auto second = sdpslam::daemon::make_engine(c, &error);
  CHECK_TRUE_TEXT(second != nullptr, error.c_str());
  NullClock clock;
  std::FILE* log_file = std::tmpfile();
  sdpslam::daemon::EventLog log(clock, 0, log_file);
  CHECK_TRUE(sdpslam::daemon::resume_from_snapshot(c, *second, log) == sdpslam::daemon::ResumeOutcome::kResumed);
  std::fclose(log_file);
  const std::vector<sdpslam::io::StampedPose> resumed = second->trajectory();
  LONGS_EQUAL(before.size(), resumed.size());
  for (std::size_t k = 0; k < before.size(); ++k) {
    LONGS_EQUAL(before[k].stamp_us, resumed[k].stamp_us);
    CHECK(before[k].pose.x_m == resumed[k].pose.x_m && before[k].pose.y_m == resumed[k].pose.y_m);
  }
  feed(*second, 60, 120, 60);
  const std::vector<sdpslam::io::StampedPose> after = second->trajectory();
  LONGS_EQUAL(120, static_cast<long>(after.size()));
  // The same session uninterrupted (the encoders counting on): the restart changes the
  // odometry's origin only, which the engine carries over, so the poses agree to
  // rounding.
  auto whole = sdpslam::daemon::make_engine(c, &error);
  feed(*whole, 0, 120, 1000);
  const double worst = worst_difference(after, whole->trajectory());
  CHECK_TEXT(worst < 1e-6, ("resumed and uninterrupted differ by up to " + std::to_string(worst) + " m").c_str());
  // And the robot went on: the last pose is metres from the one at the restart.
  CHECK(after.back().pose.x_m - after[60].pose.x_m > 2.0);
}

// After a power loss the monotonic clock starts again: the new scans are stamped before
// the session's last. They are moved to follow it (the session's paths are in time
// order), and the robot goes on as if the clock had run on.
TEST(SdpEngineSnapshot, a_clock_that_started_again_does_not_break_the_session_s_time_order) {
  const DaemonConfig c = sdp_config(sdpslam::test::make_temp_dir("sdp_engine_clock"));
  auto second = resumed_session(c);
  feed(*second, 60, 120, 60, true);
  const std::vector<sdpslam::io::StampedPose> after = second->trajectory();
  LONGS_EQUAL(120, static_cast<long>(after.size()));
  for (std::size_t k = 1; k < after.size(); ++k) CHECK(after[k].stamp_us > after[k - 1].stamp_us);
  // The first new scan one second after the session's last.
  LONGS_EQUAL(after[59].stamp_us + 1000000, after[60].stamp_us);
  const sdpslam::io::Json js = second->status_json();
  STRCMP_EQUAL("in place", js["resumed"]["place"].get<std::string>().c_str());
  std::string error;
  auto whole = sdpslam::daemon::make_engine(c, &error);
  feed(*whole, 0, 120, 1000);
  const double worst = worst_difference(after, whole->trajectory());
  CHECK_TEXT(worst < 1e-6, ("resumed and uninterrupted differ by up to " + std::to_string(worst) + " m").c_str());
}

// Pushed 0.6 m on while sdpslamd was off: the first scan after the restart fits the saved
// map there, unambiguously (the box's far wall pins the distance), so the session goes on
// from there rather than from where it stopped; odometry alone could not know.
TEST(SdpEngineSnapshot, a_robot_pushed_while_off_goes_on_where_its_first_scan_fits) {
  auto second = resumed_session(sdp_config(sdpslam::test::make_temp_dir("sdp_engine_pushed")));
  static sdpslam::RangeScan scan;
  const double pushed_x = truth_x(59) + 0.6;
  for (int j = 0; j < 40; ++j) {
    const double x = pushed_x + 0.05 * j;
    box_scan(x, 3.0, 1000000 + 100000LL * (60 + j), &scan);
    CHECK_TRUE(second->process(sdpslam::OdometrySample{scan.stamp_us, sdpslam::Pose2{0.05 * j, 0.0, 0.0}}, scan).placed);
  }
  const sdpslam::io::Json js = second->status_json();
  STRCMP_EQUAL("in place", js["resumed"]["place"].get<std::string>().c_str());
  DOUBLES_EQUAL(0.6, js["resumed"]["moved_m"].get<double>(), 0.1);
  // The map frame is the first scan's pose (x = 2): every pose after the push within a
  // decimetre of the truth.
  const std::vector<sdpslam::io::StampedPose> after = second->trajectory();
  LONGS_EQUAL(100, static_cast<long>(after.size()));
  double worst = 0.0;
  for (int j = 0; j < 40; ++j) {
    const sdpslam::Pose2& p = after[static_cast<std::size_t>(60 + j)].pose;
    worst = std::fmax(worst, std::hypot(p.x_m - (pushed_x + 0.05 * j - 2.0), p.y_m));
  }
  CHECK_TEXT(worst < 0.1, ("after the push the poses are up to " + std::to_string(worst) + " m off").c_str());
}

// Another configuration's snapshot, or one damaged on the way (a flipped byte), is not
// read into the engine: it is moved aside, kept for inspection, and the caller starts a
// new map. No snapshot at all: a fresh start.
TEST(SdpEngineSnapshot, a_foreign_or_damaged_snapshot_is_kept_aside_and_the_map_starts_anew) {
  const std::string dir = sdpslam::test::make_temp_dir("sdp_engine_snapshot_refused");
  DaemonConfig c = sdp_config(dir);
  std::string error;
  NullClock clock;
  std::FILE* log_file = std::tmpfile();
  sdpslam::daemon::EventLog log(clock, 0, log_file);
  const std::string path = sdpslam::daemon::snapshot_path(c);
  {
    auto e = sdpslam::daemon::make_engine(c, &error);
    CHECK_TRUE(sdpslam::daemon::resume_from_snapshot(c, *e, log) == sdpslam::daemon::ResumeOutcome::kFresh);
    feed(*e, 0, 30, 1000);
    std::uint64_t bytes = 0U;
    CHECK_TRUE_TEXT(e->save_snapshot(path, c.slam_fingerprint, &bytes, &error), error.c_str());
  }
  {  // other options
    DaemonConfig other = c;
    other.slam_fingerprint = 43U;
    auto e = sdpslam::daemon::make_engine(other, &error);
    std::uint64_t scans = 0U;
    CHECK_FALSE(e->resume_snapshot(path, other.slam_fingerprint, &scans, &error));
    STRCMP_CONTAINS("another configuration", error.c_str());
    CHECK_TRUE(sdpslam::daemon::resume_from_snapshot(other, *e, log) == sdpslam::daemon::ResumeOutcome::kRefused);
    CHECK_FALSE(exists(path));
    CHECK_TRUE(exists(path + ".refused"));
    CHECK_EQUAL(0, std::rename((path + ".refused").c_str(), path.c_str()));
  }
  {  // a byte flipped in the middle
    std::FILE* f = std::fopen(path.c_str(), "r+b");
    CHECK(f != nullptr);
    std::fseek(f, 0, SEEK_END);
    const long size = std::ftell(f);
    std::fseek(f, size / 2, SEEK_SET);
    const int ch = std::fgetc(f);
    std::fseek(f, size / 2, SEEK_SET);
    std::fputc(ch ^ 0x10, f);
    std::fclose(f);
    auto e = sdpslam::daemon::make_engine(c, &error);
    std::uint64_t scans = 0U;
    CHECK_FALSE(e->resume_snapshot(path, c.slam_fingerprint, &scans, &error));
    STRCMP_CONTAINS("CRC-32 mismatch", error.c_str());
  }
  {  // cut short
    std::FILE* f = std::fopen(path.c_str(), "r+b");
    std::fseek(f, 0, SEEK_END);
    const long size = std::ftell(f);
    std::fclose(f);
    CHECK_EQUAL(0, ::truncate(path.c_str(), size - 100));
    auto e = sdpslam::daemon::make_engine(c, &error);
    std::uint64_t scans = 0U;
    CHECK_FALSE(e->resume_snapshot(path, c.slam_fingerprint, &scans, &error));
    STRCMP_CONTAINS("cut short or corrupt", error.c_str());
  }
  std::fclose(log_file);
}

// The live pose's covariance (SlamEngine::spread(), [output] pose_socket): the bottom-level
// particles' spread, a covariance matrix (non-negative variances, |cov| within them), of
// the size scan matching leaves (centimetres) after the particles have spread and
// converged along a box.
TEST(SdpEngineSnapshot, the_estimate_s_spread_is_a_covariance_of_centimetres) {
  const DaemonConfig c = sdp_config(sdpslam::test::make_temp_dir("sdp_engine_spread"));
  std::string error;
  auto e = sdpslam::daemon::make_engine(c, &error);
  CHECK_TRUE_TEXT(e != nullptr, error.c_str());
  feed(*e, 0, 40, 1000);
  const sdpslam::daemon::PoseSpread s = e->spread();
  CHECK(s.var_x >= 0.0 && s.var_y >= 0.0 && s.var_heading >= 0.0);
  CHECK(s.cov_xy * s.cov_xy <= s.var_x * s.var_y * (1.0 + 1e-9));
  CHECK(s.var_x + s.var_y > 0.0);            // the particles are not one
  CHECK(s.var_x + s.var_y < 0.1 * 0.1);      // within decimetres of each other
  CHECK(s.var_heading < 0.1 * 0.1);
}
