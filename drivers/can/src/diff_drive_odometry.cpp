#include "sdpslam/drivers/diff_drive_odometry.h"

#include <cmath>

namespace sdpslam::drivers {
namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kStraightThreshold_rad = 1e-6;  // protocols.md §4
bool positive_finite(double v) { return std::isfinite(v) && v > 0.0; }

// Wraps to (-pi, pi]. Kept local (std::remainder is exact) so this file's results do not
// depend on the core's trigonometry choices.
double wrap_pi(double a) {
  a = std::remainder(a, 2.0 * kPi);
  if (a <= -kPi) a += 2.0 * kPi;
  return a;
}

// Metres travelled by a wheel per (signed) tick.
double metres_per_tick(const DiffDriveParams& p, double radius_m) {
  return 2.0 * kPi / p.ticks_per_rev * p.gear_ratio * radius_m;
}
}  // namespace

DiffDriveParamsError validate(const DiffDriveParams& p) {
  if (!positive_finite(p.ticks_per_rev)) return DiffDriveParamsError::kTicksPerRev;
  if (!positive_finite(p.gear_ratio)) return DiffDriveParamsError::kGearRatio;
  if (!positive_finite(p.left_radius_m) || !positive_finite(p.right_radius_m)) {
    return DiffDriveParamsError::kRadius;
  }
  if (!positive_finite(p.wheel_separation_m)) return DiffDriveParamsError::kWheelSeparation;
  if ((p.left_sign != 1 && p.left_sign != -1) || (p.right_sign != 1 && p.right_sign != -1)) {
    return DiffDriveParamsError::kSign;
  }
  if (p.counter_bits != 16 && p.counter_bits != 32) return DiffDriveParamsError::kCounterBits;
  return DiffDriveParamsError::kOk;
}

const char* to_string(DiffDriveParamsError e) {
  switch (e) {
    case DiffDriveParamsError::kOk: return "ok";
    case DiffDriveParamsError::kTicksPerRev: return "ticks_per_rev must be > 0";
    case DiffDriveParamsError::kGearRatio: return "gear_ratio must be > 0";
    case DiffDriveParamsError::kRadius: return "wheel radii must be > 0";
    case DiffDriveParamsError::kWheelSeparation: return "wheel_separation_m must be > 0";
    case DiffDriveParamsError::kSign: return "wheel signs must be +1 or -1";
    case DiffDriveParamsError::kCounterBits: return "counter_bits must be 16 or 32";
  }
  return "?";
}

std::int32_t wrap_delta(std::uint32_t cur, std::uint32_t last, std::uint8_t bits) {
  const std::uint32_t diff = cur - last;
  if (bits == 16) return static_cast<std::int16_t>(static_cast<std::uint16_t>(diff));
  return static_cast<std::int32_t>(diff);
}

DiffDriveOdometry::DiffDriveOdometry(const DiffDriveParams& params, const Pose2& start)
    : params_(params), params_ok_(validate(params) == DiffDriveParamsError::kOk), pose_(start) {}

DiffDriveOdometry::Step DiffDriveOdometry::update(std::uint32_t left_raw, std::uint32_t right_raw,
                                                  std::int64_t stamp_us) {
  if (!params_ok_) return Step::kInvalidParams;
  if (!latched_) {
    latched_ = true;
    last_left_ = left_raw;
    last_right_ = right_raw;
    stamp_us_ = stamp_us;
    return Step::kLatched;
  }
  const std::int64_t dl_ticks =
      static_cast<std::int64_t>(wrap_delta(left_raw, last_left_, params_.counter_bits)) * params_.left_sign;
  const std::int64_t dr_ticks =
      static_cast<std::int64_t>(wrap_delta(right_raw, last_right_, params_.counter_bits)) * params_.right_sign;
  last_left_ = left_raw;
  last_right_ = right_raw;
  stamp_us_ = stamp_us;
  left_total_ += dl_ticks;
  right_total_ += dr_ticks;

  const double wheel_rad_per_tick = 2.0 * kPi / params_.ticks_per_rev * params_.gear_ratio;
  const double dl_rad = static_cast<double>(dl_ticks) * wheel_rad_per_tick;
  const double dr_rad = static_cast<double>(dr_ticks) * wheel_rad_per_tick;
  const double left_m = dl_rad * params_.left_radius_m;
  const double right_m = dr_rad * params_.right_radius_m;
  const double ds = (left_m + right_m) / 2.0;
  const double dtheta = (right_m - left_m) / params_.wheel_separation_m;
  const double th = pose_.heading_rad;
  if (std::fabs(dtheta) < kStraightThreshold_rad) {
    pose_.x_m += ds * std::cos(th);
    pose_.y_m += ds * std::sin(th);
  } else {
    pose_.x_m += ds / dtheta * (std::sin(th + dtheta) - std::sin(th));
    pose_.y_m -= ds / dtheta * (std::cos(th + dtheta) - std::cos(th));
  }
  pose_.heading_rad = wrap_pi(th + dtheta);
  return Step::kIntegrated;
}

bool poses_to_ticks(const DiffDriveParams& p, const Pose2* poses, std::size_t n,
                    std::int64_t* left_ticks, std::int64_t* right_ticks) {
  if (validate(p) != DiffDriveParamsError::kOk || n == 0 || poses == nullptr) return false;
  const double left_m_per_tick = metres_per_tick(p, p.left_radius_m);
  const double right_m_per_tick = metres_per_tick(p, p.right_radius_m);
  double left_exact = 0.0;
  double right_exact = 0.0;
  left_ticks[0] = 0;
  right_ticks[0] = 0;
  for (std::size_t i = 1; i < n; ++i) {
    const Pose2& a = poses[i - 1];
    const Pose2& b = poses[i];
    const double dx = b.x_m - a.x_m;
    const double dy = b.y_m - a.y_m;
    const double dtheta = wrap_pi(b.heading_rad - a.heading_rad);
    double ds;
    if (std::fabs(dtheta) < kStraightThreshold_rad) {
      ds = dx * std::cos(a.heading_rad) + dy * std::sin(a.heading_rad);
    } else {
      // The chord of an arc of length ds turning by dθ has length ds·sin(dθ/2)/(dθ/2) and
      // points along θ + dθ/2; project the displacement on that direction.
      const double mid = a.heading_rad + dtheta / 2.0;
      const double chord_along = dx * std::cos(mid) + dy * std::sin(mid);
      ds = chord_along * (dtheta / 2.0) / std::sin(dtheta / 2.0);
    }
    const double half_turn_m = dtheta * p.wheel_separation_m / 2.0;
    left_exact += (ds - half_turn_m) / left_m_per_tick * p.left_sign;
    right_exact += (ds + half_turn_m) / right_m_per_tick * p.right_sign;
    left_ticks[i] = std::llround(left_exact);
    right_ticks[i] = std::llround(right_exact);
  }
  return true;
}

EncoderOdometrySource::EncoderOdometrySource(hal::WheelEncoderSource& encoders,
                                             const DiffDriveParams& params)
    : encoders_(encoders), odom_(params) {}

int EncoderOdometrySource::update() {
  const int r = encoders_.update();
  const hal::WheelEncoderSample s = encoders_.latest();
  if (!s.both_fresh()) {
    if (s.left.has_sample || s.right.has_sample || odom_.latched()) {
      if (!was_stale_ && odom_.latched()) stale_count_++;
      if (odom_.latched()) {
        was_stale_ = true;
        reading_.status = hal::OdometryStatus::kStale;
      }
    }
    return r < 0 ? r : 0;
  }
  if (s.left.sequence == used_left_seq_ && s.right.sequence == used_right_seq_) {
    return r < 0 ? r : 0;  // nothing new
  }
  if (was_stale_) {
    odom_.unlatch();
    relatch_count_++;
    was_stale_ = false;
  }
  used_left_seq_ = s.left.sequence;
  used_right_seq_ = s.right.sequence;
  const std::int64_t stamp = s.left.stamp_us > s.right.stamp_us ? s.left.stamp_us : s.right.stamp_us;
  const auto step = odom_.update(s.left.raw_count, s.right.raw_count, stamp);
  reading_.pose = odom_.pose();
  reading_.stamp_us = stamp;
  switch (step) {
    case DiffDriveOdometry::Step::kLatched:
      // After a re-latch the pose is still a valid (older) estimate, but motion during
      // the outage is unknown: say so until the next integrated step.
      reading_.status = hal::OdometryStatus::kLatching;
      return r < 0 ? r : 0;
    case DiffDriveOdometry::Step::kIntegrated:
      reading_.status = hal::OdometryStatus::kValid;
      return 1;
    case DiffDriveOdometry::Step::kInvalidParams:
      reading_.status = hal::OdometryStatus::kNoData;
      return -1;
  }
  return 0;
}

}  // namespace sdpslam::drivers
