#pragma once
// A small world for sdpslamd's engine tests: a 10 m x 6 m box, and the small sdp
// configuration that ends several segments in a few metres of it.
#include <cmath>
#include <cstdint>

#include "sdpslam/core/range_scan.h"
#include "sdpslam/daemon/daemon_config.h"

namespace sdpslam::test {

// The box seen from (x, y) looking along +x: 181 beams over 180 degrees.
inline void box_scan(double x, double y, std::int64_t stamp_us, RangeScan* s) {
  s->stamp_us = stamp_us;
  s->beam_count = 181U;
  s->geometry.angle_min_rad = static_cast<float>(-M_PI / 2.0);
  s->geometry.angle_increment_rad = static_cast<float>(M_PI / 180.0);
  s->geometry.range_min_m = 0.05F;
  s->geometry.range_max_m = 30.0F;
  for (std::uint32_t i = 0; i < s->beam_count; ++i) {
    const double a = static_cast<double>(s->beam_angle_rad(i));
    const double c = std::cos(a), n = std::sin(a);
    double t = 1e9;
    if (c > 1e-9) t = std::fmin(t, (10.0 - x) / c);
    if (c < -1e-9) t = std::fmin(t, (0.0 - x) / c);
    if (n > 1e-9) t = std::fmin(t, (6.0 - y) / n);
    if (n < -1e-9) t = std::fmin(t, (0.0 - y) / n);
    s->ranges_m[i] = static_cast<float>(t);
  }
}

// SDP-SLAM small enough for the box: 5 bottom / 8 top particles, a segment every 5
// processed scans, 3 live levels.
inline daemon::DaemonConfig small_sdp_config() {
  daemon::DaemonConfig c;
  c.mode = daemon::SlamMode::kSdp;
  c.slam.filter.particle_count = 5U;
  c.slam.filter.update_min_travel_m = 0.1;
  c.slam.filter.map_width_m = 30.0;
  c.slam.filter.map_height_m = 30.0;
  c.sdp.top_particles = 8U;
  c.sdp.period_scans = 5U;
  c.sdp.period_travel_m = 0.0;
  c.sdp.min_segment_scans = 3U;
  c.sdp.max_levels = 3U;
  c.sdp.map_tile_capacity = 2000U;
  c.sdp.map_observation_capacity = 300000U;
  c.max_trajectory_scans = 200U;
  return c;
}

}  // namespace sdpslam::test
