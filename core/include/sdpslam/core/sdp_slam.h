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
// become permanent early until the next segment's expected need fits (make_room();
// counted as levels_made_permanent_for_room). The last of them gives its observations
// back over the next scans, one submap per scan (its room counted as made meanwhile),
// unless a scan's writes need them at once. A full pool would instead refuse the
// current segment's own map updates.
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
// process() never touches the heap. The object holds its parts in fixed storage of its
// own (the parts' headers are the core's, src/, not installed): about 9 KiB, allocate it
// once at start-up.
#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "sdpslam/core/arena.h"
#include "sdpslam/core/bottom/dpslam_filter.h"
#include "sdpslam/core/pose2.h"
#include "sdpslam/core/range_scan.h"
#include "sdpslam/core/sdp_options.h"
#include "sdpslam/core/sdp_stats.h"
#include "sdpslam/core/state_io.h"

namespace sdpslam {

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

// The grid of the global map (SdpSlam::global_map_grid).
struct SdpGlobalMapGrid {
  double origin_x_m = 0.0;  // corner of cell (0, 0)
  double origin_y_m = 0.0;
  double resolution_m = 0.0;
  std::uint32_t width = 0U;
  std::uint32_t height = 0U;
};

// One loop constraint held now (SdpSlam::loop_record): the transform z of the newer
// level's frame in the older level's (m, rad), found by the top level's ICP refined on
// obstacle points (searched = false) or by the wide loop search (true), and the mean
// residual of its obstacle-point match.
struct SdpLoopRecord {
  std::uint32_t older_level = 0U;
  std::uint32_t newer_level = 0U;
  bool searched = false;
  double error_m = 0.0;
  Pose2 z;
};

// The fixed stores of the top level and their use (SdpSlam::pools); the bottom level's
// are DpSlamFilter's.
struct SdpPools {
  std::uint32_t pgs_levels_peak = 0U;  // live PGS levels at most (capacity: max_levels)
  std::uint32_t permanent_submaps = 0U;  // held now (capacity: max_permanent_submaps)
  std::uint32_t pose_ring_capacity = 0U;  // committed poses of the live levels
  // Work on permanent levels not done yet, spread over the next scans: submaps waiting to
  // be released (at most max_levels levels' worth), and permanent submaps whose copy into
  // the permanent map is not complete (for_each_best_submap draws them meanwhile).
  std::uint32_t pending_releases = 0U;
  std::uint32_t pending_copies = 0U;
  // The global map's permanent part (permanent_map_tiles; PermanentMap): tiles, cells
  // known, compactions, the side of its cells (DP-map cells × 2^scale_log2) and the
  // writes refused for want of a tile.
  std::uint32_t permanent_map_tile_capacity = 0U;
  std::uint32_t permanent_map_tiles_used = 0U;
  std::uint64_t permanent_map_known_cells = 0U;
  std::uint64_t permanent_map_compactions = 0U;
  std::uint32_t permanent_map_scale_log2 = 0U;
  std::uint64_t permanent_map_refused = 0U;
};

// Private to the core (src/): the engine, and the parts tests inspect.
class SdpSlamImpl;
class SegmentGraph;
class PermanentMap;

class SdpSlam {
 public:
  SdpSlam();
  ~SdpSlam();
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
  const char* why() const;

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
  void set_permanent_sink(SdpPathSink* sink);
  void set_listener(TopLevelListener* listener);

  // ---- the best combination ---------------------------------------------------------
  // f(stamp_us, pose_in_global) for every pose of the live levels' chosen submaps and of
  // the current segment's best particle, oldest first (permanent segments went to the
  // sink). Uses the tree's scratch walk: do not call back into this object from f.
  template <class F>
  void for_each_best_pose(F&& f) const {
    visit_best_poses(&call<F, std::int64_t, const Pose2&>, context_of(f));
  }
  // f(node, frame_in_global, rect) for every DP-map view that makes up the best global
  // map besides its permanent part: the permanent submap still being copied (what is
  // not copied yet) and those waiting for their copy, each live level's chosen submap
  // and the current segment's best particle; rect bounds the cells worth reading.
  template <class F>
  void for_each_best_submap(F&& f) const {
    visit_best_submaps(&call<F, NodeId, const Pose2&, const CellRect&>, context_of(f));
  }
  // f(x_m, y_m, value) for every cell of the global map's permanent part: the centre of
  // the cell in the global frame, moved by the correction its level's frame got since
  // the cell was copied (frame_now ⊕ frame_at_copy⁻¹). A cell of a level that left the
  // ring of permanent submaps (max_permanent_submaps) stays where it was copied: its
  // correction at the time it left is not kept (that would cost a pose per level for
  // ever). Moving it with the oldest submap still held instead was measured worse
  // (SdpSlam test forgotten_permanent_levels_stay_where_they_were_copied).
  template <class F>
  void for_each_permanent_cell(F&& f) const {
    visit_permanent_cells(&call<F, double, double, const CellObservation&>, context_of(f));
  }

  // ---- the global map, rendered by the caller ------------------------------------------
  // The grid of the best combination's global map in the global frame: aligned to the
  // DP map's grid (an identity frame maps cells exactly), its cells as coarse as the
  // permanent part kept them (the DP map's, or coarser once a full store was compacted:
  // PermanentMap::compact), covering every permanent cell and every live view's
  // rectangle. False when nothing is mapped yet.
  using GlobalMapGrid = SdpGlobalMapGrid;
  bool global_map_grid(GlobalMapGrid* grid) const;
  // f(x_m, y_m, value) for every known fine cell of the global map, at its centre in the
  // global frame: the permanent part (for_each_permanent_cell), then each view of
  // for_each_best_submap, read from the DP map in strips of rows through the engine's
  // work buffer. A caller sums the values of the cells that fall in one grid cell
  // (accumulate()) and turns the sum into an occupancy (occupancy()). Call between
  // calls of process(), never from f.
  template <class F>
  void for_each_global_cell(F&& f) const {
    visit_global_cells(&call<F, double, double, const CellObservation&>, context_of(f));
  }
  // The occupancy the observation model gives a cell's (hits, misses).
  double occupancy(const CellObservation& value) const;

  // Frame of the current segment in the global frame for the best top particle.
  Pose2 current_frame() const;
  std::uint32_t best_top_particle() const;

  const DpSlamFilter& bottom() const;
  const SdpOptions& options() const;
  const SdpStats& stats() const;
  SdpPools pools() const;

  // ---- loop closure ------------------------------------------------------------------
  // The loop constraints held now (loop_record(k), k < loop_record_count()): each joins
  // the frames of two levels. level_origin() says where a level started: the stamp of
  // the scan its segment restarted at (the previous segment's last) and the restart
  // pose in the level's frame, so that with a ground truth GT the level's frame is
  // GT(stamp) ⊕ initial⁻¹ and a constraint can be checked. False for a level not held
  // (forgotten, or not made yet). level_held(): the level's frame is in the pose graph
  // (a loop between two held levels is used).
  std::uint32_t loop_record_count() const;
  SdpLoopRecord loop_record(std::uint32_t k) const;
  bool level_origin(std::uint32_t level, std::int64_t* stamp_us, Pose2* initial) const;
  bool level_held(std::uint32_t level) const;
  // The segment being mapped now: the level it becomes when it ends (every level below
  // it was made before) and the stamp it started at, as level_origin() gives for a
  // level (one microsecond before the first scan for the first segment). Level l holds
  // the scans after its start stamp up to the next level's start stamp, included. False
  // before the first processed scan.
  bool current_segment(std::uint32_t* level, std::int64_t* start_stamp_us) const;
  std::size_t arena_bytes_used() const;
  // Mean/std of the ICP error over the top-level particles that have one (0 if none).
  void top_error(double* mean_m, double* std_m, std::uint32_t* count) const;

  // ---- the parts, for the core's own tests -------------------------------------------
  // Their types are declared in the core's private headers (src/top/segment_graph.h,
  // src/top/permanent_map.h): a caller that includes them may inspect the parts;
  // nothing else needs to.
  const SegmentGraph& graph() const;
  const PermanentMap& permanent_map() const;

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

  // Bytes of the engine's own storage: at least sizeof(SdpSlamImpl) on every target
  // (checked where the engine is built, sdp_slam.cpp).
  static constexpr std::size_t kStorageBytes = 9280U;

 private:
  // The visits above, without templates: fn(context, ...) per item. `context` is the
  // caller's callable. A const callable travels as void* and is cast back to its own
  // const type by call(), so its constness is never lost.
  template <class F>
  static void* context_of(F& f) {
    return const_cast<void*>(static_cast<const void*>(&f));
  }
  template <class F, class... A>
  static void call(void* context, A... a) {
    (*static_cast<typename std::remove_reference<F>::type*>(context))(a...);
  }
  void visit_best_poses(void (*fn)(void*, std::int64_t, const Pose2&), void* context) const;
  void visit_best_submaps(void (*fn)(void*, NodeId, const Pose2&, const CellRect&), void* context) const;
  void visit_permanent_cells(void (*fn)(void*, double, double, const CellObservation&), void* context) const;
  void visit_global_cells(void (*fn)(void*, double, double, const CellObservation&), void* context) const;

  SdpSlamImpl& impl() { return *impl_; }
  const SdpSlamImpl& impl() const { return *impl_; }

  alignas(alignof(std::max_align_t)) unsigned char storage_[kStorageBytes];
  SdpSlamImpl* impl_;  // constructed in storage_
};

}  // namespace sdpslam
