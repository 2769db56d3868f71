// Relative pose error over a travelled distance (see rpe.h).
#include "sdpslam/eval/rpe.h"

#include <algorithm>
#include <cmath>

#include "sdpslam/eval/stamp_match.h"

namespace sdpslam::eval {

bool compute_rpe(const std::vector<io::StampedPose>& estimate, const std::vector<io::StampedPose>& ground_truth,
                 std::int64_t tolerance_us, double distance_m, RpeResult* result) {
  RpeResult r;
  r.distance_m = distance_m;
  std::vector<PosePair> pairs = pair_by_stamp(estimate, ground_truth, tolerance_us, nullptr);
  std::stable_sort(pairs.begin(), pairs.end(),
                   [](const PosePair& x, const PosePair& y) { return x.stamp_us < y.stamp_us; });
  r.matched_count = pairs.size();
  if (!(distance_m > 0.0) || pairs.size() < 2) {
    *result = r;
    return false;
  }
  // Ground-truth path length from the first pair to each pair.
  std::vector<double> travel(pairs.size(), 0.0);
  for (std::size_t k = 1; k < pairs.size(); ++k) {
    travel[k] = travel[k - 1] + std::hypot(pairs[k].truth.x_m - pairs[k - 1].truth.x_m, pairs[k].truth.y_m - pairs[k - 1].truth.y_m);
  }
  double sum = 0.0, sum_sq = 0.0, sum_heading = 0.0, sum_scale = 0.0;
  std::size_t scaled = 0;
  std::size_t j = 0;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    if (j <= i) j = i + 1;
    while (j < pairs.size() && travel[j] - travel[i] < distance_m) ++j;
    if (j >= pairs.size()) break;  // every later start is shorter still
    const Pose2 de = between(pairs[i].estimate, pairs[j].estimate);
    const Pose2 dg = between(pairs[i].truth, pairs[j].truth);
    const double ex = de.x_m - dg.x_m;
    const double ey = de.y_m - dg.y_m;
    const double e = std::hypot(ex, ey);
    sum += e;
    sum_sq += e * e;
    r.max_m = std::max(r.max_m, e);
    sum_heading += std::fabs(normalize_angle_rad(de.heading_rad - dg.heading_rad));
    const double len = std::hypot(dg.x_m, dg.y_m);
    if (len >= 0.5 * distance_m) {  // a stretch that turns back says little about scale
      sum_scale += (ex * dg.x_m + ey * dg.y_m) / (len * len);
      ++scaled;
    }
    ++r.stretch_count;
  }
  if (r.stretch_count == 0) {
    *result = r;
    return false;
  }
  const double n = static_cast<double>(r.stretch_count);
  r.mean_m = sum / n;
  r.rmse_m = std::sqrt(sum_sq / n);
  r.heading_mean_rad = sum_heading / n;
  r.scale_error = scaled > 0 ? sum_scale / static_cast<double>(scaled) : 0.0;
  *result = r;
  return true;
}

}  // namespace sdpslam::eval
