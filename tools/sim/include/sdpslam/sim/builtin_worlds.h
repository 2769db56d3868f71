#pragma once
// The named built-in worlds of `sdpslam simulate --world NAME`: each is a world, the
// route made for it, and the robot and sensors it is meant to be driven with (a preset
// over SimulationOptions; the command line's explicit options still win over it).
//   paper  the SDP-SLAM paper's nested 28 m / 80 m loops (world.h), the paper's robot and
//          laser: the SimulationOptions defaults. The default world.
//   large  a 203 m x 123 m building, 2.26 km of nested loops and an open hall (world.h),
//          driven with large_world_options().
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

#include "sdpslam/core/capacities.h"
#include "sdpslam/sim/simulator.h"
#include "sdpslam/sim/world.h"

namespace sdpslam::sim {

struct BuiltinWorld {
  const char* name;
  const char* description;  // one line, for --help
  World (*world)();
  Route (*route)();
  // The world's robot and sensors applied over `base`: the fields the world prescribes
  // change, every other one (seed, rates, noise the world does not fix) is kept.
  SimulationOptions (*preset)(SimulationOptions base);
};

inline constexpr std::size_t kBuiltinWorldCount = 2;

// The built-in worlds, the default ("paper") first.
const std::array<BuiltinWorld, kBuiltinWorldCount>& builtin_worlds();
// The built-in world called `name` (exact, case-sensitive), or null iff there is none.
const BuiltinWorld* find_builtin_world(const std::string& name);

// The paper world's preset: `base` unchanged (the defaults are the paper's).
SimulationOptions paper_world_options(SimulationOptions base);

// The large world's laser: 270 deg at 0.5 deg steps, 30 m, 10 Hz, a Hokuyo UTM-30LX-like
// scanner. 541 beams, or the largest odd count under capacity::kMaxBeams in a build that
// lowers it (the beams then stay symmetric about the heading).
inline constexpr std::uint32_t kLargeLaserBeams =
    capacity::kMaxBeams >= 541U ? 541U
                                : (capacity::kMaxBeams % 2U == 1U ? capacity::kMaxBeams : capacity::kMaxBeams - 1U);
inline constexpr double kLargeLaserFov_deg = 270.0;
inline constexpr double kLargeLaserMaxRange_m = 30.0;
inline constexpr std::uint32_t kLargeLaserRate_hz = 10;
inline constexpr double kLargeMaxSpeed_mps = 1.0;
// Odometry of a cheap robot: the default random walks and scale error, wheel radii 1e-4
// apart: a steady heading drift of 1e-4 / wheel_base rad per metre, 14 deg per km with
// the default 0.4 m wheel base.
inline constexpr double kLargeWheelRadiusMismatch = 0.0001;

// The large world's preset: the laser and top speed above and that odometry drift.
SimulationOptions large_world_options(SimulationOptions base);

}  // namespace sdpslam::sim
