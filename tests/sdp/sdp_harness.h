#pragma once
// Runs the synthetic room loop (tests/dpslam_filter/sim_world.h) through SdpSlam.
#include <cstring>
#include <memory>
#include <vector>

#include "../dpslam_filter/filter_harness.h"
#include "sdpslam/core/sdp_slam.h"

namespace sdpslam::test {

// Small two-level configuration: 5 bottom particles, 12 top particles, short segments and
// a PGS of 4 levels so that a few loops fill it and levels become permanent.
inline SdpOptions small_sdp_options() {
  SdpOptions s;
  s.top_particles = 12U;
  s.period_travel_m = 3.0;
  s.min_segment_scans = 5U;
  s.max_segment_scans = 60U;
  s.max_levels = 4U;
  s.max_permanent_submaps = 16U;
  s.skeleton_points = 200U;
  s.skeleton_max_side_m = 16.0;
  s.evaluations_per_scan = 4U;
  s.min_overlap_m2 = 1.0;
  s.rounds_per_segment = 1U;   // keeps the tests quick: the small room overlaps everywhere
  s.max_pairs_per_sample = 3U;
  s.map_tile_capacity = 0U;         // the DP map is sized by the bottom options here
  // Room for the observations of every live level (a few loops of the room hold ~230,000
  // at their peak): the tests see the PGS fill, not the pool.
  s.map_observation_capacity = 300000U;
  return s;
}

struct SdpRig {
  std::vector<unsigned char> buffer;
  Arena arena;
  std::unique_ptr<SdpSlam> slam = std::make_unique<SdpSlam>();

  bool init(const DpSlamOptions& b, const SdpOptions& s, std::uint64_t seed) {
    buffer.assign(SdpSlam::required_arena_bytes(b, s), 0);
    arena.reset(buffer.data(), buffer.size());
    return slam->init(b, s, arena, seed);
  }
};

// Scans of `loops` loops generated up front (the generator uses the heap).
struct ScanSet {
  SimRun run;
  std::vector<std::unique_ptr<RangeScan>> scans;
  explicit ScanSet(std::uint32_t loops) : run(make_loop(loops)) {
    const auto world = room_world();
    for (std::size_t i = 0; i < run.truth.size(); ++i) {
      scans.push_back(std::make_unique<RangeScan>());
      make_scan(world, run.truth[i], static_cast<std::int64_t>(i) * 100000, scans.back().get());
    }
  }
  OdometrySample odom(std::size_t i) const {
    OdometrySample o;
    o.stamp_us = scans[i]->stamp_us;
    o.pose = run.odom[i];
    return o;
  }
};

// The permanent path: local poses by level, and each level's latest frame.
class CollectPoses final : public SdpPathSink {
 public:
  void on_pose(std::uint32_t level, std::int64_t s, const Pose2& p) override {
    levels.push_back(level);
    stamps.push_back(s);
    local.push_back(p);
  }
  void on_frame(std::uint32_t level, const Pose2& f) override {
    if (level >= frames.size()) frames.resize(level + 1U);
    frames[level] = f;
  }
  // Poses in the global frame.
  std::vector<Pose2> poses() const {
    std::vector<Pose2> out;
    for (std::size_t k = 0; k < local.size(); ++k) out.push_back(frames.at(levels[k]).compose(local[k]));
    return out;
  }
  std::vector<std::uint32_t> levels;
  std::vector<std::int64_t> stamps;
  std::vector<Pose2> local;
  std::vector<Pose2> frames;
};

}  // namespace sdpslam::test
