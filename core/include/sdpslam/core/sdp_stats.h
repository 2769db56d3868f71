#pragma once
// What SdpSlam (sdp_slam.h) reports: the result of one process() call and the engine's
// counters, loop closure's among them. Plain data, part of the API.
#include <cstdint>

#include "sdpslam/core/bottom/dpslam_filter.h"  // StepResult
#include "sdpslam/core/pose2.h"

namespace sdpslam {

// Why a segment ended (paper §III, Algorithm 1 line 4; top/segmentation.h). kPeriod,
// kDispersion and kMaxLength are the segmentation modes' own decisions.
// kWindow: SdpSlam ended the segment because the robot reached the edge of the square
// its lineage may use in the DP map's torus (sdp_slam.h), whatever the mode says.
// kPool: SdpSlam ended it because the DP map's observation pool could not take another
// scan's writes (sdp_slam.h, make_room()).
enum class SegmentEnd : std::uint8_t { kNone, kPeriod, kDispersion, kMaxLength, kWindow, kPool };
const char* to_string(SegmentEnd reason);

// Loop closure's counts (beyond the paper; loops/loop_closure.h).
struct LoopClosureStats {
  std::uint64_t loop_records = 0U;          // loop constraints held now
  std::uint64_t loop_refinements = 0U;      // obstacle-point ICP runs
  std::uint64_t loop_records_added = 0U;    // ICP matches kept as loop constraints
  std::uint64_t loop_records_dropped = 0U;  // kept matches that found no room (store full)
  std::uint64_t loop_rivals_refused = 0U;   // ICP matches of a verified pair, far from its peak, kept out despite a lower residual
  std::uint64_t loop_constraints_used = 0U; // in the last adjustment
  std::uint64_t loop_downweighted = 0U;     // of those, weight < 0.5 after it (disagreeing)
  std::uint64_t loop_constraints_weak_direction = 0U;  // loop matches weak along a direction (corridors)
  std::uint64_t loop_information_unmeasured = 0U;      // loop matches whose direction information failed
  std::uint64_t frame_adjustments = 0U;     // pose-graph solves
  std::uint64_t frame_graph_refused = 0U;   // nodes or loops that did not fit the graph
  std::uint64_t frame_steps_refused = 0U;   // pose-graph solves ended by a step that raised the objective
  std::uint64_t frame_adjustments_capped = 0U;  // pose-graph solves that ended after graph_iterations steps still converging
  std::uint64_t loop_searches = 0U;         // wide searches run (pairs of submaps)
  std::uint64_t loop_search_candidates_dropped = 0U;  // older submaps within a level's reach left unsearched: beyond loop_search_candidates, or a newer level came first
  std::uint64_t loop_search_levels_skipped = 0U;      // levels never searched: a newer one was ready before their turn
  std::uint64_t loop_search_weak = 0U;      // ... whose best peak scored below loop_search_min_score
  std::uint64_t loop_search_ambiguous = 0U; // ... with a distinct peak nearly as good
  std::uint64_t loop_search_failed = 0U;    // ... that could not run (too few points, grid too large)
  std::uint64_t loop_search_refuted = 0U;   // ... found a peak that obstacle ICP did not confirm
  std::uint64_t loop_search_closed = 0U;    // ... that became loop constraints
  std::uint64_t loop_search_far = 0U;       // ... refused: would move their submap beyond loop_search_drift_m × √hops
  std::uint64_t loop_search_recentred = 0U; // ... moving their submap over half the window: searched again around the peak
  std::uint64_t loop_search_recentred_closed = 0U;  // of those, confirmed by that search (then recorded)
};

struct SdpStepResult {
  StepResult bottom;      // the bottom filter's step (pose in the current segment's frame)
  Pose2 pose;             // the estimate in the global frame (best top-level particle)
  SegmentEnd segmented = SegmentEnd::kNone;
  std::uint32_t evaluations = 0U;  // top-level samples evaluated during this call
  std::uint32_t work_cells = 0U;   // map cells read by anchorage work during this call
};

// The engine's counters; loop closure's are part of it.
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

}  // namespace sdpslam
