#include "sdpslam/sim/laser_model.h"

#include <algorithm>
#include <cmath>

namespace sdpslam::sim {

namespace {
constexpr std::uint64_t kLaserStream = 2;
constexpr double kPi = 3.14159265358979323846;
}  // namespace

LaserSimulator::LaserSimulator(const RayCaster& caster, const LaserOptions& options, std::uint64_t seed)
    : caster_(caster), options_(options), rng_(seed, kLaserStream) {
  const double fov_rad = options_.fov_deg * kPi / 180.0;
  geometry_.angle_min_rad = static_cast<float>(-0.5 * fov_rad);
  geometry_.angle_increment_rad =
      options_.beam_count > 1U ? static_cast<float>(fov_rad / static_cast<double>(options_.beam_count - 1U)) : 0.0F;
  geometry_.range_min_m = static_cast<float>(options_.min_range_m);
  geometry_.range_max_m = static_cast<float>(options_.max_range_m);
  geometry_.laser_in_base = Pose2{};
}

void LaserSimulator::scan(const Pose2& laser_pose, RangeScan* out) {
  const double fov_rad = options_.fov_deg * kPi / 180.0;
  const double inc = options_.beam_count > 1U ? fov_rad / static_cast<double>(options_.beam_count - 1U) : 0.0;
  out->geometry = geometry_;
  out->beam_count = std::min<std::uint32_t>(options_.beam_count, capacity::kMaxBeams);
  for (std::uint32_t i = 0; i < out->beam_count; ++i) {
    const double angle = laser_pose.heading_rad - 0.5 * fov_rad + static_cast<double>(i) * inc;
    const double noise = rng_.gaussian();
    const double spurious = rng_.uniform();
    const double truth = caster_.cast(laser_pose.x_m, laser_pose.y_m, angle, options_.max_range_m);
    double r = options_.max_range_m;
    if (std::isfinite(truth) && spurious >= options_.spurious_max_prob) {
      r = std::clamp(truth + options_.range_noise_std_m * noise, options_.min_range_m, options_.max_range_m);
    }
    out->ranges_m[i] = static_cast<float>(r);
  }
}

}  // namespace sdpslam::sim
