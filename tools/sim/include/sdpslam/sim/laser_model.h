#pragma once
// A planar laser scanner simulated by ray casting (ray_caster.h).
//
// Beam i points at -fov/2 + i * fov/(beam_count-1) in the laser frame (x forward,
// counter-clockwise positive), so the default 181 beams cover 180 deg at 1 deg, like the
// SICK LMS of the CARMEN logs. A beam's reading is the true distance to the nearest wall
// plus N(0, range_noise_std²), clamped to [min_range, max_range]; a wall beyond max_range
// (or no wall) reads exactly max_range, which RangeScan classifies as "no return".
// With probability spurious_max_prob a beam reads max_range whatever it sees (a missed
// return, as on glass or black surfaces). The laser sits at the robot's origin.
#include <cstdint>

#include "sdpslam/core/range_scan.h"
#include "sdpslam/sim/ray_caster.h"
#include "sdpslam/sim/rng.h"

namespace sdpslam::sim {

struct LaserOptions {
  std::uint32_t beam_count = 181;  // at most capacity::kMaxBeams
  double fov_deg = 180.0;          // (0, 360]
  double max_range_m = 8.0;
  double min_range_m = 0.02;
  double range_noise_std_m = 0.01;
  double spurious_max_prob = 0.002;
  std::uint32_t rate_hz = 10;
};

class LaserSimulator {
 public:
  // Keeps a reference to `caster`, which must outlive this object.
  LaserSimulator(const RayCaster& caster, const LaserOptions& options, std::uint64_t seed);

  // Fills `scan` (geometry, beam_count, ranges; not the stamp) for a laser at
  // `laser_pose` in the world. Draws the same number of random numbers per beam whatever
  // the scene, so noise realisations stay aligned between scans.
  void scan(const Pose2& laser_pose, RangeScan* scan);

  const ScanGeometry& geometry() const { return geometry_; }

 private:
  const RayCaster& caster_;
  LaserOptions options_;
  ScanGeometry geometry_;
  Rng rng_;
};

}  // namespace sdpslam::sim
