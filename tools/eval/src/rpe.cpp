// Relative pose error over a travelled distance (see rpe.h).
#include "sdpslam/eval/rpe.h"

#include <algorithm>
#include <cmath>

#include "sdpslam/eval/stamp_match.h"

namespace sdpslam::eval {
namespace {

struct Pair {
  std::int64_t stamp_us;
  Pose2 est;
  Pose2 gt;
};

}  // namespace

bool compute_rpe(const std::vector<io::StampedPose>& estimate, const std::vector<io::StampedPose>& ground_truth,
                 std::int64_t tolerance_us, double distance_m, RpeResult* result) {
  RpeResult r;
  r.distance_m = distance_m;
  std::vector<io::StampedPose> gt = ground_truth;
  std::stable_sort(gt.begin(), gt.end(),
                   [](const io::StampedPose& x, const io::StampedPose& y) { return x.stamp_us < y.stamp_us; });
  std::vector<Pair> pairs;
  pairs.reserve(estimate.size());
  for (const io::StampedPose& e : estimate) {
    std::size_t k = 0;
    if (find_stamp(gt, e.stamp_us, tolerance_us, &k) == StampMatch::kNone) continue;
    pairs.push_back({e.stamp_us, e.pose, gt[k].pose});
  }
  std::stable_sort(pairs.begin(), pairs.end(), [](const Pair& x, const Pair& y) { return x.stamp_us < y.stamp_us; });
  r.matched_count = pairs.size();
  if (!(distance_m > 0.0) || pairs.size() < 2) {
    *result = r;
    return false;
  }
  // Ground-truth path length from the first pair to each pair.
  std::vector<double> travel(pairs.size(), 0.0);
  for (std::size_t k = 1; k < pairs.size(); ++k) {
    travel[k] = travel[k - 1] + std::hypot(pairs[k].gt.x_m - pairs[k - 1].gt.x_m, pairs[k].gt.y_m - pairs[k - 1].gt.y_m);
  }
  double sum = 0.0, sum_sq = 0.0, sum_heading = 0.0, sum_scale = 0.0;
  std::size_t scaled = 0;
  std::size_t j = 0;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    if (j <= i) j = i + 1;
    while (j < pairs.size() && travel[j] - travel[i] < distance_m) ++j;
    if (j >= pairs.size()) break;  // every later start is shorter still
    const Pose2 de = between(pairs[i].est, pairs[j].est);
    const Pose2 dg = between(pairs[i].gt, pairs[j].gt);
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
