#pragma once
// A small synthetic world for the filter tests: a walled room with pillars, a robot
// driving a loop in it, exact laser scans by ray casting, and drifting odometry.
#include <cmath>
#include <cstdint>
#include <vector>

#include "sdpslam/core/pose2.h"
#include "sdpslam/core/range_scan.h"
#include "sdpslam/core/rng.h"

namespace sdpslam::test {

struct Segment {
  double x0, y0, x1, y1;
};

inline std::vector<Segment> room_world() {
  std::vector<Segment> s;
  auto box = [&s](double x0, double y0, double x1, double y1) {
    s.push_back({x0, y0, x1, y0});
    s.push_back({x1, y0, x1, y1});
    s.push_back({x1, y1, x0, y1});
    s.push_back({x0, y1, x0, y0});
  };
  box(-2.0, -2.0, 10.0, 7.0);  // outer walls
  box(1.5, 1.5, 2.5, 2.0);     // pillars and an inner block: features for matching
  box(5.0, 1.0, 5.6, 1.6);
  box(3.0, 3.5, 6.0, 4.0);
  box(7.5, 4.8, 8.2, 5.2);
  s.push_back({-2.0, 3.0, -0.5, 3.0});  // a wall stub
  s.push_back({8.5, -2.0, 8.5, -0.8});
  return s;
}

// A straight corridor 3 m wide along x from -2 m to length_m, turned by heading_rad
// about the origin, closed at both ends: plain walls, or walls with a door recess every
// 3 m on each side (1 m wide, 0.5 m deep on the right, 0.4 m on the left).
inline std::vector<Segment> corridor_world(bool doors, double heading_rad, double length_m) {
  std::vector<Segment> w;
  const double c = std::cos(heading_rad);
  const double s = std::sin(heading_rad);
  auto add = [&](double x0, double y0, double x1, double y1) {
    w.push_back({x0 * c - y0 * s, x0 * s + y0 * c, x1 * c - y1 * s, x1 * s + y1 * c});
  };
  const double half = 1.5;
  if (!doors) {
    add(-2.0, -half, length_m, -half);
    add(-2.0, half, length_m, half);
  } else {
    for (double x = -2.0; x < length_m; x += 3.0) {
      add(x, -half, x + 2.0, -half);
      add(x + 2.0, -half, x + 2.0, -half - 0.5);
      add(x + 2.0, -half - 0.5, x + 3.0, -half - 0.5);
      add(x + 3.0, -half - 0.5, x + 3.0, -half);
      add(x + 1.0, half, x + 3.0, half);
      add(x + 1.0, half, x + 1.0, half + 0.4);
      add(x, half + 0.4, x + 1.0, half + 0.4);
      add(x, half + 0.4, x, half);
    }
  }
  add(length_m, -half - 1.0, length_m, half + 1.0);
  add(-2.0, -half - 1.0, -2.0, half + 1.0);
  return w;
}

inline double cast_ray(const std::vector<Segment>& world, double ox, double oy, double dx, double dy, double max_m) {
  double best = max_m;
  for (const Segment& g : world) {
    const double ex = g.x1 - g.x0, ey = g.y1 - g.y0;
    const double den = dx * ey - dy * ex;
    if (std::fabs(den) < 1e-12) continue;
    const double wx = g.x0 - ox, wy = g.y0 - oy;
    const double t = (wx * ey - wy * ex) / den;
    const double u = (wx * dy - wy * dx) / den;
    if (t > 0.0 && u >= 0.0 && u <= 1.0 && t < best) best = t;
  }
  return best;
}

inline void make_scan(const std::vector<Segment>& world, const Pose2& pose, std::int64_t stamp_us, RangeScan* scan,
                      Rng* noise = nullptr, double sigma_m = 0.0) {
  scan->stamp_us = stamp_us;
  scan->geometry.angle_min_rad = static_cast<float>(-M_PI / 2.0);
  scan->geometry.angle_increment_rad = static_cast<float>(M_PI / 180.0);
  scan->geometry.range_min_m = 0.05F;
  scan->geometry.range_max_m = 30.0F;
  scan->beam_count = 181;
  for (std::uint32_t i = 0; i < scan->beam_count; ++i) {
    const double a = pose.heading_rad + static_cast<double>(scan->beam_angle_rad(i));
    double r = cast_ray(world, pose.x_m, pose.y_m, std::cos(a), std::sin(a), 30.0);
    if (noise != nullptr && r < 30.0) r += noise->gaussian(sigma_m);
    scan->ranges_m[i] = static_cast<float>(r);
  }
}

// True poses of a loop around the inner block (0.1 m or ~6 deg per step), and odometry
// that over-reads rotation by 4 % and drifts sideways: after a loop it is off by ~1 m.
struct SimRun {
  std::vector<Pose2> truth;
  std::vector<Pose2> odom;
};

inline SimRun make_loop(std::uint32_t loops = 1U, std::uint64_t seed = 7U) {
  SimRun run;
  const double corners[4][2] = {{0.0, 0.0}, {7.0, 0.0}, {7.0, 5.5}, {0.0, 5.5}};
  Pose2 p{0.0, 0.0, 0.0};
  run.truth.push_back(p);
  for (std::uint32_t l = 0; l < loops; ++l) {
    for (int c = 0; c < 4; ++c) {
      const double* to = corners[(c + 1) % 4];
      // Drive straight to the next corner.
      while (true) {
        const double dx = to[0] - p.x_m, dy = to[1] - p.y_m;
        const double d = std::sqrt(dx * dx + dy * dy);
        if (d < 1e-9) break;
        const double step = d < 0.1 ? d : 0.1;
        p.x_m += step * dx / d;
        p.y_m += step * dy / d;
        run.truth.push_back(p);
      }
      p.x_m = to[0];
      p.y_m = to[1];
      // Turn left 90 degrees in place.
      for (int k = 0; k < 15; ++k) {
        p.heading_rad = normalize_angle_rad(p.heading_rad + M_PI / 30.0);
        run.truth.push_back(p);
      }
    }
  }
  Rng rng(seed);
  Pose2 o = run.truth[0];
  run.odom.push_back(o);
  for (std::size_t i = 1; i < run.truth.size(); ++i) {
    Pose2 d = between(run.truth[i - 1], run.truth[i]);
    d.heading_rad = d.heading_rad * 1.04 + rng.gaussian(0.003);
    d.x_m = d.x_m * 1.02 + rng.gaussian(0.004);
    d.y_m = d.y_m + 0.01 * d.x_m + rng.gaussian(0.004);
    o = o.compose(d);
    run.odom.push_back(o);
  }
  return run;
}

}  // namespace sdpslam::test
