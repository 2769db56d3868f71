#include "sdpslam/sim/builtin_worlds.h"

namespace sdpslam::sim {

SimulationOptions paper_world_options(SimulationOptions base) { return base; }

SimulationOptions large_world_options(SimulationOptions base) {
  base.laser.fov_deg = kLargeLaserFov_deg;
  base.laser.beam_count = kLargeLaserBeams;
  base.laser.max_range_m = kLargeLaserMaxRange_m;
  base.laser.rate_hz = kLargeLaserRate_hz;
  base.robot.max_speed_mps = kLargeMaxSpeed_mps;
  base.odometry.wheel_radius_mismatch = kLargeWheelRadiusMismatch;
  return base;
}

const std::array<BuiltinWorld, kBuiltinWorldCount>& builtin_worlds() {
  static const std::array<BuiltinWorld, kBuiltinWorldCount> worlds = {{
      {"paper", "the SDP-SLAM paper's nested 28 m / 80 m loops, 1.8 m corridors (default)", builtin_world,
       builtin_route, paper_world_options},
      {"large",
       "a 203 m x 123 m building, 3 m corridors, an open hall, 2.26 km of nested loops",
       large_world, large_route, large_world_options},
  }};
  return worlds;
}

const BuiltinWorld* find_builtin_world(const std::string& name) {
  for (const BuiltinWorld& w : builtin_worlds()) {
    if (name == w.name) return &w;
  }
  return nullptr;
}

}  // namespace sdpslam::sim
