// smooth_with_odometry (firmware-host/runtime/slam/slam_outputs.h): the scan-to-scan
// jitter of processed poses is averaged out through the odometry, what the map fixed
// over longer stretches stays, and odometry that disagrees is left out.
#include <CppUTest/TestHarness.h>

#include <cmath>
#include <vector>

#include "sdpslam/slam/slam_outputs.h"

using sdpslam::Pose2;
using sdpslam::io::StampedPose;
using sdpslam::slam::ScanRecord;
using sdpslam::slam::smooth_with_odometry;

namespace {

// A robot driving 0.05 m per scan along a gentle arc for `n` scans, with its odometry
// exact: scans (stamp, odometry) and the true poses.
struct Drive {
  std::vector<ScanRecord> scans;
  std::vector<StampedPose> truth;
};

Drive drive(std::size_t n) {
  Drive d;
  Pose2 p{2.0, -1.0, 0.4};
  for (std::size_t i = 0; i < n; ++i) {
    const std::int64_t stamp = 1000000 + static_cast<std::int64_t>(i) * 100000;
    d.scans.push_back(ScanRecord{stamp, p, p, i % 4 == 0});
    d.truth.push_back({stamp, p});
    p = p.compose(Pose2{0.05, 0.0, 0.004});
  }
  return d;
}

// Every processed scan (one in four) placed `jitter_m` off to its left or right and
// `jitter_rad` off in heading, alternately, the three scans after it following it by
// the odometry: as assemble_trajectory() makes a trajectory of a jittery match.
std::vector<StampedPose> jittered(const Drive& d, double jitter_m, double jitter_rad) {
  std::vector<StampedPose> t = d.truth;
  Pose2 anchor;
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (d.scans[i].processed) {
      const double s = (i / 4) % 2 == 0 ? 1.0 : -1.0;
      anchor = d.truth[i].pose.compose(Pose2{0.0, s * jitter_m, s * jitter_rad});
      t[i].pose = anchor;
    } else {
      t[i].pose = t[i - 1].pose.compose(sdpslam::between(d.scans[i - 1].odom, d.scans[i].odom));
    }
  }
  return t;
}

double max_position_error_m(const std::vector<StampedPose>& a, const std::vector<StampedPose>& b, std::size_t from,
                            std::size_t to) {
  double worst = 0.0;
  for (std::size_t i = from; i < to; ++i) {
    worst = std::fmax(worst, std::hypot(a[i].pose.x_m - b[i].pose.x_m, a[i].pose.y_m - b[i].pose.y_m));
  }
  return worst;
}

}  // namespace

TEST_GROUP(TrajectorySmoothing){};

TEST(TrajectorySmoothing, the_jitter_of_processed_poses_is_averaged_out_through_the_odometry) {
  const Drive d = drive(400);  // 20 m
  const std::vector<StampedPose> t = jittered(d, 0.02, 0.005);
  const std::vector<StampedPose> s = smooth_with_odometry(d.scans, t);
  LONGS_EQUAL(t.size(), s.size());
  // Away from the ends (a window's reach), the 2 cm and 0.3 deg jitter mostly cancels.
  const double before = max_position_error_m(t, d.truth, 40, 360);
  const double after = max_position_error_m(s, d.truth, 40, 360);
  CHECK(before > 0.019);
  CHECK_TRUE(after < 0.25 * before);
  for (std::size_t i = 40; i < 360; ++i) {
    const double dh = std::fabs(sdpslam::normalize_angle_rad(s[i].pose.heading_rad - d.truth[i].pose.heading_rad));
    CHECK_TRUE(dh < 0.0015);
    LONGS_EQUAL(t[i].stamp_us, s[i].stamp_us);
  }
}

TEST(TrajectorySmoothing, what_the_map_fixed_over_longer_stretches_stays) {
  // The trajectory leaves the odometry by a lateral offset growing 1 cm per metre (the
  // map's correction of a drift): a stretch of a metre shows no jitter to remove.
  const Drive d = drive(400);
  std::vector<StampedPose> t = d.truth;
  for (std::size_t i = 0; i < t.size(); ++i) {
    t[i].pose = t[i].pose.compose(Pose2{0.0, 0.01 * 0.05 * static_cast<double>(i), 0.0});
  }
  const std::vector<StampedPose> s = smooth_with_odometry(d.scans, t);
  CHECK_TRUE(max_position_error_m(s, t, 40, 360) < 0.001);
}

TEST(TrajectorySmoothing, odometry_that_disagrees_is_left_out) {
  // A wheel slip: the odometry jumps 1 m at scan 200 (its frame moves), the robot does not.
  Drive d = drive(400);
  for (std::size_t i = 200; i < d.scans.size(); ++i) d.scans[i].odom = Pose2{1.0, 0.0, 0.0}.compose(d.scans[i].odom);
  const std::vector<StampedPose> s = smooth_with_odometry(d.scans, d.truth);
  // Neighbours across the jump would put each pose a metre off: none is averaged in.
  const double moved = max_position_error_m(s, d.truth, 0, d.truth.size());
  DOUBLES_EQUAL(0.0, moved, 1e-9);
}

TEST(TrajectorySmoothing, a_trajectory_that_is_not_one_pose_per_scan_is_returned_unchanged) {
  const Drive d = drive(100);
  const std::vector<StampedPose> t = jittered(d, 0.02, 0.005);
  std::vector<StampedPose> shorter(t.begin(), t.end() - 1);
  const std::vector<StampedPose> s = smooth_with_odometry(d.scans, shorter);
  LONGS_EQUAL(shorter.size(), s.size());
  CHECK_TRUE(max_position_error_m(s, shorter, 0, shorter.size()) == 0.0);
  std::vector<StampedPose> other = t;
  other[50].stamp_us += 1;
  CHECK_TRUE(max_position_error_m(smooth_with_odometry(d.scans, other), other, 0, other.size()) == 0.0);
}
