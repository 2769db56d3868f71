#include "sdpslam/daemon/odometry_ring.h"

#include "sdpslam/core/det_math.h"

namespace sdpslam::daemon {
namespace {

// V(θ) = [[sinθ/θ, −(1−cosθ)/θ], [(1−cosθ)/θ, sinθ/θ]] maps the twist's translation to
// the pose's; series near 0 keep it exact for straight motion.
void v_coefficients(double theta, double* a, double* b) {
  if ((theta < 0.0 ? -theta : theta) < 1e-9) {
    *a = 1.0 - theta * theta / 6.0;
    *b = theta / 2.0;
  } else {
    *a = det::sin(theta) / theta;
    *b = (1.0 - det::cos(theta)) / theta;
  }
}

}  // namespace

Pose2 interpolate_se2(const Pose2& a, const Pose2& b, double f) {
  if (f == 0.0) return a;
  if (f == 1.0) return b;
  const Pose2 d = between(a, b);
  // log: twist (u, θ) with V(θ) u = (dx, dy)
  const double theta = d.heading_rad;
  double va = 0.0;
  double vb = 0.0;
  v_coefficients(theta, &va, &vb);
  const double det_v = va * va + vb * vb;
  const double ux = (va * d.x_m + vb * d.y_m) / det_v;
  const double uy = (-vb * d.x_m + va * d.y_m) / det_v;
  // exp(f · twist)
  const double tf = f * theta;
  v_coefficients(tf, &va, &vb);
  const Pose2 step{f * (va * ux - vb * uy), f * (vb * ux + va * uy), normalize_angle_rad(tf)};
  return a.compose(step);
}

bool OdometryRing::push(std::int64_t stamp_us, const Pose2& pose) {
  if (!ring_.empty() && stamp_us <= ring_.back().stamp_us) {
    ++refused_count_;
    return false;
  }
  Sample s;
  s.stamp_us = stamp_us;
  s.pose = pose;
  s.segment_start = break_pending_ || ring_.empty();
  break_pending_ = false;
  ring_.push_overwrite(s);
  return true;
}

void OdometryRing::mark_break() {
  if (!break_pending_) ++break_count_;
  break_pending_ = true;
}

OdometryRing::Lookup OdometryRing::interpolate(std::int64_t stamp_us, std::int64_t max_gap_us, Pose2* out) const {
  if (ring_.empty() || stamp_us > ring_.back().stamp_us) return Lookup::kNotYet;
  if (stamp_us < ring_.front().stamp_us) return Lookup::kTooOld;
  // Newest first: scans are usually close to the head of the ring.
  std::size_t i = ring_.size() - 1U;
  while (ring_[i].stamp_us > stamp_us) --i;  // ring_[0].stamp_us <= stamp_us holds
  const Sample& lo = ring_[i];
  if (lo.stamp_us == stamp_us) {
    *out = lo.pose;
    return Lookup::kOk;
  }
  const Sample& hi = ring_[i + 1U];  // exists: stamp_us < back().stamp_us
  if (hi.segment_start || hi.stamp_us - lo.stamp_us > max_gap_us) return Lookup::kGap;
  const double f = static_cast<double>(stamp_us - lo.stamp_us) / static_cast<double>(hi.stamp_us - lo.stamp_us);
  *out = interpolate_se2(lo.pose, hi.pose, f);
  return Lookup::kOk;
}

const char* to_string(OdometryRing::Lookup l) {
  switch (l) {
    case OdometryRing::Lookup::kOk: return "ok";
    case OdometryRing::Lookup::kNotYet: return "not-yet";
    case OdometryRing::Lookup::kTooOld: return "too-old";
    case OdometryRing::Lookup::kGap: return "gap";
  }
  return "?";
}

}  // namespace sdpslam::daemon
