#pragma once
// Relative pose error over a travelled distance (Sturm et al., "A benchmark for the
// evaluation of RGB-D SLAM systems", IROS 2012, §VI-A, with distance instead of time
// steps, as the KITTI odometry benchmark does): the drift of the estimate over every
// stretch of the ground-truth path of a given length, whatever happened before it.
// ATE mixes local drift with the closure of large loops; this measures the local part,
// the one a bottom-level filter and its scan matcher are responsible for.
//
// Estimate and ground truth are paired by stamp (as for ATE) and ordered by stamp. For
// every pair i, j is the first later pair whose ground-truth path from i is at least
// distance_m long; the error of that stretch is the difference of the two relative
// motions, both in the frame of their pose i:
//   e = (est_i⁻¹ · est_j).t − (gt_i⁻¹ · gt_j).t
// Reported: mean, RMS and largest |e|; the mean heading error; and the along-track
// scale error, the mean of e·u / |Δgt| (u the unit ground-truth displacement) over the
// stretches that end at least distance_m / 2 from their start (one that turns back says
// little about scale): negative when the estimate comes out shorter than the path, as a
// scan matcher that lags behind the robot makes it.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "sdpslam/io/trajectory_io.h"

namespace sdpslam::eval {

struct RpeResult {
  double distance_m = 0.0;       // the stretch length asked for
  std::size_t matched_count = 0; // pairs matched by stamp
  std::size_t stretch_count = 0; // stretches measured (0: the path is shorter than distance_m)
  double mean_m = 0.0;
  double rmse_m = 0.0;
  double max_m = 0.0;
  double heading_mean_rad = 0.0; // mean |wrap(Δθ_est − Δθ_gt)|
  double scale_error = 0.0;      // mean along-track error per metre of stretch (−0.01 = 1 % short)
};

// False iff no stretch could be measured (no pair, or a path shorter than distance_m);
// `*result` still holds the counts. distance_m must be > 0.
bool compute_rpe(const std::vector<io::StampedPose>& estimate, const std::vector<io::StampedPose>& ground_truth,
                 std::int64_t tolerance_us, double distance_m, RpeResult* result);

}  // namespace sdpslam::eval
