// Absolute trajectory error: alignment is exact on rigid copies, and residuals are the
// ones computed by hand.
#include <CppUTest/TestHarness.h>

#include <cmath>
#include <vector>

#include "sdpslam/eval/ate.h"

using sdpslam::Pose2;
using sdpslam::io::StampedPose;

namespace {
std::vector<StampedPose> path(std::size_t n) {
  std::vector<StampedPose> p;
  for (std::size_t i = 0; i < n; ++i) {
    const double t = 0.1 * static_cast<double>(i);
    p.push_back({static_cast<std::int64_t>(i) * 100000, {3.0 * std::cos(t), 2.0 * std::sin(2.0 * t), t}});
  }
  return p;
}
}  // namespace

TEST_GROUP(Ate){};

TEST(Ate, rotated_and_translated_copy_has_zero_error) {
  const auto gt = path(60);
  auto est = gt;
  const Pose2 frame{-7.0, 12.5, -2.4};
  for (auto& p : est) p.pose = frame.compose(p.pose);
  sdpslam::eval::AteResult r;
  CHECK_TRUE(sdpslam::eval::compute_ate(est, gt, 1000, &r));
  LONGS_EQUAL(60, r.matched_count);
  DOUBLES_EQUAL(0.0, r.rmse_m, 1e-9);
  DOUBLES_EQUAL(0.0, r.max_m, 1e-9);
  DOUBLES_EQUAL(0.0, r.heading_rmse_rad, 1e-9);
  // The alignment is the inverse of the frame change.
  const Pose2 inv = frame.inverse();
  DOUBLES_EQUAL(inv.x_m, r.alignment.x_m, 1e-9);
  DOUBLES_EQUAL(inv.y_m, r.alignment.y_m, 1e-9);
  DOUBLES_EQUAL(inv.heading_rad, r.alignment.heading_rad, 1e-9);
}

TEST(Ate, alternating_offset_gives_its_magnitude_as_rmse) {
  // Poses come in pairs at the same place; within a pair the estimate is 0.2 m left and
  // 0.2 m right of it. The offsets cancel in the centroid and in the cross-covariance,
  // so the best alignment is the identity and every residual is exactly 0.2 m.
  std::vector<StampedPose> gt;
  for (int i = 0; i < 40; ++i) gt.push_back({i, {0.0, static_cast<double>(i / 2), 0.0}});
  auto est = gt;
  for (std::size_t i = 0; i < est.size(); ++i) est[i].pose.x_m += (i % 2 == 0) ? 0.2 : -0.2;
  sdpslam::eval::AteResult r;
  CHECK_TRUE(sdpslam::eval::compute_ate(est, gt, 0, &r));
  DOUBLES_EQUAL(0.0, r.alignment.heading_rad, 1e-12);
  DOUBLES_EQUAL(0.2, r.rmse_m, 1e-9);
  DOUBLES_EQUAL(0.2, r.mean_m, 1e-9);
  DOUBLES_EQUAL(0.2, r.max_m, 1e-9);
}

TEST(Ate, one_outlier_gives_closed_form_rmse) {
  // Points on a line; one estimate displaced perpendicular... solved by hand for the
  // simplest case: two points, displacement along the line joining them. est = gt except
  // the second point is 0.4 m further: best alignment splits it, residuals 0.2 m each.
  std::vector<StampedPose> gt{{0, {0, 0, 0}}, {1, {1, 0, 0}}};
  auto est = gt;
  est[1].pose.x_m = 1.4;
  sdpslam::eval::AteResult r;
  CHECK_TRUE(sdpslam::eval::compute_ate(est, gt, 0, &r));
  DOUBLES_EQUAL(0.2, r.rmse_m, 1e-12);
  DOUBLES_EQUAL(0.0, r.alignment.heading_rad, 1e-12);
}

TEST(Ate, constant_heading_offset_is_removed_by_alignment_but_heading_noise_is_not) {
  const auto gt = path(30);
  auto est = gt;
  for (std::size_t i = 0; i < est.size(); ++i) est[i].pose.heading_rad += (i % 2 == 0) ? 0.01 : -0.01;
  sdpslam::eval::AteResult r;
  CHECK_TRUE(sdpslam::eval::compute_ate(est, gt, 0, &r));
  DOUBLES_EQUAL(0.0, r.rmse_m, 1e-12);
  DOUBLES_EQUAL(0.01, r.heading_rmse_rad, 1e-12);
}

TEST(Ate, unmatched_estimates_are_counted) {
  const auto gt = path(10);
  auto est = gt;
  est.push_back({5000000, {}});
  sdpslam::eval::AteResult r;
  CHECK_TRUE(sdpslam::eval::compute_ate(est, gt, 1000, &r));
  LONGS_EQUAL(11, r.estimate_count);
  LONGS_EQUAL(10, r.matched_count);
  LONGS_EQUAL(1, r.unmatched_estimate_count);
}

TEST(Ate, nothing_matched_is_a_failure) {
  sdpslam::eval::AteResult r;
  CHECK_FALSE(sdpslam::eval::compute_ate({{1, {}}}, {{2000, {}}}, 1000, &r));
  LONGS_EQUAL(0, r.matched_count);
}

TEST(Ate, unsorted_ground_truth_still_matches) {
  auto gt = path(10);
  std::swap(gt[2], gt[7]);
  sdpslam::eval::AteResult r;
  CHECK_TRUE(sdpslam::eval::compute_ate(path(10), gt, 0, &r));
  LONGS_EQUAL(10, r.matched_count);
  DOUBLES_EQUAL(0.0, r.rmse_m, 1e-9);
}

TEST(Ate, single_pair_aligns_by_translation_only) {
  sdpslam::eval::AteResult r;
  CHECK_TRUE(sdpslam::eval::compute_ate({{0, {5, 5, 1}}}, {{0, {0, 0, 0}}}, 0, &r));
  DOUBLES_EQUAL(0.0, r.rmse_m, 1e-12);
  DOUBLES_EQUAL(0.0, r.alignment.heading_rad, 0.0);
  DOUBLES_EQUAL(1.0, r.heading_rmse_rad, 1e-12);
}
