#pragma once
// Segmented DP-SLAM (paper §III, Algorithm 1): the two-level filter.
//
// Bottom level (lines 3-6): a DpSlamFilter builds the submaps of the current segment.
// At a segmentation (segmentation.h) the particles' nodes are ANCHORED (left active in
// the ancestry tree, so their map views and paths can no longer change) and the
// particles RESTART at a common pose on a fresh root with an empty map
// (DpSlamFilter::restart_segment). The restart pose is the bottom filter's best pose in
// the DP map's grid frame, so consecutive segments do not pile up in one spot of the
// shared grid; each segment still has its own local frame (Fig. 3 (l)): a submap's
// initial pose is that restart pose and its final pose the particle's pose at the next
// segmentation, and T_ab = final_a ⊕ initial_b⁻¹ (SegmentGraph's convention).
//
// The DP map is a torus (DpMap::Options::wrap) of at least [map] width_m × height_m,
// so the robot never leaves it: a segment is one lineage of the ancestry tree and sees
// only its own observations, so segments far apart may share the torus's storage. What
// must not happen is a segment meeting itself across the seam: a segment also ends
// (SegmentEnd::kWindow) when the bottom's best pose gets window/8 from the segment's
// start, so its map updates (max_update_range_m around its path, checked ≤ window/8 at
// init) stay in a square of half the window, and the beam model leaves out readings
// longer than half the window. Cells popped from the torus are brought back next to
// their submap's rectangle (DpMap::unwrap_near). The permanent map has no edge either
// (permanent_map.h): memory bounds the area mapped, not the building's size.
//
// Top level (lines 7-12): the PGS (segment_graph.h) gets one level per segment, one node
// per bottom particle. At anchorage every node's free-space skeleton (Fig. 2 (b)) is
// extracted from its DP-map view around its path, in the submap frame
// (skeleton_reader.h), into fixed storage (submap_store.h). T top-level particles (top_particles.h) each hold one
// submap choice per live level: after a segmentation they are resampled with elitism
// and diversified from the PGS (or, with SegSLAM's topology, only over its last
// levels), extended to the new level, and evaluated, evaluations_per_scan per call of
// process(): a combination's error is the ICP nearest-neighbour error of its
// overlapping non-adjacent submaps, permanent ones included (combination_evaluator.h).
// The error weights the particle (lower is better) and is added to the PGS edges of the
// combination between the oldest and newest live level involved (line 12, equation
// (4)). Samples without any overlap keep their weight ("in the rest of the process the
// weights are not changed", §IV). Up to rounds_per_segment rounds run after each
// segmentation, as long as samples overlap.
//
// Bounded memory: when all max_levels PGS levels are live, the oldest becomes PERMANENT
// with the best top particle's choice: that submap's poses go to the permanent path
// sink (SdpPathSink: the poses in its frame, and that frame in the global frame), its
// map is copied into the global map's permanent part (map_transfer.h, permanent_map.h:
// one grid, each cell tagged with the level that put it there) and its skeleton into a ring of permanent
// submaps (still matched for loop closures); the level's other submaps are released
// (set_active(false) + prune frees their DP-map observations; counted), one submap per
// call of process() so that no single scan pays for all of them. The DP map's
// observation pool bounds the live levels too: a segment ends (SegmentEnd::kPool) when
// the pool could not take another scan's writes, and at a segmentation older levels
// become permanent early, released at once, until the next segment's expected need
// fits (make_room(); counted as levels_made_permanent_for_room). A full pool would
// instead refuse the current segment's own map updates.
//
// Loop closure (beyond the paper, SdpOptions::loop_closure; loop_closure.h): every
// skeleton ICP match of two non-adjacent submaps is handed to LoopClosure::refine, which
// keeps constraints between the two levels' frames; the wide loop search runs a slice
// per call of process(). After every ranking, the frames of the best combination — the
// permanent submaps still held and the chosen live submaps, chained by the transforms T
// of Fig. 3 (l) — are adjusted to those constraints (adjust_frames()). Permanent frames
// and the PGS anchor move with it, so later samples are placed from the corrected
// frames; the permanent path sink is told every new frame, so the trajectory follows,
// and so does the map: each permanent cell is drawn moved by its level's correction
// since the copy (for_each_permanent_cell). SdpSlam shows LoopClosure its submaps
// through LoopSubmaps (the best combination's choice of each held level).
//
// Worst-scan time: anchorage work is spread over calls of process() within
// work_cells_per_scan cells each (plus at most one row): first the copy of a permanent
// submap into the global map, in strips of rows (it goes first because the submap's
// observations are freed only when its copy is complete, and where the pool is tight
// holding them longer costs the bottom level its map updates), then the skeleton
// patches, read from the DP map in strips of coarse rows; top-level samples are
// evaluated evaluations_per_scan per call. With defer_top_work all of it waits while
// the bottom level processes scans (at most capacity::kMaxDeferredTopWork in a row), so
// the two costs do not add up. All counts, no clocks: the output is deterministic.
//
// Memory: init() carves everything from the caller's Arena (required_arena_bytes());
// process() never touches the heap. The object is large (ICP tables, bottom filter):
// allocate it once at start-up.
#include <cstddef>
#include <cstdint>

#include "sdpslam/core/bottom/dpslam_filter.h"
#include "sdpslam/core/loops/frame_graph.h"
#include "sdpslam/core/top/free_space_skeleton.h"
#include "sdpslam/core/top/icp2d.h"
#include "sdpslam/core/top/map_transfer.h"
#include "sdpslam/core/loops/loop_closure.h"
#include "sdpslam/core/top/permanent_map.h"
#include "sdpslam/core/pose_ring.h"
#include "sdpslam/core/sdp_options.h"
#include "sdpslam/core/top/combination_evaluator.h"
#include "sdpslam/core/top/segment_graph.h"
#include "sdpslam/core/top/segmentation.h"
#include "sdpslam/core/top/skeleton_reader.h"
#include "sdpslam/core/top/submap_store.h"
#include "sdpslam/core/top/top_particles.h"

namespace sdpslam {

struct SdpStepResult {
  StepResult bottom;      // the bottom filter's step (pose in the current segment's frame)
  Pose2 pose;             // the estimate in the global frame (best top-level particle)
  SegmentEnd segmented = SegmentEnd::kNone;
  std::uint32_t evaluations = 0U;  // top-level samples evaluated during this call
  std::uint32_t work_cells = 0U;   // map cells read by anchorage work during this call
};

// Loop closure's counts (loop_closure.h) are part of it.
struct SdpStats : LoopClosureStats {
  std::uint64_t segments = 0U;            // segmentations done (levels added)
  std::uint64_t restart_refused = 0U;     // segmentation postponed: no room to restart
  std::uint64_t window_segmentations = 0U;  // segments ended at the edge of their DP-map square
  std::uint64_t pool_segmentations = 0U;    // ... when the DP map's pool could not take another scan
  std::uint64_t pgs_refused = 0U;         // add_level refused (should stay 0)
  std::uint64_t levels_made_permanent = 0U;
  std::uint64_t levels_made_permanent_for_room = 0U;  // ... early, to fit the next segment's map (pool)
  std::uint64_t submaps_released = 0U;    // submaps freed when their level became permanent
  std::uint64_t permanent_forgotten = 0U; // permanent skeletons dropped from the ring
  std::uint64_t skeletons = 0U;
  std::uint64_t skeleton_truncated_points = 0U;
  std::uint64_t map_transfer_cells = 0U;
  std::uint64_t map_transfer_dropped = 0U;  // global-map cell updates refused (pool full)
  std::uint64_t map_transfers_popped = 0U;  // permanent submaps copied by popping (the rule)
  std::uint64_t map_transfers_by_rows = 0U; // ... by reading their rectangle (fallback)
  // The global map's permanent part is stored where its submaps' frames were when copied;
  // loop closure may move those frames later, and the map is drawn moved with them
  // (for_each_permanent_cell). How far (m, at the submap's box corners) that correction
  // moves a permanent submap's cells: the largest over the ring after the last
  // adjustment, and the largest ever seen.
  double permanent_map_offset_m = 0.0;
  double permanent_map_offset_max_m = 0.0;
  std::uint64_t rounds = 0U;
  std::uint64_t top_work_deferred = 0U;     // processed scans whose top-level work waited (defer_top_work)
  std::uint64_t rounds_with_overlap = 0U;
  std::uint64_t evaluations = 0U;
  std::uint64_t evaluations_with_overlap = 0U;
  std::uint64_t icp_matches = 0U;
  std::uint64_t icp_failures = 0U;          // overlapping boxes, too few correspondences
  std::uint64_t icp_memo_hits = 0U;         // pair results reused instead of recomputed
  std::uint64_t pose_ring_dropped = 0U;     // committed poses lost (trajectory gap)
  std::uint32_t pose_ring_peak = 0U;
  std::uint32_t max_live_levels = 0U;
  // All evaluated samples with overlap (Table I's μ and σ).
  double error_sum_m = 0.0;
  double error_sq_sum_m2 = 0.0;
  std::uint64_t error_samples = 0U;
  double error_mean_m() const { return error_samples > 0U ? error_sum_m / static_cast<double>(error_samples) : 0.0; }
  double error_std_m() const;
};

// Told about every finished evaluation round in which some sample overlapped.
class TopLevelListener {
 public:
  virtual void on_round(std::int64_t stamp_us, double mean_error_m, double std_error_m, std::uint32_t samples) = 0;

 protected:
  ~TopLevelListener() = default;
};

// Receives the path of the segments made permanent: every pose once, in its level's
// submap frame, and the level's frame in the global frame whenever it is set or moved by
// loop closure. A pose's global place is frame(level) ⊕ local.
class SdpPathSink {
 public:
  virtual void on_pose(std::uint32_t level, std::int64_t stamp_us, const Pose2& local) = 0;
  virtual void on_frame(std::uint32_t level, const Pose2& frame_in_global) = 0;

 protected:
  ~SdpPathSink() = default;
};

class SdpSlam {
 public:
  SdpSlam() = default;
  SdpSlam(const SdpSlam&) = delete;
  SdpSlam& operator=(const SdpSlam&) = delete;

  // The bottom options SDP-SLAM actually uses: `bottom` plus the pool room anchored
  // segments need (extra ancestry nodes and path entries for max_levels segments).
  static DpSlamOptions bottom_options_for(const DpSlamOptions& bottom, const SdpOptions& sdp);
  // Every check init() makes of the options, without an arena: each option's range
  // (SdpOptions::validate, and DpSlamOptions::validate of bottom_options_for()) and the
  // limits that join options (the skeleton patch, the cell coordinates of loop
  // closure's obstacle points). Options that pass start: init()
  // refuses them only for an arena smaller than required_arena_bytes(). `why` (may be
  // null) gets "section.key: reason" naming the key to change.
  static bool check_options(const DpSlamOptions& bottom, const SdpOptions& sdp, char* why, std::size_t n);
  // Arena bytes init() needs (0 iff the options are invalid).
  static std::size_t required_arena_bytes(const DpSlamOptions& bottom, const SdpOptions& sdp);
  // False iff check_options() refuses the options or the arena is too small (why() says
  // which). Call once.
  bool init(const DpSlamOptions& bottom, const SdpOptions& sdp, Arena& arena, std::uint64_t seed);
  const char* why() const { return why_; }

  // One scan: bottom update, segmentation decision, anchorage/restart, top-level work
  // within the per-scan budget.
  SdpStepResult process(const OdometrySample& odom, const RangeScan& scan);
  // Completes pending anchorage work (skeletons, map transfer) at once, e.g. before the
  // outputs are read at the end of a run. Not bounded by the per-scan budget.
  void finish();
  // The robot was moved by `delta` (its own frame at the last processed scan) where
  // odometry could not see it, e.g. while the program was off (a resumed session whose
  // first scan was found elsewhere in the saved map). The current segment's particles
  // move rigidly (DpSlamFilter::displace): the segment's path steps by `delta` and goes
  // on from there, so the global estimate continues at the place found. False,
  // changing nothing, iff no scan was processed yet or `delta` is not finite.
  bool relocate(const Pose2& delta);

  // Path of the segments made permanent (see SdpPathSink), in time order. Not owned.
  void set_permanent_sink(SdpPathSink* sink) { permanent_sink_ = sink; }
  void set_listener(TopLevelListener* listener) { listener_ = listener; }

  // ---- the best combination ---------------------------------------------------------
  // f(stamp_us, pose_in_global) for every pose of the live levels' chosen submaps and of
  // the current segment's best particle, oldest first (permanent segments went to the
  // sink). Uses the tree's scratch walk: do not call back into this object from f.
  template <class F>
  void for_each_best_pose(F&& f) const;
  // f(node, frame_in_global, rect) for every DP-map view that makes up the best global
  // map besides its permanent part: the permanent submap still being copied (what is
  // not copied yet), each live level's chosen submap and the current segment's best
  // particle; rect bounds the cells worth reading.
  template <class F>
  void for_each_best_submap(F&& f) const;
  // f(x_m, y_m, value) for every cell of the global map's permanent part: the centre of
  // the cell in the global frame, moved by the correction its level's frame got since
  // the cell was copied (frame_now ⊕ frame_at_copy⁻¹). A cell of a level that left the
  // ring of permanent submaps (max_permanent_submaps) stays where it was copied: its
  // correction at the time it left is not kept (that would cost a pose per level for
  // ever). Moving it with the oldest submap still held instead was measured worse
  // (SdpSlam test forgotten_permanent_levels_stay_where_they_were_copied).
  template <class F>
  void for_each_permanent_cell(F&& f) const;
  const PermanentMap& permanent_map() const { return permanent_map_; }

  // ---- the global map, rendered by the caller ------------------------------------------
  // The grid of the best combination's global map in the global frame: aligned to the
  // DP map's grid (an identity frame maps cells exactly), its cells as coarse as the
  // permanent part kept them (the DP map's, or coarser once a full store was compacted:
  // PermanentMap::compact), covering every permanent cell and every live view's
  // rectangle. False when nothing is mapped yet.
  struct GlobalMapGrid {
    double origin_x_m = 0.0;  // corner of cell (0, 0)
    double origin_y_m = 0.0;
    double resolution_m = 0.0;
    std::uint32_t width = 0U;
    std::uint32_t height = 0U;
  };
  bool global_map_grid(GlobalMapGrid* grid) const;
  // f(x_m, y_m, value) for every known fine cell of the global map, at its centre in the
  // global frame: the permanent part (for_each_permanent_cell), then each view of
  // for_each_best_submap, read from the DP map in strips of rows through the engine's
  // work buffer. A caller sums the values of the cells that fall in one grid cell
  // (accumulate()) and turns the sum into an occupancy (occupancy()). Call between
  // calls of process(), never from f.
  template <class F>
  void for_each_global_cell(F&& f) const;
  // The occupancy the observation model gives a cell's (hits, misses).
  double occupancy(const CellObservation& value) const { return filter_->occupancy(value); }

  // Frame of the current segment in the global frame for the best top particle.
  Pose2 current_frame() const { return current_frame_; }
  std::uint32_t best_top_particle() const { return best_top_; }

  const DpSlamFilter& bottom() const { return *filter_; }
  const SegmentGraph& graph() const { return graph_; }
  const SdpOptions& options() const { return options_; }
  const SdpStats& stats() const { return stats_; }

  // ---- loop closure, for inspection (loop_closure.h) ----------------------------------
  // The loop constraints held now: each joins the frames of two levels. level_origin()
  // says where a level started: the stamp of the scan its segment restarted at (the
  // previous segment's last) and the restart pose in the level's frame, so that with a
  // ground truth GT the level's frame is GT(stamp) ⊕ initial⁻¹ and a constraint can be
  // checked. False for a level not held (forgotten, or not made yet). level_held(): the
  // level's frame is in the pose graph (a loop between two held levels is used).
  const LoopClosure& loop_closure() const { return loop_closure_; }
  bool level_origin(std::uint32_t level, std::int64_t* stamp_us, Pose2* initial) const;
  bool level_held(std::uint32_t level) const {
    std::uint32_t index = 0U;
    return graph_index(level, &index);
  }
  std::uint32_t permanent_submap_count() const { return store_.permanent_count(); }
  std::uint32_t pose_ring_capacity() const { return ring_.capacity(); }
  std::size_t arena_bytes_used() const { return arena_used_; }
  // Mean/std of the ICP error over the top-level particles that have one (0 if none).
  void top_error(double* mean_m, double* std_m, std::uint32_t* count) const;

  // ---- snapshots (core/state_io.h) ----------------------------------------------------
  // The complete state, between two process() calls: the arena blocks carved by init()
  // and every member that changed since, so that an engine initialised with the same
  // options and build and given load_state() continues exactly as this one would (the
  // same poses and maps, bit for bit). The permanent sink and the listener are the
  // caller's: their data is not part of it. False (why() says where) iff the writer
  // failed or the engine is not initialised. No heap.
  bool save_state(StateWriter& writer);
  // Replaces the whole state with a stream from save_state(). Call after init() with the
  // options the stream was written with: a stream of another build, of options that lay
  // the arena out otherwise, or cut short is refused (false, why() names the part);
  // options that keep the layout are not told apart here (the snapshot file is keyed to
  // the configuration, io/snapshot_file.h). After a refusal the engine is unusable
  // (process() does nothing) until init() on a fresh arena.
  bool load_state(StateReader& reader);
  // Bytes save_state() writes for this engine (the snapshot's size before compression).
  std::uint64_t state_bytes() const;

  // Pure helper: share (m²) of the overlap of two axis-aligned boxes.
  static double box_overlap_m2(const double a[4], const double b[4]);

 private:
  class RingSink final : public PoseSink {
   public:
    explicit RingSink(SdpSlam& owner) : owner_(owner) {}
    void on_committed(std::int64_t stamp_us, const Pose2& pose) override { owner_.ring_push(stamp_us, pose); }

   private:
    SdpSlam& owner_;
  };

  // Cell points → metres in the submap frame (scratch buffer).
  void unpack(const CellPoint* in, std::uint32_t n, Point2* out) const;
  std::uint16_t choice(std::uint32_t particle, std::uint32_t level) const { return top_.choice(particle, level); }

  void ring_push(std::int64_t stamp_us, const Pose2& pose);
  template <class F>
  void for_each_level_pose(std::uint32_t level, NodeId leaf, F&& f) const;
  template <class F>
  void for_each_current_pose(F&& f) const;

  void segment(std::int64_t stamp_us);
  std::uint64_t observations_needed() const;
  void make_room(std::uint64_t need);
  // The most DP map observations one processed scan asked for, in this segment or the previous one.
  std::uint64_t scan_burst() const;
  void finish_releases();
  void make_oldest_permanent();
  std::uint32_t do_work(std::uint32_t budget_cells);
  // The whole skeleton now (completing any other job first); returns cells read.
  std::uint32_t extract_skeleton(std::uint32_t level, std::uint32_t node);
  std::uint32_t skeleton_step(std::uint32_t budget_cells);  // the job, within the budget
  std::uint32_t transfer_step(std::uint32_t budget_cells);  // the map transfer, within the budget
  FineBuffer fine_buffer() const { return FineBuffer{fine_values_, fine_known_, fine_cells_}; }
  std::uint32_t release_one();
  void evaluate(std::uint32_t particle);
  void end_round(std::int64_t stamp_us, bool may_continue);
  void update_best();
  // Index of a level's frame in the best combination's frame graph, if it is part of it.
  bool graph_index(std::uint32_t level, std::uint32_t* index) const;
  void adjust_frames();
  // Both directions of a snapshot (save_state / load_state).
  void transfer_state(StateIo& io);
  // Obstacle points and global frame of a level in the best combination (permanent or
  // live); false if the level is no longer held.
  bool level_obstacles(std::uint32_t level, const CellPoint** points, std::uint32_t* count, Pose2* frame,
                       double box[4]) const;
  // The best combination's submaps, as loop closure sees them (LoopView).
  std::uint32_t first_held_level() const;
  bool placement(std::uint32_t level, Pose2* frame, double box[4], std::uint32_t* obstacle_count) const;
  void obstacles(std::uint32_t level, Point2* out) const;
  // LoopSubmaps for LoopClosure, kept a member (as RingSink) so that SdpSlam itself has no
  // virtual functions.
  class LoopView final : public LoopSubmaps {
   public:
    explicit LoopView(SdpSlam& owner) : owner_(owner) {}
    bool node_index(std::uint32_t level, std::uint32_t* index) const override { return owner_.graph_index(level, index); }
    std::uint32_t node_count() const override { return owner_.store_.permanent_count() + owner_.graph_.live_level_count(); }
    std::uint32_t first_held_level() const override { return owner_.first_held_level(); }
    std::uint32_t first_live_level() const override { return owner_.graph_.first_live_level(); }
    std::uint32_t level_end() const override { return owner_.graph_.level_end(); }
    bool placement(std::uint32_t level, Pose2* frame, double box[4], std::uint32_t* count) const override {
      return owner_.placement(level, frame, box, count);
    }
    void obstacles(std::uint32_t level, Point2* out) const override { owner_.obstacles(level, out); }
    void on_verified_loop() override { owner_.update_best(); }

   private:
    SdpSlam& owner_;
  };

  SdpOptions options_{};
  DpSlamOptions bottom_options_{};
  DpSlamFilter* filter_ = nullptr;  // in the arena
  Icp2d* icp_ = nullptr;            // in the arena
  SegmentGraph graph_;
  Segmenter* segmenter_ = nullptr;
  Rng rng_;
  RingSink ring_sink_{*this};
  SdpPathSink* permanent_sink_ = nullptr;
  TopLevelListener* listener_ = nullptr;
  SdpStats stats_{};

  std::uint32_t n_bottom_ = 0U;
  SubmapStore store_;                  // live and permanent submaps
  SkeletonReader skeletons_;           // skeletons read from the DP map at anchorage
  TopParticles top_;                   // the T combinations (lines 9-12)
  CombinationEvaluator evaluator_;     // a combination's ICP error (line 11)
  CombinationResult evaluation_{};     // scratch of evaluate()
  std::uint32_t* chain_ = nullptr;     // max_levels
  Pose2* frames_ = nullptr;            // max_levels: the best particle's chain
  Pose2* eval_frames_ = nullptr;       // max_levels: the chain being evaluated
  Pose2* poses_scratch_ = nullptr;     // N
  PoseRing ring_;  // committed poses of the live levels and the current segment
  CellObservation* fine_values_ = nullptr;
  std::uint8_t* fine_known_ = nullptr;
  std::size_t fine_cells_ = 0U;
  Point2* obst_a_ = nullptr;        // loop_points (scratch)
  Point2* obst_b_ = nullptr;
  LoopClosure loop_closure_;
  LoopView loop_view_{*this};
  // Submaps of a permanent level waiting to be released, one per call of process()
  // (freeing a submap's observations walks their cell lists: spread over scans).
  NodeId* release_queue_ = nullptr;  // N
  std::uint32_t release_count_ = 0U;
  MapTransfer transfer_;  // the newest permanent submap's copy into permanent_map_
  PermanentMap permanent_map_;

  // Current segment.
  bool started_ = false;
  Pose2 segment_start_pose_{};     // restart pose (current segment's initial pose)
  double window_radius_m_ = 0.0;   // a segment ends when its path leaves this disc (1/8 window)
  std::int64_t segment_start_stamp_us_ = 0;  // exclusive
  std::uint32_t segment_scans_ = 0U;  // processed scans in the current segment
  // DP map observations asked for by one processed scan: the most in this segment, and
  // in the previous one.
  std::uint64_t scan_requests_ = 0U;
  std::uint64_t previous_scan_requests_ = 0U;
  // DP map observations freed by releasing permanent levels' submaps (release_one,
  // transfer_rows), ever; and, when the current segment started, that count and the
  // observations in use and refused then (observations_needed()).
  std::uint64_t observations_released_ = 0U;
  std::uint64_t segment_observations_released_ = 0U;
  std::uint64_t segment_observations_used_ = 0U;
  std::uint64_t segment_observations_refused_ = 0U;
  std::int64_t last_processed_stamp_us_ = 0;
  double seg_box_[4] = {0.0, 0.0, 0.0, 0.0};  // best poses of the current segment
  // Top-level round.
  bool round_active_ = false;
  std::uint32_t deferred_in_a_row_ = 0U;  // defer_top_work: processed scans without top-level work
  std::uint32_t eval_cursor_ = 0U;
  std::uint32_t rounds_in_segment_ = 0U;
  double round_sum_ = 0.0;
  double round_sq_ = 0.0;
  std::uint32_t round_samples_ = 0U;
  std::uint32_t best_top_ = 0U;
  Pose2 current_frame_{};
  std::size_t arena_used_ = 0U;
  unsigned char* state_begin_ = nullptr;  // the arena blocks init() carved
  unsigned char* state_end_ = nullptr;
  bool initialised_ = false;
  char why_[200] = {};
};

// ---- templates ----------------------------------------------------------------------

template <class F>
void SdpSlam::for_each_level_pose(std::uint32_t level, NodeId leaf, F&& f) const {
  const SubmapLevel& lv = store_.level(level);
  ring_.for_each_between(lv.start_stamp_us, lv.end_stamp_us, f);
  filter_->tree().for_each_pose_from_root(leaf, f);
}

template <class F>
void SdpSlam::for_each_current_pose(F&& f) const {
  ring_.for_each_between(segment_start_stamp_us_, INT64_MAX, f);
  filter_->for_each_best_pose(f);
}

template <class F>
void SdpSlam::for_each_best_pose(F&& f) const {
  if (!initialised_) return;
  const std::uint32_t first = graph_.first_live_level();
  const std::uint32_t count = graph_.live_level_count();
  for (std::uint32_t i = 0; i < count; ++i) {
    const std::uint32_t level = first + i;
    const Pose2 frame = frames_[i];
    const Submap& sm = store_.submap(level, choice(best_top_, level));
    for_each_level_pose(level, sm.node, [&](std::int64_t s, const Pose2& p) { f(s, frame.compose(p)); });
  }
  const Pose2 cur = current_frame_;
  for_each_current_pose([&](std::int64_t s, const Pose2& p) { f(s, cur.compose(p)); });
}

template <class F>
void SdpSlam::for_each_best_submap(F&& f) const {
  if (!initialised_ || !started_) return;
  NodeId copying = kNoNode;
  CellRect rest{};
  if (transfer_.pending(&copying, &rest) && store_.permanent_count() > 0U) {
    // What the permanent map does not hold yet, at its level's frame now (the newest
    // permanent submap).
    f(copying, store_.permanent(store_.permanent_slot_at(store_.permanent_count() - 1U)).frame_in_global, rest);
  }
  const std::uint32_t first = graph_.first_live_level();
  const std::uint32_t count = graph_.live_level_count();
  for (std::uint32_t i = 0; i < count; ++i) {
    const Submap& sm = store_.submap(first + i, choice(best_top_, first + i));
    f(sm.node, frames_[i], sm.map_rect);
  }
  const double pad = bottom_options_.beam.max_update_range_m;
  f(filter_->best_node(), current_frame_,
    filter_->map().rect_around(seg_box_[0], seg_box_[1], seg_box_[2], seg_box_[3], pad));
}

template <class F>
void SdpSlam::for_each_permanent_cell(F&& f) const {
  if (!initialised_) return;
  std::uint32_t last_tag = 0U;
  Pose2 correction;
  permanent_map_.for_each_cell([&](std::int32_t ix, std::int32_t iy, const PermanentMap::Cell& c) {
    if (c.tag != last_tag) {
      last_tag = c.tag;
      correction = Pose2{};
      std::uint32_t slot = 0U;
      if (store_.find_permanent(c.tag - 1U, &slot)) {  // a tag is its level + 1
        const PermanentSubmap& pm = store_.permanent(slot);
        correction = pm.frame_in_global.compose(pm.frame_in_map.inverse());
      }
    }
    // A coarsened cell (PermanentMap::compact) stands for the block of fine cells it
    // covers: each is drawn with its value.
    const std::uint32_t s = permanent_map_.scale_log2();
    const std::int64_t side = std::int64_t{1} << s;
    for (std::int64_t b = 0; b < side; ++b) {
      for (std::int64_t a = 0; a < side; ++a) {
        double x = 0.0;
        double y = 0.0;
        filter_->map().cell_center(static_cast<std::int32_t>(static_cast<std::int64_t>(ix) * side + a),
                                   static_cast<std::int32_t>(static_cast<std::int64_t>(iy) * side + b), &x, &y);
        double gx = 0.0;
        double gy = 0.0;
        correction.transform_point(x, y, gx, gy);
        f(gx, gy, c.value);
      }
    }
  });
}

template <class F>
void SdpSlam::for_each_global_cell(F&& f) const {
  if (!initialised_) return;
  for_each_permanent_cell(f);
  const DpMap& map = filter_->map();
  for_each_best_submap([&](NodeId node, const Pose2& frame, const CellRect& r) {
    if (r.width == 0U || r.height == 0U) return;
    // Strips of whole rows that fit the work buffer (of columns too, for a rectangle
    // wider than the buffer), row-major as the rectangle reads.
    const std::uint32_t cols = r.width < fine_cells_ ? r.width : static_cast<std::uint32_t>(fine_cells_);
    const std::uint32_t rows_per_strip = static_cast<std::uint32_t>(fine_cells_ / cols);
    for (std::uint32_t y0 = 0; y0 < r.height; y0 += rows_per_strip) {
      for (std::uint32_t x0 = 0; x0 < r.width; x0 += cols) {
        CellRect strip = r;
        strip.ix0 = r.ix0 + static_cast<std::int32_t>(x0);
        strip.iy0 = r.iy0 + static_cast<std::int32_t>(y0);
        strip.width = r.width - x0 < cols ? r.width - x0 : cols;
        strip.height = r.height - y0 < rows_per_strip ? r.height - y0 : rows_per_strip;
        map.fill_rect(node, strip, fine_values_, fine_known_);
        for (std::uint32_t y = 0; y < strip.height; ++y) {
          for (std::uint32_t x = 0; x < strip.width; ++x) {
            const std::size_t i = static_cast<std::size_t>(y) * strip.width + x;
            if (fine_known_[i] == 0U) continue;
            double cx = 0.0;
            double cy = 0.0;
            map.cell_center(strip.ix0 + static_cast<std::int32_t>(x), strip.iy0 + static_cast<std::int32_t>(y), &cx, &cy);
            double gx = 0.0;
            double gy = 0.0;
            frame.transform_point(cx, cy, gx, gy);
            f(gx, gy, fine_values_[i]);
          }
        }
      }
    }
  });
}

}  // namespace sdpslam
