#include "sdpslam/core/bottom/motion_model.h"

#include "sdpslam/core/det_math.h"

namespace sdpslam {

OdometryDelta decompose_odometry(const Pose2& delta) {
  OdometryDelta d;
  const double trans = det::sqrt(delta.x_m * delta.x_m + delta.y_m * delta.y_m);
  if (trans < 1e-6) {
    // No translation: the whole turn is rot1 (rot1 of a zero move is undefined).
    d.rot1_rad = delta.heading_rad;
    return d;
  }
  double rot1 = det::atan2(delta.y_m, delta.x_m);
  double signed_trans = trans;
  if (rot1 > 0.5 * det::kPi || rot1 < -0.5 * det::kPi) {  // moving backwards
    rot1 = det::wrap_angle(rot1 - det::kPi);
    signed_trans = -trans;
  }
  d.rot1_rad = rot1;
  d.trans_m = signed_trans;
  d.rot2_rad = det::wrap_angle(delta.heading_rad - rot1);
  return d;
}

Pose2 apply_odometry(const Pose2& start, const OdometryDelta& d) {
  const double heading = start.heading_rad + d.rot1_rad;
  return Pose2{start.x_m + d.trans_m * det::cos(heading), start.y_m + d.trans_m * det::sin(heading),
               det::wrap_angle(heading + d.rot2_rad)};
}

OdometryDelta MotionModel::sigmas(const OdometryDelta& d) const {
  const MotionModelOptions& o = options_;
  const double r1 = d.rot1_rad * d.rot1_rad;
  const double t = d.trans_m * d.trans_m;
  const double r2 = d.rot2_rad * d.rot2_rad;
  OdometryDelta s;
  s.rot1_rad = det::sqrt(o.alpha_rot_from_rot * r1 + o.alpha_rot_from_trans * t + o.min_sigma_rot_rad * o.min_sigma_rot_rad);
  s.trans_m = det::sqrt(o.alpha_trans_from_trans * t + o.alpha_trans_from_rot * (r1 + r2) +
                        o.min_sigma_trans_m * o.min_sigma_trans_m);
  s.rot2_rad = det::sqrt(o.alpha_rot_from_rot * r2 + o.alpha_rot_from_trans * t + o.min_sigma_rot_rad * o.min_sigma_rot_rad);
  return s;
}

MotionPrior MotionModel::prior(const Pose2& start, const Pose2& odom_delta) const {
  const OdometryDelta d = decompose_odometry(odom_delta);
  const OdometryDelta s = sigmas(d);
  // With every noise parameter at zero the model is exact; a variance floor far below
  // any map cell keeps the information finite.
  constexpr double kMinVariance = 1e-12;
  double var_along = s.trans_m * s.trans_m;
  if (var_along < kMinVariance) var_along = kMinVariance;
  MotionPrior p;
  p.predicted = start.compose(odom_delta);  // = apply_odometry(start, d)
  const double travel = start.heading_rad + d.rot1_rad;
  p.along_cos = det::cos(travel);
  p.along_sin = det::sin(travel);
  p.info_along = 1.0 / var_along;
  return p;
}

Pose2 MotionModel::sample(const Pose2& start, const Pose2& odom_delta, Rng& rng) const {
  const OdometryDelta d = decompose_odometry(odom_delta);
  const OdometryDelta s = sigmas(d);
  OdometryDelta noisy;
  // Fixed draw order (rot1, trans, rot2) keeps runs reproducible.
  noisy.rot1_rad = d.rot1_rad + rng.gaussian(s.rot1_rad);
  noisy.trans_m = d.trans_m + rng.gaussian(s.trans_m);
  noisy.rot2_rad = d.rot2_rad + rng.gaussian(s.rot2_rad);
  return apply_odometry(start, noisy);
}

}  // namespace sdpslam
