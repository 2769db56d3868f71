#pragma once
// Wheel odometry as the robot would integrate it from its encoders, with noise.
//
// Per physics step the true motion (arc length ds, rotation dθ) is corrupted as
//   ds' = ds * (1 + scale_error) + N(0, trans² · |ds|)
//   dθ' = dθ + wheel_radius_mismatch · ds / wheel_base
//            + N(0, rot_per_rot² · |dθ| + rot_per_dist² · |ds|)
// and integrated with the same exact-arc formula as the ground truth. The random terms
// have variance proportional to the motion (a random walk in distance / rotation), so
// the accumulated error does not depend on the physics rate: after travelling D metres
// the along-track error has std trans·√D. The systematic terms model a distance scale
// error and unequal wheel radii ((r_right − r_left) / r, a steady turn of
// mismatch/wheel_base rad per metre: Borenstein & Feng, UMBmark, 1996).
// With every coefficient zero the odometry equals the ground truth bit for bit.
#include <cstdint>

#include "sdpslam/core/pose2.h"
#include "sdpslam/sim/rng.h"

namespace sdpslam::sim {

struct OdometryNoise {
  double trans_m_per_sqrt_m = 0.02;        // along-track random walk
  double rot_rad_per_sqrt_rad = 0.02;      // heading random walk per rotation
  double rot_rad_per_sqrt_m = 0.005;       // heading random walk per distance
  double scale_error = 0.002;              // odometry over-reads distance by this fraction
  double wheel_radius_mismatch = 0.0003;   // (r_right - r_left) / r: steady heading drift
};

class WheelOdometry {
 public:
  WheelOdometry(const Pose2& start, const OdometryNoise& noise, double wheel_base_m, std::uint64_t seed);

  // Adds one step of true motion. Always draws two Gaussians, so the same seed gives the
  // same noise realisation whatever the coefficients (scaling a coefficient scales the
  // error of the same run).
  void step(double ds_m, double dtheta_rad);

  const Pose2& pose() const { return pose_; }

 private:
  Pose2 pose_;
  OdometryNoise noise_;
  double wheel_base_m_;
  Rng rng_;
};

}  // namespace sdpslam::sim
