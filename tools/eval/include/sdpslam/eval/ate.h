#pragma once
// Absolute trajectory error (Sturm et al., "A benchmark for the evaluation of RGB-D SLAM
// systems", IROS 2012, §VI-B) in the plane: estimate and ground truth are paired by
// stamp, the estimate is moved by the rigid SE(2) transform that minimises the sum of
// squared position differences (closed form, Horn 1987 / Umeyama 1991 without scale,
// reduced to 2D), and the residual position errors are summarised.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "sdpslam/core/pose2.h"
#include "sdpslam/eval/stamp_match.h"
#include "sdpslam/io/trajectory_io.h"

namespace sdpslam::eval {

// The T minimising Σ‖T(a_i) − b_i‖² over rotations and translations (no scale):
// with centroids ā, b̄ and centred points a', b',
//   θ = atan2(Σ a'×b', Σ a'·b'),  t = b̄ − R(θ) ā.
// With fewer than two distinct points the rotation is undetermined and θ = 0.
// Precondition: a.size() == b.size().
Pose2 align_se2(const std::vector<Pose2>& a, const std::vector<Pose2>& b);

struct AteResult {
  std::size_t estimate_count = 0;
  std::size_t ground_truth_count = 0;
  std::size_t matched_count = 0;            // pairs used
  std::size_t unmatched_estimate_count = 0; // estimates with no ground truth within tolerance
  Pose2 alignment;                          // maps the estimate frame into the ground-truth frame
  double rmse_m = 0.0;
  double mean_m = 0.0;
  double max_m = 0.0;
  double heading_rmse_rad = 0.0;            // of wrap(θ_gt − (θ_est + θ_alignment))
};

// False iff no pair matched (then `*result` holds only the counts). Ground truth must be
// ascending by stamp (it is sorted internally if not).
bool compute_ate(const std::vector<io::StampedPose>& estimate, const std::vector<io::StampedPose>& ground_truth,
                 std::int64_t tolerance_us, AteResult* result);

}  // namespace sdpslam::eval
