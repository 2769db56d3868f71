// Absolute trajectory error (see ate.h).
#include "sdpslam/eval/ate.h"

#include <algorithm>
#include <cmath>

namespace sdpslam::eval {

Pose2 align_se2(const std::vector<Pose2>& a, const std::vector<Pose2>& b) {
  const std::size_t n = std::min(a.size(), b.size());
  if (n == 0) return Pose2{};
  double ax = 0.0, ay = 0.0, bx = 0.0, by = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    ax += a[i].x_m;
    ay += a[i].y_m;
    bx += b[i].x_m;
    by += b[i].y_m;
  }
  const double inv_n = 1.0 / static_cast<double>(n);
  ax *= inv_n;
  ay *= inv_n;
  bx *= inv_n;
  by *= inv_n;
  // Cross-covariance terms: the optimal rotation angle is atan2(Σ a'×b', Σ a'·b')
  // (the 2D case of Umeyama 1991, Eq. 40-41, with c = 1).
  double dot = 0.0;
  double cross = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double px = a[i].x_m - ax;
    const double py = a[i].y_m - ay;
    const double qx = b[i].x_m - bx;
    const double qy = b[i].y_m - by;
    dot += px * qx + py * qy;
    cross += px * qy - py * qx;
  }
  const double theta = (dot == 0.0 && cross == 0.0) ? 0.0 : std::atan2(cross, dot);
  const double c = std::cos(theta);
  const double s = std::sin(theta);
  return Pose2{bx - (c * ax - s * ay), by - (s * ax + c * ay), theta};
}

bool compute_ate(const std::vector<io::StampedPose>& estimate, const std::vector<io::StampedPose>& ground_truth,
                 std::int64_t tolerance_us, AteResult* result) {
  AteResult r;
  r.estimate_count = estimate.size();
  r.ground_truth_count = ground_truth.size();
  std::vector<Pose2> est_pts;
  std::vector<Pose2> gt_pts;
  for (const PosePair& p : pair_by_stamp(estimate, ground_truth, tolerance_us, &r.unmatched_estimate_count)) {
    est_pts.push_back(p.estimate);
    gt_pts.push_back(p.truth);
  }
  r.matched_count = est_pts.size();
  if (est_pts.empty()) {
    *result = r;
    return false;
  }
  r.alignment = align_se2(est_pts, gt_pts);
  double sum_sq = 0.0;
  double sum = 0.0;
  double sum_heading_sq = 0.0;
  for (std::size_t i = 0; i < est_pts.size(); ++i) {
    const Pose2 aligned = r.alignment.compose(est_pts[i]);
    const double d = std::hypot(aligned.x_m - gt_pts[i].x_m, aligned.y_m - gt_pts[i].y_m);
    sum_sq += d * d;
    sum += d;
    r.max_m = std::max(r.max_m, d);
    const double dh = normalize_angle_rad(gt_pts[i].heading_rad - aligned.heading_rad);
    sum_heading_sq += dh * dh;
  }
  const double n = static_cast<double>(est_pts.size());
  r.rmse_m = std::sqrt(sum_sq / n);
  r.mean_m = sum / n;
  r.heading_rmse_rad = std::sqrt(sum_heading_sq / n);
  *result = r;
  return true;
}

}  // namespace sdpslam::eval
