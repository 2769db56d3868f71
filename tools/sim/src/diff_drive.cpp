#include "sdpslam/sim/diff_drive.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace sdpslam::sim {

double wrap_angle_rad(double a) {
  constexpr double kPi = 3.14159265358979323846;
  constexpr double kTwoPi = 2.0 * kPi;
  a = std::fmod(a, kTwoPi);
  if (a <= -kPi) a += kTwoPi;
  if (a > kPi) a -= kTwoPi;
  return a;
}

Pose2 integrate_arc(const Pose2& p, double ds_m, double dtheta_rad) {
  // Chord of the arc: length ds * sinc(dθ/2), direction heading + dθ/2.
  const double half = 0.5 * dtheta_rad;
  const double chord = std::fabs(half) < 1e-9 ? ds_m : ds_m * std::sin(half) / half;
  const double dir = p.heading_rad + half;
  return Pose2{p.x_m + chord * std::cos(dir), p.y_m + chord * std::sin(dir),
               wrap_angle_rad(p.heading_rad + dtheta_rad)};
}

PathFollower::PathFollower(const Route& route, const FollowerOptions& options, const RobotLimits& limits)
    : route_(route), options_(options), limits_(limits) {
  cumulative_m_.push_back(0.0);
  for (std::size_t i = 1; i < route_.waypoints.size(); ++i) {
    const Point2& a = route_.waypoints[i - 1];
    const Point2& b = route_.waypoints[i];
    cumulative_m_.push_back(cumulative_m_.back() + std::hypot(b.x_m - a.x_m, b.y_m - a.y_m));
  }
  total_m_ = cumulative_m_.back();
  finished_ = route_.waypoints.size() < 2;
}

Point2 PathFollower::point_at(double s_m) const {
  s_m = std::clamp(s_m, 0.0, total_m_);
  std::size_t i = leg_;
  while (i + 2 < cumulative_m_.size() && cumulative_m_[i + 1] < s_m) ++i;
  const Point2& a = route_.waypoints[i];
  const Point2& b = route_.waypoints[i + 1];
  const double len = cumulative_m_[i + 1] - cumulative_m_[i];
  const double u = len > 0.0 ? (s_m - cumulative_m_[i]) / len : 0.0;
  return Point2{a.x_m + u * (b.x_m - a.x_m), a.y_m + u * (b.y_m - a.y_m)};
}

void PathFollower::project(const Pose2& pose) {
  const double limit = progress_m_ + options_.projection_window_m;
  double best_d2 = std::numeric_limits<double>::infinity();
  double best_s = progress_m_;
  std::size_t best_leg = leg_;
  for (std::size_t i = leg_; i + 1 < route_.waypoints.size() && cumulative_m_[i] <= limit; ++i) {
    const Point2& a = route_.waypoints[i];
    const Point2& b = route_.waypoints[i + 1];
    const double ex = b.x_m - a.x_m;
    const double ey = b.y_m - a.y_m;
    const double len = cumulative_m_[i + 1] - cumulative_m_[i];
    double u = ((pose.x_m - a.x_m) * ex + (pose.y_m - a.y_m) * ey) / (len * len);
    // Stay inside the window and never go back.
    const double u_lo = std::max(0.0, (progress_m_ - cumulative_m_[i]) / len);
    const double u_hi = std::min(1.0, (limit - cumulative_m_[i]) / len);
    if (u_lo > u_hi) continue;
    u = std::clamp(u, u_lo, u_hi);
    const double px = a.x_m + u * ex - pose.x_m;
    const double py = a.y_m + u * ey - pose.y_m;
    const double d2 = px * px + py * py;
    if (d2 < best_d2) {
      best_d2 = d2;
      best_s = cumulative_m_[i] + u * len;
      best_leg = i;
    }
  }
  progress_m_ = std::max(progress_m_, best_s);
  leg_ = best_leg;
}

Twist PathFollower::update(const Pose2& pose, double dt_s) {
  if (finished_) return Twist{};
  const double dv = limits_.max_accel_mps2 * dt_s;
  const double dw = limits_.max_angular_accel_radps2 * dt_s;
  project(pose);
  const Point2& goal = route_.waypoints.back();
  const double goal_dist = std::hypot(goal.x_m - pose.x_m, goal.y_m - pose.y_m);
  const double remaining = total_m_ - progress_m_;
  if (remaining <= options_.lookahead_m && goal_dist <= options_.goal_tolerance_m) stopping_ = true;
  if (stopping_) {
    // Brake within the acceleration limits; finished once at rest.
    last_.v_mps = std::max(0.0, last_.v_mps - dv);
    last_.w_radps = last_.w_radps > 0.0 ? std::max(0.0, last_.w_radps - dw) : std::min(0.0, last_.w_radps + dw);
    if (last_.v_mps == 0.0 && last_.w_radps == 0.0) finished_ = true;
    return last_;
  }

  const Point2 carrot = point_at(progress_m_ + options_.lookahead_m);
  const double c = std::cos(pose.heading_rad);
  const double s = std::sin(pose.heading_rad);
  const double wx = carrot.x_m - pose.x_m;
  const double wy = carrot.y_m - pose.y_m;
  const double fx = c * wx + s * wy;   // carrot in the robot frame
  const double fy = -s * wx + c * wy;
  const double alpha = std::atan2(fy, fx);
  const double d2 = fx * fx + fy * fy;

  Twist want;
  if (std::fabs(alpha) > options_.turn_in_place_rad) {
    want.v_mps = 0.0;
    want.w_radps = std::copysign(limits_.max_angular_speed_radps, alpha);
  } else {
    const double curvature = d2 > 1e-12 ? 2.0 * fy / d2 : 0.0;
    double v = limits_.max_speed_mps;
    if (std::fabs(curvature) * v > limits_.max_angular_speed_radps) {
      v = limits_.max_angular_speed_radps / std::fabs(curvature);
    }
    // Brake so that the robot can stop on the goal: v <= sqrt(2 a d).
    // Aim to come to rest half the tolerance before the goal, so that braking from the
    // moment the tolerance is reached ends close to the goal.
    const double to_go = std::max(remaining, goal_dist) - 0.5 * options_.goal_tolerance_m;
    v = std::min(v, std::sqrt(2.0 * limits_.max_accel_mps2 * std::max(0.0, to_go)));
    want.v_mps = v;
    want.w_radps = v * curvature;
  }
  last_.v_mps = std::clamp(want.v_mps, last_.v_mps - dv, last_.v_mps + dv);
  last_.w_radps = std::clamp(want.w_radps, last_.w_radps - dw, last_.w_radps + dw);
  last_.v_mps = std::clamp(last_.v_mps, 0.0, limits_.max_speed_mps);
  last_.w_radps = std::clamp(last_.w_radps, -limits_.max_angular_speed_radps, limits_.max_angular_speed_radps);
  return last_;
}

}  // namespace sdpslam::sim
