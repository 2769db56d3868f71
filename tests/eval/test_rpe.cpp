// Relative pose error over a travelled distance: invariant to the frame, exact on a
// uniformly scaled copy, and silent on a path shorter than the stretch.
#include <CppUTest/TestHarness.h>

#include <cmath>
#include <vector>

#include "sdpslam/eval/rpe.h"

using sdpslam::Pose2;
using sdpslam::io::StampedPose;

namespace {
// Steps of 0.125 m, so that path lengths add up exactly.
constexpr double kStepM = 0.125;

// 30 m straight along x, then a quarter turn and 10 m along y.
std::vector<StampedPose> corridor() {
  std::vector<StampedPose> p;
  std::int64_t t = 0;
  for (int i = 0; i <= 240; ++i) p.push_back({t++ * 100000, {kStepM * i, 0.0, 0.0}});
  for (int i = 1; i <= 80; ++i) p.push_back({t++ * 100000, {30.0, kStepM * i, 0.5 * 3.14159265358979323846}});
  return p;
}
}  // namespace

TEST_GROUP(Rpe){};

TEST(Rpe, a_rigidly_moved_copy_has_no_relative_error) {
  const auto gt = corridor();
  auto est = gt;
  const Pose2 frame{4.0, -3.0, 2.1};
  for (auto& p : est) p.pose = frame.compose(p.pose);
  sdpslam::eval::RpeResult r;
  CHECK_TRUE(sdpslam::eval::compute_rpe(est, gt, 1000, 10.0, &r));
  LONGS_EQUAL(gt.size(), r.matched_count);
  CHECK(r.stretch_count > 0U);
  DOUBLES_EQUAL(0.0, r.max_m, 1e-9);
  DOUBLES_EQUAL(0.0, r.heading_mean_rad, 1e-9);
  DOUBLES_EQUAL(0.0, r.scale_error, 1e-12);
}

TEST(Rpe, a_path_two_percent_short_has_that_scale_error_and_drift) {
  // The estimate covers 98 % of every step: each stretch comes out 2 % short along its
  // own direction, whatever the heading: 0.2 m on the straight 10 m stretches, less on
  // those that cut the corner.
  const auto gt = corridor();
  auto est = gt;
  for (auto& p : est) {
    p.pose.x_m *= 0.98;
    p.pose.y_m *= 0.98;
  }
  sdpslam::eval::RpeResult r;
  CHECK_TRUE(sdpslam::eval::compute_rpe(est, gt, 1000, 10.0, &r));
  DOUBLES_EQUAL(-0.02, r.scale_error, 1e-6);
  DOUBLES_EQUAL(0.2, r.max_m, 1e-9);
  CHECK(r.mean_m > 0.14 && r.mean_m < 0.2);
  DOUBLES_EQUAL(0.0, r.heading_mean_rad, 1e-9);
  // Every start with 10 m of path ahead of it (path 0 .. 30 m), and no other.
  LONGS_EQUAL(241U, r.stretch_count);
}

TEST(Rpe, a_heading_error_shows_as_heading_and_sideways_drift) {
  // The estimate turns 0.01 rad per metre to the left of a straight path.
  std::vector<StampedPose> gt;
  std::vector<StampedPose> est;
  for (int i = 0; i <= 160; ++i) {
    const double s = kStepM * i;
    gt.push_back({i * 100000, {s, 0.0, 0.0}});
    const double k = 0.01;
    est.push_back({i * 100000, {std::sin(k * s) / k, (1.0 - std::cos(k * s)) / k, k * s}});
  }
  sdpslam::eval::RpeResult r;
  CHECK_TRUE(sdpslam::eval::compute_rpe(est, gt, 1000, 10.0, &r));
  DOUBLES_EQUAL(0.1, r.heading_mean_rad, 1e-9);
  // Over 10 m the arc ends (1 − cos 0.1)/0.01 ≈ 0.4996 m to the side.
  DOUBLES_EQUAL(std::hypot(std::sin(0.1) / 0.01 - 10.0, (1.0 - std::cos(0.1)) / 0.01), r.mean_m, 1e-9);
}

TEST(Rpe, a_path_shorter_than_the_stretch_is_not_measured) {
  std::vector<StampedPose> gt;
  for (int i = 0; i < 50; ++i) gt.push_back({i * 100000, {kStepM * i, 0.0, 0.0}});
  sdpslam::eval::RpeResult r;
  CHECK_FALSE(sdpslam::eval::compute_rpe(gt, gt, 1000, 10.0, &r));
  LONGS_EQUAL(50U, r.matched_count);
  LONGS_EQUAL(0U, r.stretch_count);
  CHECK_FALSE(sdpslam::eval::compute_rpe(gt, gt, 1000, 0.0, &r));
}

TEST(Rpe, only_poses_with_ground_truth_count) {
  const auto gt = corridor();
  auto est = gt;
  for (auto& p : est) p.stamp_us += 5000000000LL;  // no stamp in common
  sdpslam::eval::RpeResult r;
  CHECK_FALSE(sdpslam::eval::compute_rpe(est, gt, 1000, 10.0, &r));
  LONGS_EQUAL(0U, r.matched_count);
}
