// Within-segment error against a ground truth (eval/segment_drift.h) on synthetic runs
// whose segments were displaced, shortened or turned by known amounts.
#include <CppUTest/TestHarness.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "rectangle_run.h"
#include "sdpslam/eval/ate.h"
#include "sdpslam/eval/segment_drift.h"

using sdpslam::Pose2;
using sdpslam::eval::SegmentDriftResult;
using sdpslam::eval::SegmentStart;
using sdpslam::io::StampedPose;

namespace {

constexpr std::size_t kPerSegment = 40U;

// Twice round a 6 m × 4 m rectangle, one scan every 10 cm: 400 scans, 10 segments of
// 4 m of path each (every one has a chord of at least 2.8 m).
std::vector<StampedPose> truth() { return sdpslam::test::rectangle_run(2); }

std::vector<SegmentStart> segments_of(const std::vector<StampedPose>& gt) {
  return sdpslam::test::segments_every(gt, kPerSegment);
}

// Each segment's scans expressed in its first scan's frame, changed by `within` (the
// submap's own error), and put back under a frame moved by an amount that differs from
// segment to segment (the placement's error).
template <typename Within>
std::vector<StampedPose> estimate_of(const std::vector<StampedPose>& gt, Within within) {
  std::vector<StampedPose> out = gt;
  for (std::size_t i = 0; i < gt.size(); ++i) {
    const std::size_t seg = i / kPerSegment;
    const double k = static_cast<double>(seg);
    const Pose2 frame{0.3 * std::sin(1.3 * k), 0.2 * std::cos(0.7 * k), 0.05 * std::sin(2.1 * k + 0.5)};
    const Pose2 anchor = gt[seg * kPerSegment].pose;
    const Pose2 local = within(sdpslam::between(anchor, gt[i].pose), i - seg * kPerSegment);
    out[i].pose = anchor.compose(frame).compose(local);
  }
  return out;
}

double chord_sum(const std::vector<StampedPose>& gt) {
  double sum = 0.0;
  for (std::size_t s = 0; s < gt.size(); s += kPerSegment) {
    const Pose2 rel = sdpslam::between(gt[s].pose, gt[s + kPerSegment - 1U].pose);
    sum += std::hypot(rel.x_m, rel.y_m);
  }
  return sum;
}

}  // namespace

TEST_GROUP(SegmentDrift){};

TEST(SegmentDrift, misplaced_frames_leave_no_error_within_the_segments) {
  const std::vector<StampedPose> gt = truth();
  const std::vector<StampedPose> est = estimate_of(gt, [](const Pose2& p, std::size_t) { return p; });
  sdpslam::eval::AteResult whole;
  CHECK_TRUE(sdpslam::eval::compute_ate(est, gt, 0, &whole));
  CHECK_TRUE(whole.mean_m > 0.1);  // the displaced frames cost the whole run this much
  SegmentDriftResult r;
  CHECK_TRUE(sdpslam::eval::measure_segment_drift(est, gt, segments_of(gt), 0, &r));
  UNSIGNED_LONGS_EQUAL(10U, r.segments_measured);
  UNSIGNED_LONGS_EQUAL(400U, r.scans_matched);
  UNSIGNED_LONGS_EQUAL(10U, r.chords_measured);
  DOUBLES_EQUAL(10.0 * 3.9, r.path_m, 1e-9);  // 39 steps of 10 cm per segment
  DOUBLES_EQUAL(0.0, r.aligned_rmse_m, 1e-9);
  DOUBLES_EQUAL(0.0, r.endpoint_max_m, 1e-9);
  DOUBLES_EQUAL(0.0, r.along_track_scale, 1e-12);
  DOUBLES_EQUAL(0.0, r.heading_mean_rad, 1e-12);
}

TEST(SegmentDrift, submaps_that_come_out_short_give_their_along_track_scale) {
  const std::vector<StampedPose> gt = truth();
  const std::vector<StampedPose> est = estimate_of(gt, [](const Pose2& p, std::size_t) {
    return Pose2{0.98 * p.x_m, 0.98 * p.y_m, p.heading_rad};
  });
  SegmentDriftResult r;
  CHECK_TRUE(sdpslam::eval::measure_segment_drift(est, gt, segments_of(gt), 0, &r));
  DOUBLES_EQUAL(-0.02, r.along_track_scale, 1e-12);
  // Every endpoint is 2 % of its chord short, and nothing else is wrong.
  DOUBLES_EQUAL(0.02 * chord_sum(gt) / 10.0, r.endpoint_mean_m, 1e-12);
  DOUBLES_EQUAL(10.0 * 0.02 * chord_sum(gt) / r.path_m, r.drift_per_10m_m, 1e-12);
  DOUBLES_EQUAL(0.0, r.heading_mean_rad, 1e-12);
  CHECK_TRUE(r.aligned_rmse_m > 0.005);
}

TEST(SegmentDrift, a_turn_within_the_segments_is_measured_from_first_to_last_scan) {
  const std::vector<StampedPose> gt = truth();
  // A heading error that grows by 1 mrad per scan: 39 mrad from first to last.
  const std::vector<StampedPose> est = estimate_of(gt, [](const Pose2& p, std::size_t k) {
    return Pose2{p.x_m, p.y_m, p.heading_rad + 0.001 * static_cast<double>(k)};
  });
  SegmentDriftResult r;
  CHECK_TRUE(sdpslam::eval::measure_segment_drift(est, gt, segments_of(gt), 0, &r));
  DOUBLES_EQUAL(0.039, r.heading_mean_rad, 1e-12);
  DOUBLES_EQUAL(0.0, r.endpoint_max_m, 1e-12);  // the positions are right
}

TEST(SegmentDrift, scans_without_ground_truth_are_left_out) {
  const std::vector<StampedPose> gt = truth();
  std::vector<StampedPose> est = estimate_of(gt, [](const Pose2& p, std::size_t) { return p; });
  std::vector<StampedPose> partial(gt.begin(), gt.begin() + 41);  // segment 0, and one scan of segment 1
  SegmentDriftResult r;
  CHECK_TRUE(sdpslam::eval::measure_segment_drift(est, partial, segments_of(gt), 0, &r));
  UNSIGNED_LONGS_EQUAL(41U, r.scans_matched);
  UNSIGNED_LONGS_EQUAL(1U, r.segments_measured);
  std::vector<StampedPose> one(gt.begin(), gt.begin() + 1);
  CHECK_FALSE(sdpslam::eval::measure_segment_drift(est, one, segments_of(gt), 0, &r));
  UNSIGNED_LONGS_EQUAL(0U, r.segments_measured);
}
