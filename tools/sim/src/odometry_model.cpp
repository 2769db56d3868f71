#include "sdpslam/sim/odometry_model.h"

#include <cmath>

#include "sdpslam/sim/diff_drive.h"

namespace sdpslam::sim {

namespace {
constexpr std::uint64_t kOdometryStream = 1;
}

WheelOdometry::WheelOdometry(const Pose2& start, const OdometryNoise& noise, double wheel_base_m, std::uint64_t seed)
    : pose_(start), noise_(noise), wheel_base_m_(wheel_base_m), rng_(seed, kOdometryStream) {}

void WheelOdometry::step(double ds_m, double dtheta_rad) {
  const double n_trans = rng_.gaussian();
  const double n_rot = rng_.gaussian();
  const double ads = std::fabs(ds_m);
  const double adt = std::fabs(dtheta_rad);
  const double sigma_trans = noise_.trans_m_per_sqrt_m * std::sqrt(ads);
  const double sigma_rot = std::sqrt(noise_.rot_rad_per_sqrt_rad * noise_.rot_rad_per_sqrt_rad * adt +
                                     noise_.rot_rad_per_sqrt_m * noise_.rot_rad_per_sqrt_m * ads);
  const double ds = ds_m * (1.0 + noise_.scale_error) + sigma_trans * n_trans;
  const double dtheta = dtheta_rad + noise_.wheel_radius_mismatch * ds_m / wheel_base_m_ + sigma_rot * n_rot;
  pose_ = integrate_arc(pose_, ds, dtheta);
}

}  // namespace sdpslam::sim
