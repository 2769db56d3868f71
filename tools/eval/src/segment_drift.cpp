// Within-segment error against a ground truth (see segment_drift.h).
#include "sdpslam/eval/segment_drift.h"

#include <algorithm>
#include <cmath>

#include "sdpslam/eval/ate.h"
#include "sdpslam/eval/stamp_match.h"

namespace sdpslam::eval {

bool measure_segment_drift(const std::vector<io::StampedPose>& estimate,
                           const std::vector<io::StampedPose>& ground_truth,
                           const std::vector<SegmentStart>& segments, std::int64_t tolerance_us,
                           SegmentDriftResult* result) {
  SegmentDriftResult r;
  std::vector<PosePair> pairs = pair_by_stamp(sorted_by_stamp(estimate), ground_truth, tolerance_us, nullptr);
  r.scans_matched = pairs.size();
  double endpoint_sum = 0.0;
  double heading_sum = 0.0;
  double along_sum = 0.0;
  double chord_sum = 0.0;
  double aligned_sq = 0.0;
  double aligned_sum = 0.0;
  std::size_t aligned_count = 0;
  std::vector<Pose2> est;
  std::vector<Pose2> truth;
  std::size_t begin = 0;
  while (begin < pairs.size()) {
    const std::size_t seg = segment_of(segments, pairs[begin].stamp_us);
    std::size_t end = begin + 1;
    while (end < pairs.size() && segment_of(segments, pairs[end].stamp_us) == seg) ++end;
    if (end - begin >= 2) {
      ++r.segments_measured;
      const PosePair& first = pairs[begin];
      const PosePair& last = pairs[end - 1];
      const Pose2 rel_est = between(first.estimate, last.estimate);
      const Pose2 rel_truth = between(first.truth, last.truth);
      const double ex = rel_est.x_m - rel_truth.x_m;
      const double ey = rel_est.y_m - rel_truth.y_m;
      const double endpoint = std::hypot(ex, ey);
      endpoint_sum += endpoint;
      r.endpoint_max_m = std::max(r.endpoint_max_m, endpoint);
      heading_sum += std::fabs(normalize_angle_rad(rel_est.heading_rad - rel_truth.heading_rad));
      const double chord = std::hypot(rel_truth.x_m, rel_truth.y_m);
      if (chord >= kMinDriftChordM) {
        ++r.chords_measured;
        along_sum += (ex * rel_truth.x_m + ey * rel_truth.y_m) / chord;
        chord_sum += chord;
      }
      est.clear();
      truth.clear();
      for (std::size_t i = begin; i < end; ++i) {
        if (i > begin) {
          r.path_m += std::hypot(pairs[i].truth.x_m - pairs[i - 1].truth.x_m, pairs[i].truth.y_m - pairs[i - 1].truth.y_m);
        }
        est.push_back(pairs[i].estimate);
        truth.push_back(pairs[i].truth);
      }
      const Pose2 align = align_se2(est, truth);
      for (std::size_t i = 0; i < est.size(); ++i) {
        const Pose2 p = align.compose(est[i]);
        const double d = std::hypot(p.x_m - truth[i].x_m, p.y_m - truth[i].y_m);
        aligned_sq += d * d;
        aligned_sum += d;
        ++aligned_count;
      }
    }
    begin = end;
  }
  if (r.segments_measured == 0) {
    *result = r;
    return false;
  }
  const double n = static_cast<double>(r.segments_measured);
  r.endpoint_mean_m = endpoint_sum / n;
  r.heading_mean_rad = heading_sum / n;
  r.drift_per_10m_m = r.path_m > 0.0 ? 10.0 * endpoint_sum / r.path_m : 0.0;
  r.along_track_scale = chord_sum > 0.0 ? along_sum / chord_sum : 0.0;
  r.aligned_rmse_m = std::sqrt(aligned_sq / static_cast<double>(aligned_count));
  r.aligned_mean_m = aligned_sum / static_cast<double>(aligned_count);
  *result = r;
  return true;
}

}  // namespace sdpslam::eval
