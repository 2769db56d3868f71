#pragma once
// Runs the synthetic loop (sim_world.h) through a DpSlamFilter.
#include <cmath>
#include <cstring>
#include <memory>
#include <vector>

#include "sdpslam/core/bottom/dpslam_filter.h"
#include "sim_world.h"

namespace sdpslam::test {

inline DpSlamOptions sim_options(std::uint32_t particles) {
  DpSlamOptions o;
  o.particle_count = particles;
  o.update_min_travel_m = 0.15;
  o.update_min_rotation_rad = 0.15;
  o.map_width_m = 30.0;
  o.map_height_m = 30.0;
  o.map_observations_base = 100000U;
  o.map_observations_per_particle = 8000U;
  o.path_entries_per_particle = 64U;
  o.motion.alpha_rot_from_rot = 0.02;
  o.motion.alpha_rot_from_trans = 0.02;
  o.motion.alpha_trans_from_trans = 0.02;
  o.motion.alpha_trans_from_rot = 0.001;
  o.beam.weight_beam_stride = 3;
  o.beam.max_update_range_m = 12.0;
  return o;
}

// Owns the arena buffer and the filter (both large: heap-allocated at set-up).
struct FilterRig {
  std::vector<unsigned char> buffer;
  Arena arena;
  std::unique_ptr<DpSlamFilter> filter = std::make_unique<DpSlamFilter>();
  std::unique_ptr<RangeScan> scan = std::make_unique<RangeScan>();
  double laser_sigma_m = 0.0;  // range noise of the simulated laser (0: exact ranges)
  Rng laser_noise{99U};

  bool init(const DpSlamOptions& o, std::uint64_t seed) {
    buffer.assign(DpSlamFilter::required_arena_bytes(o), 0);
    arena.reset(buffer.data(), buffer.size());
    return filter->init(o, arena, seed);
  }
  // Feeds scan i of `run`; returns the step result.
  StepResult step(const SimRun& run, const std::vector<Segment>& world, std::size_t i) {
    make_scan(world, run.truth[i], static_cast<std::int64_t>(i) * 100000, scan.get(),
              laser_sigma_m > 0.0 ? &laser_noise : nullptr, laser_sigma_m);
    OdometrySample od;
    od.stamp_us = static_cast<std::int64_t>(i) * 100000;
    od.pose = run.odom[i];
    return filter->process(od, *scan);
  }
};

// Mean position error (m) of poses given in the frame of the first pose.
inline double mean_error(const std::vector<Pose2>& est_in_start, const std::vector<Pose2>& truth) {
  double sum = 0.0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const Pose2 t = between(truth[0], truth[i]);
    sum += std::hypot(est_in_start[i].x_m - t.x_m, est_in_start[i].y_m - t.y_m);
  }
  return sum / static_cast<double>(truth.size());
}

}  // namespace sdpslam::test
