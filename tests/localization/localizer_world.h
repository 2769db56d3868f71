#pragma once
// A small asymmetric building for the localizer's tests: a 16 m x 10 m grid at 0.1 m with
// outer walls, an inner wall with a door, two boxes and a pillar, and a ray caster that
// sees it as a 181-beam 180° laser of 20 m. No symmetry maps one place onto another.
#include <cmath>
#include <cstdint>
#include <vector>

#include "sdpslam/core/localization/monte_carlo_localizer.h"

namespace sdpslam::test {

struct LocalizerWorld {
  static constexpr std::uint32_t kWidth = 160U;
  static constexpr std::uint32_t kHeight = 100U;
  static constexpr double kRes = 0.1;
  std::vector<std::uint8_t> cells;

  LocalizerWorld() : cells(kWidth * kHeight, LocalizerMap::kFree) {
    for (std::uint32_t c = 0; c < kWidth; ++c) {
      set(c, 0);
      set(c, kHeight - 1U);
    }
    for (std::uint32_t r = 0; r < kHeight; ++r) {
      set(0, r);
      set(kWidth - 1U, r);
      if (r < 40U || r > 52U) set(70, r);  // inner wall at x = 7 m, door at y 4.0 .. 5.2 m
    }
    box(20, 20, 35, 28);    // x 2.0-3.5, y 2.0-2.8
    box(110, 60, 118, 85);  // x 11.0-11.8, y 6.0-8.5
    box(130, 15, 133, 18);  // a pillar
    box(40, 70, 55, 72);    // a bench
  }
  void set(std::uint32_t c, std::uint32_t r) { cells[r * kWidth + c] = LocalizerMap::kOccupied; }
  void box(std::uint32_t c0, std::uint32_t r0, std::uint32_t c1, std::uint32_t r1) {
    for (std::uint32_t r = r0; r <= r1; ++r)
      for (std::uint32_t c = c0; c <= c1; ++c) set(c, r);
  }
  LocalizerMap map() const {
    LocalizerMap m;
    m.width = kWidth;
    m.height = kHeight;
    m.resolution_m = kRes;
    m.origin_x_m = 0.0;
    m.origin_y_m = 0.0;
    m.cells = cells.data();
    return m;
  }
  bool occupied(double x, double y) const {
    if (x < 0.0 || y < 0.0) return true;
    const auto c = static_cast<std::uint32_t>(x / kRes), r = static_cast<std::uint32_t>(y / kRes);
    return c >= kWidth || r >= kHeight || cells[r * kWidth + c] == LocalizerMap::kOccupied;
  }
  // The scan a laser at `pose` (mounted at the robot's centre) sees; march at 1 cm.
  void scan(const Pose2& pose, std::int64_t stamp_us, RangeScan* s) const {
    s->stamp_us = stamp_us;
    s->beam_count = 181U;
    s->geometry.angle_min_rad = static_cast<float>(-M_PI / 2.0);
    s->geometry.angle_increment_rad = static_cast<float>(M_PI / 180.0);
    s->geometry.range_min_m = 0.05F;
    s->geometry.range_max_m = 20.0F;
    s->geometry.laser_in_base = Pose2{};
    for (std::uint32_t i = 0; i < s->beam_count; ++i) {
      const double a = pose.heading_rad + static_cast<double>(s->beam_angle_rad(i));
      double r = 0.0;
      while (r < 20.0 && !occupied(pose.x_m + r * std::cos(a), pose.y_m + r * std::sin(a))) r += 0.01;
      s->ranges_m[i] = static_cast<float>(r);
    }
  }
};

// A drive through both rooms: waypoints visited in order at 0.1 m per step.
inline std::vector<Pose2> localizer_route() {
  const double pts[][2] = {{2.0, 5.0}, {5.5, 4.6}, {8.5, 4.6}, {13.5, 3.0}, {14.0, 8.0}, {9.0, 8.5}, {8.0, 4.6},
                           {4.0, 4.4}, {1.5, 8.0}};
  std::vector<Pose2> route;
  for (std::size_t k = 0; k + 1U < sizeof pts / sizeof pts[0]; ++k) {
    const double dx = pts[k + 1][0] - pts[k][0], dy = pts[k + 1][1] - pts[k][1];
    const double len = std::sqrt(dx * dx + dy * dy);
    const double heading = std::atan2(dy, dx);
    for (double s = 0.0; s < len; s += 0.1) {
      route.push_back(Pose2{pts[k][0] + dx * s / len, pts[k][1] + dy * s / len, heading});
    }
  }
  return route;
}

}  // namespace sdpslam::test
