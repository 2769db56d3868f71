#pragma once
// Odometry motion model: the proposal distribution of the bottom-level filter (paper
// §II-A, DP-SLAM's odometry proposal). This is sample_motion_model_odometry of Thrun,
// Burgard & Fox, "Probabilistic Robotics" (2005), Table 5.6: the odometry displacement
// between two readings is decomposed into rot1 (turn towards the new position), trans
// (straight move) and rot2 (final turn); each is perturbed by zero-mean Gaussian noise
// whose variance grows with the motion:
//   var(rot1)  = a1·rot1² + a2·trans²        var(trans) = a3·trans² + a4·(rot1² + rot2²)
//   var(rot2)  = a1·rot2² + a2·trans²
// plus small floors (min_sigma_*) so that a robot that barely moves still diversifies.
// Backward motion (the displacement lies behind the robot) is decomposed with a
// negative trans so that rot1 stays small, as reversing robots need.
// Cost: O(1), 3 Gaussian draws; no heap; deterministic given the Rng.
#include "sdpslam/core/pose2.h"
#include "sdpslam/core/rng.h"

namespace sdpslam {

struct MotionModelOptions {
  double alpha_rot_from_rot = 0.05;         // a1, rad²/rad²
  double alpha_rot_from_trans = 0.01;       // a2, rad²/m²
  double alpha_trans_from_trans = 0.02;     // a3, m²/m²
  double alpha_trans_from_rot = 0.005;      // a4, m²/rad²
  double min_sigma_trans_m = 0.005;
  double min_sigma_rot_rad = 0.002;
};

// The rot1/trans/rot2 decomposition of an odometry displacement (in the frame of the
// earlier pose).
struct OdometryDelta {
  double rot1_rad = 0.0;
  double trans_m = 0.0;
  double rot2_rad = 0.0;
};

OdometryDelta decompose_odometry(const Pose2& delta);
// The pose reached from `start` by executing `d` exactly.
Pose2 apply_odometry(const Pose2& start, const OdometryDelta& d);

// The motion model's density around its prediction along the direction of travel. To
// first order in the rot1/trans/rot2 noise, an error moves the pose by δtrans along the
// direction of travel u (start heading + rot1) and by trans·δrot1 across it, so the
// position along u is Gaussian with variance σ_trans², independent of the rest: this is
// that marginal. Across the path and in heading it says nothing.
//
// Why this part only: the scan matcher of the improved proposal maximises the
// observation likelihood times this density (the proposal's target p(z | m, x)·p(x | x', u),
// Grisetti, Stachniss & Burgard 2007, eq. 9). Along a plain corridor the map does not
// fix the position along the path, and the likelihood alone has spurious optima there
// (a scan fits best where its hits fall on the dots the previous scans drew, so every
// step is pulled towards the last one and corridors come out short); the prior keeps
// the odometry's travel where the map is silent. Across the path and in heading, walls
// constrain the match almost everywhere, and the model's spread there (millimetres per
// step, a well-calibrated robot) would hold the match to a real robot's heading drift.
// O(1); no heap.
struct MotionPrior {
  Pose2 predicted;          // the odometry prediction: the density's mode
  double along_cos = 1.0;   // direction of travel u
  double along_sin = 0.0;
  double info_along = 0.0;  // 1 / σ_trans², 1/m²

  // log density at `pose` up to a constant: −½·(e·u)²/σ_trans², e = pose − predicted.
  // 0 at the prediction (and anywhere across the path), negative elsewhere.
  double log_density(const Pose2& pose) const {
    const double along = (pose.x_m - predicted.x_m) * along_cos + (pose.y_m - predicted.y_m) * along_sin;
    return -0.5 * info_along * along * along;
  }
};

class MotionModel {
 public:
  MotionModel() = default;
  explicit MotionModel(const MotionModelOptions& options) : options_(options) {}

  // One sample of the pose reached from `start` after the odometry displacement
  // `odom_delta` = between(odom_prev, odom_now).
  Pose2 sample(const Pose2& start, const Pose2& odom_delta, Rng& rng) const;
  // Gaussian approximation of sample()'s density from `start` (see MotionPrior).
  MotionPrior prior(const Pose2& start, const Pose2& odom_delta) const;
  // The standard deviations (rot1, trans, rot2) used for this displacement.
  OdometryDelta sigmas(const OdometryDelta& d) const;

  const MotionModelOptions& options() const { return options_; }

 private:
  MotionModelOptions options_;
};

}  // namespace sdpslam
