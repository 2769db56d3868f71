#include "sdpslam/sim/simulator.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "sdpslam/sim/ray_caster.h"

namespace sdpslam::sim {

namespace {
bool positive_finite(double v) { return std::isfinite(v) && v > 0.0; }
bool non_negative_finite(double v) { return std::isfinite(v) && v >= 0.0; }
}  // namespace

bool validate_simulation_options(const SimulationOptions& o, std::string* error) {
  auto fail = [&](const std::string& what) {
    *error = "invalid simulation option: " + what;
    return false;
  };
  if (o.physics_rate_hz == 0U || 1000000U % o.physics_rate_hz != 0U)
    return fail("physics rate must divide 1000000 Hz (got " + std::to_string(o.physics_rate_hz) + ")");
  if (o.odom_rate_hz == 0U || o.physics_rate_hz % o.odom_rate_hz != 0U)
    return fail("odometry rate must divide the physics rate " + std::to_string(o.physics_rate_hz) + " Hz (got " +
                std::to_string(o.odom_rate_hz) + ")");
  if (o.laser.rate_hz == 0U || o.physics_rate_hz % o.laser.rate_hz != 0U)
    return fail("laser rate must divide the physics rate " + std::to_string(o.physics_rate_hz) + " Hz (got " +
                std::to_string(o.laser.rate_hz) + ")");
  if (!non_negative_finite(o.max_duration_s)) return fail("max duration must be >= 0 s");
  if (!positive_finite(o.robot.max_speed_mps)) return fail("speed must be > 0 m/s");
  if (!positive_finite(o.robot.max_accel_mps2)) return fail("acceleration must be > 0 m/s^2");
  if (!positive_finite(o.robot.max_angular_speed_radps)) return fail("angular speed must be > 0 rad/s");
  if (!positive_finite(o.robot.max_angular_accel_radps2)) return fail("angular acceleration must be > 0 rad/s^2");
  if (!positive_finite(o.robot.wheel_base_m)) return fail("wheel base must be > 0 m");
  if (!positive_finite(o.follower.lookahead_m)) return fail("lookahead must be > 0 m");
  if (!positive_finite(o.follower.goal_tolerance_m)) return fail("goal tolerance must be > 0 m");
  if (!positive_finite(o.follower.turn_in_place_rad)) return fail("turn-in-place angle must be > 0 rad");
  if (!(o.follower.projection_window_m > o.follower.lookahead_m))
    return fail("projection window must exceed the lookahead");
  const OdometryNoise& n = o.odometry;
  if (!non_negative_finite(n.trans_m_per_sqrt_m) || !non_negative_finite(n.rot_rad_per_sqrt_rad) ||
      !non_negative_finite(n.rot_rad_per_sqrt_m))
    return fail("odometry noise coefficients must be finite and >= 0");
  if (!std::isfinite(n.scale_error) || std::fabs(n.scale_error) >= 0.5)
    return fail("odometry scale error must be in (-0.5, 0.5)");
  if (!std::isfinite(n.wheel_radius_mismatch) || std::fabs(n.wheel_radius_mismatch) >= 0.5)
    return fail("wheel radius mismatch must be in (-0.5, 0.5)");
  const LaserOptions& l = o.laser;
  if (l.beam_count < 2U || l.beam_count > capacity::kMaxBeams)
    return fail("beam count must be in [2, " + std::to_string(capacity::kMaxBeams) + "] (got " +
                std::to_string(l.beam_count) + ")");
  if (!(l.fov_deg > 0.0 && l.fov_deg <= 360.0)) return fail("field of view must be in (0, 360] deg");
  if (!positive_finite(l.max_range_m)) return fail("max range must be > 0 m");
  if (!non_negative_finite(l.min_range_m) || !(l.min_range_m < l.max_range_m))
    return fail("min range must be >= 0 and below max range");
  if (!non_negative_finite(l.range_noise_std_m)) return fail("range noise must be >= 0 m");
  if (!(l.spurious_max_prob >= 0.0 && l.spurious_max_prob <= 1.0))
    return fail("spurious max-range probability must be in [0, 1]");
  return true;
}

bool run_simulation(const World& world, const Route& route, const SimulationOptions& options,
                    SimulationSink* sink, SimulationSummary* summary, std::string* error) {
  if (!validate_simulation_options(options, error)) return false;
  if (route.waypoints.size() < 2) {
    *error = "route needs at least 2 waypoints";
    return false;
  }
  *summary = SimulationSummary{};
  const std::int64_t dt_us = 1000000 / static_cast<std::int64_t>(options.physics_rate_hz);
  const double dt_s = static_cast<double>(dt_us) * 1e-6;
  const std::uint64_t odom_every = options.physics_rate_hz / options.odom_rate_hz;
  const std::uint64_t laser_every = options.physics_rate_hz / options.laser.rate_hz;
  const double route_len = route_length_m(route);
  const double max_duration_s = options.max_duration_s > 0.0
                                    ? options.max_duration_s
                                    : 3.0 * route_len / options.robot.max_speed_mps + 60.0;
  const std::uint64_t max_steps = static_cast<std::uint64_t>(std::ceil(max_duration_s / dt_s));

  const RayCaster caster(world);
  LaserSimulator laser(caster, options.laser, options.seed);
  PathFollower follower(route, options.follower, options.robot);
  const Pose2 start{route.waypoints[0].x_m, route.waypoints[0].y_m, route_start_heading_rad(route)};
  Pose2 truth = start;
  WheelOdometry odometry(start, options.odometry, options.robot.wheel_base_m, options.seed);

  io::OdomRecord odom_record;
  io::LaserRecord laser_record;
  laser_record.keyword = "ROBOTLASER1";
  laser_record.has_laser_pose = true;
  laser_record.has_odom_pose = true;
  double min_clearance = std::numeric_limits<double>::infinity();
  Twist cmd;

  std::uint64_t k = 0;
  for (;; ++k) {
    const std::int64_t stamp_us = options.start_stamp_us + static_cast<std::int64_t>(k) * dt_us;
    if (k % odom_every == 0U) {
      odom_record.stamp_us = stamp_us;
      odom_record.logger_stamp_us = stamp_us;
      odom_record.pose = odometry.pose();
      odom_record.tv_mps = cmd.v_mps;
      odom_record.rv_radps = cmd.w_radps;
      sink->on_odom(odom_record);
      ++summary->odom_count;
    }
    if (k % laser_every == 0U) {
      laser.scan(truth, &laser_record.scan);
      laser_record.stamp_us = stamp_us;
      laser_record.logger_stamp_us = stamp_us;
      laser_record.scan.stamp_us = stamp_us;
      laser_record.laser_pose = odometry.pose();  // laser at the origin: laser pose = odometry pose
      laser_record.odom_pose = odometry.pose();
      sink->on_laser(laser_record, truth);
      sink->on_progress(follower.progress_m(), follower.route_length_m());
      ++summary->scan_count;
      min_clearance = std::min(min_clearance, distance_to_nearest_wall_m(world, truth.x_m, truth.y_m));
    }
    // The log ends with a scan of the robot standing at the goal.
    if ((follower.finished() && k % laser_every == 0U) || k >= max_steps) break;
    cmd = follower.update(truth, dt_s);
    if (follower.finished()) continue;
    const double ds = cmd.v_mps * dt_s;
    const double dtheta = cmd.w_radps * dt_s;
    truth = integrate_arc(truth, ds, dtheta);
    odometry.step(ds, dtheta);
    summary->distance_m += std::fabs(ds);
    summary->rotation_rad += std::fabs(dtheta);
  }
  summary->reached_goal = follower.finished();
  summary->steps = k;
  summary->duration_s = static_cast<double>(k) * dt_s;
  summary->final_true = truth;
  summary->final_odom = odometry.pose();
  summary->end_position_error_m = std::hypot(truth.x_m - odometry.pose().x_m, truth.y_m - odometry.pose().y_m);
  summary->end_heading_error_rad = std::fabs(wrap_angle_rad(truth.heading_rad - odometry.pose().heading_rad));
  summary->min_wall_clearance_m = min_clearance;
  return true;
}

}  // namespace sdpslam::sim
