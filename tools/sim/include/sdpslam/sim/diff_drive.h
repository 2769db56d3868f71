#pragma once
// Differential-drive kinematics and a pure-pursuit route follower (Coulter, "Implementation
// of the pure pursuit path tracking algorithm", CMU-RI-TR-92-01) with speed and
// acceleration limits.
#include <cstddef>
#include <vector>

#include "sdpslam/core/pose2.h"
#include "sdpslam/sim/world.h"

namespace sdpslam::sim {

struct RobotLimits {
  double max_speed_mps = 0.5;
  double max_accel_mps2 = 0.5;
  double max_angular_speed_radps = 1.0;
  double max_angular_accel_radps2 = 2.0;
  double wheel_base_m = 0.4;  // distance between the wheels (odometry drift model)
};

struct FollowerOptions {
  double lookahead_m = 0.5;          // pure-pursuit carrot distance along the route
  double goal_tolerance_m = 0.05;    // finished when this close to the last waypoint
  double turn_in_place_rad = 1.0;    // carrot further off the heading than this: rotate on the spot
  double projection_window_m = 2.0;  // progress is searched only this far ahead (routes revisit corridors)
};

// Body-frame velocity command.
struct Twist {
  double v_mps = 0.0;
  double w_radps = 0.0;
};

// Wraps an angle to (-pi, pi] with std::fmod (exact: fmod introduces no rounding).
double wrap_angle_rad(double a);

// Exact motion of a unicycle that travels arc length `ds_m` while turning `dtheta_rad`
// (constant curvature), from pose p.
Pose2 integrate_arc(const Pose2& p, double ds_m, double dtheta_rad);

// Follows a Route: update() turns the current pose into a limited velocity command.
// The route must have >= 2 waypoints. Progress along the route is the projection of the
// pose onto the polyline, searched only within `projection_window_m` ahead of the
// previous progress, so that a route driving a corridor twice is followed in order.
class PathFollower {
 public:
  PathFollower(const Route& route, const FollowerOptions& options, const RobotLimits& limits);

  // Command for the next `dt_s` given the true pose; respects the speed limits and the
  // acceleration limits relative to the previous command. Within goal_tolerance_m of the
  // last waypoint it brakes to rest; zero once finished().
  Twist update(const Pose2& pose, double dt_s);

  bool finished() const { return finished_; }
  double progress_m() const { return progress_m_; }
  double route_length_m() const { return total_m_; }

 private:
  Point2 point_at(double s_m) const;
  void project(const Pose2& pose);

  Route route_;
  FollowerOptions options_;
  RobotLimits limits_;
  std::vector<double> cumulative_m_;  // arc length at each waypoint
  double total_m_ = 0.0;
  double progress_m_ = 0.0;
  std::size_t leg_ = 0;
  Twist last_;
  bool stopping_ = false;
  bool finished_ = false;
};

}  // namespace sdpslam::sim
