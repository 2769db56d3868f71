#pragma once
// The bottom-level DP-SLAM particle filter (paper §II-A; Algorithm 1 line 3, "DP-SLAM
// update"); on its own, the DP-SLAM baseline of §IV.
//
// Each processed scan:
//   1. propagate: every particle samples a pose from the odometry motion model
//      (motion_model.h) around its previous pose; or, with the improved proposal
//      (DpSlamOptions::proposal), around a scan match against its own map view, held to
//      the odometry's travel where the map is silent (scan_matcher.h), falling back to
//      the odometry model where the match fails;
//   2. weight: log p(scan | pose, particle's map) through the DP map (beam_model.h);
//   3. resample (low variance) iff N_eff < resample_neff_ratio · N (resampling.h);
//   4. map update: every particle that survives resampling writes the scan into its own
//      ancestry node's observations (hits at end points, misses along rays) and records
//      its pose on that node's path; then every drawn particle becomes a new child node
//      (duplicates of one particle become siblings that inherit the same map). Where the
//      pool's free room does not hold the writes (BeamModel's counts), a MapRoom is
//      first asked to make room, and where it cannot make enough the step's update range
//      is shortened until they fit (far misses are left out; counted);
//   5. prune/merge the ancestry tree (the DP map follows through TreeListener) and
//      drain the poses every particle agrees on to the PoseSink.
// A scan is processed only once the odometry has moved update_min_travel_m or turned
// update_min_rotation_rad since the last processed scan; other scans get the best
// particle's pose composed with the odometry since (StepResult::pose).
//
// Memory: init() carves everything from the caller's Arena (required_arena_bytes());
// process() never touches the heap. The object itself holds ~60 KiB of per-scan tables:
// keep it in static storage or on the heap at init, not on a small stack.
//
// Exhaustion is counted, never fatal (see Stats):
//  - node pool full: a drawn particle that cannot get a child node continues on its
//    parent's node (kept active); its later map updates are then shared with its
//    siblings. Counted in node_fallback_count.
//  - observation pool short of a step's writes: the step writes with a shortened update
//    range, so that every writer keeps its near cells (map_writes_shortened).
//  - observation/tile pool full all the same: the cell update is dropped (map stays
//    consistent, the particle's map just lacks that evidence). Counted in
//    map_updates_dropped.
//  - path entries full: the pose is not recorded on the tree (the trajectory has a gap
//    the caller fills from odometry). Counted by the tree's path_oom_count.
// Deterministic: same options, seed and input → bit-identical poses.
#include <cstddef>
#include <cstdint>

#include "sdpslam/core/bottom/ancestry_tree.h"
#include "sdpslam/core/arena.h"
#include "sdpslam/core/bottom/beam_model.h"
#include "sdpslam/core/bottom/dp_map.h"
#include "sdpslam/core/dpslam_options.h"
#include "sdpslam/core/bottom/motion_model.h"
#include "sdpslam/core/range_scan.h"
#include "sdpslam/core/rng.h"
#include "sdpslam/core/bottom/view_cache.h"
#include "sdpslam/core/state_io.h"

namespace sdpslam {

struct StepResult {
  enum class Status : std::uint8_t {
    kProcessed,        // propagated, weighted, (maybe) resampled, map updated
    kSkippedNoMotion,  // below the update thresholds: pose from odometry
    kNotInitialised,   // init() was not called or failed
  };
  Status status = Status::kNotInitialised;
  Pose2 pose;                     // best estimate of the robot pose at this scan
  bool resampled = false;
  double effective_sample_size = 0.0;
  std::uint32_t map_updates_dropped = 0U;  // this step
  std::uint32_t poses_committed = 0U;      // this step
};

// Asked for room in the map's observation pool before a step's map writes (step 4),
// which all sit in the pool at once until prune folds them into the lineages, and
// before a restart writes the last scans into the new root (restart_segment()). It may
// free the observations of nodes no particle descends from (release_anchored()) and
// read the map; it must not process scans, restart or displace the filter.
class MapRoom {
 public:
  // Make room, if it can, for `observations` more than the pool holds now.
  virtual void make_room(std::uint64_t observations) = 0;

 protected:
  ~MapRoom() = default;
};

struct DpSlamStats {
  std::uint64_t scans = 0U;
  std::uint64_t processed = 0U;
  std::uint64_t resamplings = 0U;
  std::uint64_t map_updates_dropped = 0U;
  std::uint64_t node_fallback_count = 0U;
  std::uint64_t degenerate_weight_count = 0U;  // all weights -inf/NaN: kept uniform
  // Improved proposal (DpSlamOptions::Proposal::kScanMatch), per particle and step:
  std::uint64_t proposal_matched = 0U;              // drawn around a scan match
  std::uint64_t proposal_fallback_few_beams = 0U;   // odometry proposal: too few beams
  std::uint64_t proposal_fallback_empty_map = 0U;   // ... map too empty at the prediction
  std::uint64_t proposal_fallback_low_score = 0U;   // ... match scored below the threshold
  std::uint64_t proposal_evaluations = 0U;          // observation-model calls by the matcher
  // Writes (a step's, or a restart's scan) that did not fit in the pool's free room:
  std::uint64_t map_room_asked = 0U;    // ... and the MapRoom was asked for room
  std::uint64_t map_room_short = 0U;    // ... and there was still not room enough after
  // Writes (a step's, or a restart's scan) made with a shortened update range because the
  // pool could not hold them at max_update_range_m, and the shortest such range (valid
  // when map_writes_shortened > 0).
  std::uint64_t map_writes_shortened = 0U;
  double shortest_write_reach_m = 0.0;
};

class DpSlamFilter {
 public:
  DpSlamFilter() = default;
  DpSlamFilter(const DpSlamFilter&) = delete;
  DpSlamFilter& operator=(const DpSlamFilter&) = delete;

  // Arena bytes init() needs for `options` (0 iff the options are invalid).
  static std::size_t required_arena_bytes(const DpSlamOptions& options);

  // Validates options and carves every pool from `arena`. False iff the options are
  // invalid or the arena is too small (why() then says which). Call once.
  bool init(const DpSlamOptions& options, Arena& arena, std::uint64_t seed);
  const char* why() const { return why_; }

  // Feeds one laser scan with the odometry pose at its time. The first scan initialises
  // the particles at the odometry pose (so the estimate lives in the odometry frame).
  StepResult process(const OdometrySample& odom, const RangeScan& scan);

  // Receives poses every particle agrees on (committed). May be null. Not owned.
  void set_pose_sink(PoseSink* sink) { sink_ = sink; }
  // Asked for room before a step's map writes could be refused (MapRoom). May be null
  // (writes the pool cannot take are then dropped and counted). Not owned.
  void set_map_room(MapRoom* room) { room_ = room; }

  // ---- the best particle -------------------------------------------------------------
  // Highest-weight particle of the last processed step (its node is a current leaf).
  NodeId best_node() const { return particle_count_ > 0U ? particles_[best_index_].node : kNoNode; }
  Pose2 best_pose() const { return particle_count_ > 0U ? particles_[best_index_].pose : Pose2{}; }
  // Calls f(stamp_us, pose) for the best particle's uncommitted poses, oldest first
  // (committed poses went to the sink).
  template <class F>
  void for_each_best_pose(F&& f) const {
    if (best_node() != kNoNode) tree_.for_each_pose_from_root(best_node(), f);
  }
  // Occupancy probability the filter believes for a cell observation (for map output).
  double occupancy(const CellObservation& c) const { return beam_.stop_probability(c); }

  // ---- segments (SDP-SLAM, paper §III, Algorithm 1 lines 5-6) ---------------------
  // Anchorage and restart: the current particles' nodes stay in the tree, ACTIVE, so
  // their map views and paths (the finished segment's submaps) remain readable and can
  // no longer change (no particle descends from them any more); every particle then
  // restarts at `start_pose` on one fresh root (a new tree of the forest) with an empty
  // map, except that the last processed scans are written into that root: the last at
  // start_pose, and the kSeedScans before it where the best particle's lineage put them,
  // relative to start_pose as they were to its pose. The new submap so begins with what
  // the robot saw from several viewpoints where it starts: the next scans are matched
  // against it, and a single scan is a fragile reference (its far walls are sparse
  // dots, which fit a wrong heading during a turn about as well as the right one).
  // Weights become uniform. Poses are not recorded on the new root (start_pose is the
  // finished segment's last pose). Returns false, changing nothing, iff the filter has
  // not processed a scan yet or the node pool cannot hold the root and the particles'
  // children (restart_refused_count() bumps). O(N + lineage depth + kSeedScans · beams).
  bool restart_segment(const Pose2& start_pose);
  // The robot was moved by `delta` (in its own frame at the last processed scan) where
  // odometry could not see it: carried while the program was off, found again in the
  // saved map. Every particle and the best pose move rigidly, without motion noise (the
  // move is a measurement, not a prediction); the next scan's odometry is taken relative
  // to the last processed one as before, and that scan is processed whatever the motion
  // (its pose, at the new place, is recorded on the lineages). The map and the lineages
  // are unchanged until then: the move is the step between two recorded poses. False, changing nothing, iff no scan
  // was processed yet or `delta` is not finite. O(N).
  bool displace(const Pose2& delta);
  // Makes an anchored node inactive and prunes, so its observations and poses are freed
  // once nothing descends from it. False (nothing changes) iff `node` is dead or is the
  // node of a current particle. O(prune).
  bool release_anchored(NodeId node);
  // DpMap::pop_observation() on a node that is not a current particle (false, changing
  // nothing, for a particle's node).
  bool pop_anchored_observation(NodeId node, std::int32_t* ix, std::int32_t* iy, CellObservation* value);
  std::uint32_t restart_refused_count() const { return restart_refused_count_; }

  const DpMap& map() const { return map_; }
  const AncestryTree& tree() const { return tree_; }
  const DpSlamOptions& options() const { return options_; }
  const DpSlamStats& stats() const { return stats_; }
  std::uint32_t particle_count() const { return particle_count_; }
  Pose2 particle_pose(std::uint32_t i) const { return i < particle_count_ ? particles_[i].pose : Pose2{}; }
  NodeId particle_node(std::uint32_t i) const { return i < particle_count_ ? particles_[i].node : kNoNode; }
  bool initialised() const { return initialised_; }
  // The mutable state, for snapshots (core/state_io.h): what init() did not fix.
  void transfer_state(StateIo& io);

 private:
  struct Particle {
    NodeId node = kNoNode;
    Pose2 pose;
    double log_weight = 0.0;
  };

  void first_scan(const OdometrySample& odom, const RangeScan& scan, StepResult* result);
  // Draws particle i's pose into proposed_[i] (odometry or improved proposal) and returns
  // the log-weight increment.
  double propose(std::uint32_t i, const Pose2& odom_delta);
  bool is_particle_node(NodeId node) const;
  // The new observations of writing `rays` with update range `reach_m` (an upper bound
  // where a write falls outside the map, or into a writer's node that is not fresh): at
  // `pose` into node `into` (a restart's root), or, pose null, step 4's writers at their
  // proposed poses.
  std::uint64_t writes_bound(const ScanRays& rays, const Pose2* pose, NodeId into, double reach_m) const;
  // The update range those writes are made with: max_update_range_m, after asking room_
  // for room where the pool's free room does not hold them; shorter where it still cannot.
  double reach_that_fits(const ScanRays& rays, const Pose2* pose, NodeId into);
  std::uint64_t free_observations() const;
  static constexpr std::uint32_t kReachBisections = 7U;
  // Step 4 writes particle i's scan into its node.
  bool writes(std::uint32_t i) const;

  DpSlamOptions options_{};
  AncestryTree tree_;
  DpMap map_;
  BeamModel beam_;
  ViewCache view_;  // the scan matcher's memory of one particle's view (kScanMatch only)
  MotionModel motion_;
  Rng rng_;
  PoseSink* sink_ = nullptr;
  MapRoom* room_ = nullptr;
  DpSlamStats stats_{};
  ScanRays rays_{};
  // The processed scans before the last (a ring, oldest at seed_head_ once full): a new
  // segment's map starts with them (restart_segment()). Three, with the last, span the
  // robot's last ~0.6 m or ~0.6 rad at the default update thresholds.
  static constexpr std::uint32_t kSeedScans = 3U;
  ScanRays seed_rays_[kSeedScans]{};
  std::int64_t seed_stamp_us_[kSeedScans] = {};
  Pose2 seed_pose_[kSeedScans] = {};         // its pose once committed (on every lineage)
  bool seed_committed_[kSeedScans] = {};
  std::uint32_t seed_head_ = 0U;
  std::uint32_t seed_count_ = 0U;
  std::int64_t rays_stamp_us_ = 0;  // stamp of the scan in rays_

  Particle* particles_ = nullptr;      // current generation
  Particle* next_ = nullptr;           // next generation (swapped)
  Pose2* proposed_ = nullptr;          // sampled pose per particle
  double* log_w_ = nullptr;
  double* w_ = nullptr;
  std::uint32_t* drawn_ = nullptr;     // resampled indices
  std::uint32_t* counts_ = nullptr;    // children per particle
  std::uint64_t* marks_ = nullptr;     // scratch of cells_written() and update_map(), zero between calls
  std::uint32_t particle_count_ = 0U;
  std::uint32_t best_index_ = 0U;

  bool initialised_ = false;
  bool started_ = false;
  bool update_due_ = false;            // the next scan is processed whatever the motion (displace())
  OdometrySample last_odom_{};         // odometry at the last processed scan
  Pose2 last_best_pose_{};             // best pose at the last processed scan
  std::uint32_t restart_refused_count_ = 0U;
  char why_[160] = {};
};

}  // namespace sdpslam
