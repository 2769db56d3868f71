#pragma once
// Options of SDP-SLAM's segmentation and top level (paper §III, Algorithm 1 lines 4-12),
// validated once: validate() range-checks every field and names the first bad one.
// The bottom level keeps its own DpSlamOptions (dpslam_options.h); every field here has
// a key in the [sdp] section of firmware-host/runtime/slam/default.ini.
#include <cstddef>
#include <cstdint>

#include "sdpslam/core/capacities.h"
#include "sdpslam/core/option_table.h"
#include "sdpslam/core/top/icp2d.h"

namespace sdpslam {

// How a PGS edge folds the errors of the samples that crossed it (segment_graph.h).
enum class PgsAccumulation : std::uint8_t { kSum, kMean };

// Line 4, "segmentation decision": the paper tested both.
enum class SegmentationMode : std::uint8_t {
  kPeriodic,    // every period_* (whichever is reached first among those > 0)
  kDispersion,  // when the bottom particles' positions spread beyond dispersion_threshold_m
};

// How the top level searches combinations (§IV compares the two topologies).
enum class TopologyMode : std::uint8_t {
  kSdp,      // SDP-SLAM: diversification re-samples choices anywhere in the live chain
  kSegSlam,  // SegSLAM's local analysis: only the last segslam_window segments are
             // re-sampled; older choices follow the best particle's
};

struct SdpOptions {
  // [sdp] top level
  std::uint32_t top_particles = 60U;  // 1 .. capacity::kMaxTopParticles
  TopologyMode topology = TopologyMode::kSdp;
  std::uint32_t segslam_window = 3U;  // segments SegSLAM re-samples, >= 1
  double elite_fraction = 0.2;        // kept unchanged each round, [0, 1]
  double worst_fraction = 0.2;        // replaced by copies of the elite, [0, 1], elite+worst <= 1
  std::uint32_t diversify_levels = 2U;  // choices re-sampled per diversified particle, >= 1
  // Share of the particles that, at a segmentation, extend their combination with the
  // bottom filter's best submap (the others sample it from the PGS), [0, 1].
  double follow_best_fraction = 0.25;
  std::uint32_t rounds_per_segment = 3U;    // evaluation rounds after a segmentation, >= 1
  std::uint32_t evaluations_per_scan = 2U;  // particles evaluated per scan (time budget), >= 1
  std::uint32_t max_pairs_per_sample = 6U;  // overlapping submap pairs matched per sample, >= 1
  double overlap_margin_m = 0.0;            // bounding boxes grown by this before the test
  double min_overlap_m2 = 4.0;              // pairs whose boxes share less area are ignored
  // [sdp] segmentation
  SegmentationMode segmentation = SegmentationMode::kPeriodic;
  double period_travel_m = 8.0;       // periodic: travel per segment (0 = not used)
  double period_time_s = 0.0;         // periodic: log time per segment (0 = not used)
  std::uint32_t period_scans = 0U;    // periodic: processed scans per segment (0 = not used)
  double dispersion_threshold_m = 0.15;  // dispersion: RMS distance of the particles to their mean
  std::uint32_t min_segment_scans = 10U;   // processed scans before any segmentation, >= 1
  std::uint32_t max_segment_scans = 120U;  // a segment never gets longer (bounds storage)
  // [sdp] PGS
  std::uint32_t max_levels = 12U;  // live PGS levels, 2 .. capacity::kMaxPgsLevels
  PgsAccumulation accumulation = PgsAccumulation::kSum;
  double prior_error_m = 1.0;      // effective error of never-sampled edges (and of
                                   // never-evaluated particles when ranking)
  // Submaps made permanent that stay in the loop-closure pose graph and the top level's
  // matching (submap_store.h keeps each in about 2.7 KB: skeleton cells, obstacle points,
  // frames); beyond, the oldest is forgotten (counted). 4096 submaps of a segment each
  // are kilometres of route.
  std::uint32_t max_permanent_submaps = 4096U;  // 1 .. capacity::kMaxPermanentSubmaps
  // [sdp] skeleton (free-space points per submap, computed at anchorage)
  std::uint32_t skeleton_points = 200U;  // per submap, 8 .. capacity::kMaxIcpPoints
  std::uint32_t skeleton_downsample = 2U;  // skeleton grid = map cells × this, 1 .. 8
  double skeleton_pad_m = 3.0;             // around the submap's path
  double skeleton_max_side_m = 30.0;       // patch side bound (also the work buffers)
  double skeleton_min_clearance_m = 0.2;
  double occupied_threshold = 0.6;  // occupancy >= this is an obstacle
  double free_threshold = 0.35;     // occupancy <= this is free
  // Map cells read per scan by anchorage work: skeleton patches, and the copy of a
  // permanent submap into the global map (one popped observation counts
  // SdpSlam::kPopCostCells; see SdpSlam::Transfer).
  std::uint32_t work_cells_per_scan = 120000U;
  // Beyond the paper (per-scan time): true = the top level's work (anchorage, evaluations,
  // loop search) waits while the bottom level processes scans, so that the two costs do
  // not add up in one scan; it runs on the scans the bottom level skips (most of them:
  // it processes a scan per update_min_travel_m), and anyway after
  // capacity::kMaxDeferredTopWork processed scans in a row, so that it is never starved.
  // The price: submaps are released later, so the observation pool runs shorter where
  // it is tight, and the bottom level loses updates. Off.
  bool defer_top_work = false;
  // [sdp] fixed memory of the shared DP map in SDP mode (0 = keep the [map] values):
  // tiles that may hold data and observations for every live submap (the permanent
  // submaps go to the permanent map below): tiles with room to spare for an office
  // floor's live submaps, and 1.5 million observations (24 B each, 36 MB), which keeps
  // the default state well inside its 64 MiB budget. A larger pool keeps more levels
  // live in wide spaces, where it also makes longer segments (fewer end for the pool),
  // so it is not simply better. Where the pool runs short, older levels become
  // permanent early, before a segment starts and before any scan's writes (counted at
  // the particles' poses); only a segment that alone outgrows the pool has a scan's
  // writes made with a shortened update range, each one counted (stats.json
  // pools.observations.writes_shortened).
  std::uint32_t map_tile_capacity = 2500U;
  std::uint32_t map_observation_capacity = 1505000U;
  // [sdp] tiles of the global map's permanent part (permanent_map.h), 16 × 16 cells of
  // 8 bytes each (2 KiB), wherever they are: 4096 tiles hold 2,600 m² of mapped floor at
  // 5 cm. A full map is coarsened (PermanentMap::compact: 2 × 2 cells into one, each
  // time counted) rather than refusing copies; only past its coarsest scale is a copy
  // refused and counted (map_transfer_dropped).
  std::uint32_t permanent_map_tiles = 4096U;
  // [sdp] the DP map's (owner, cell) index (DpMap::Options::owner_cell_index) for the
  // bottom level: off by default, its ~17 MB would break the memory budget, and with N
  // bottom particles per segment the cell lists stay short. Results are identical.
  bool map_owner_cell_index = false;
  // [sdp] ICP (Icp2d options)
  Icp2dOptions icp{};
  // Beyond the paper: the ICP residual alone barely depends on how well the chain placed
  // the two submaps (ICP removes the misplacement before measuring), so a sample's
  // error may also charge the correction ICP had to apply: error = residual +
  // icp_correction_weight × (|Δt| + icp_correction_lever_m × |Δθ|). 0 = the paper's error.
  double icp_correction_weight = 0.0;
  double icp_correction_lever_m = 1.0;
  // [sdp] loop closure, beyond the paper (frame_graph.h). Free-space skeletons depend on
  // how much of a place a submap saw, so a skeleton match places two submaps only
  // roughly; each submap therefore also keeps up to loop_points obstacle points (the
  // occupied cells that border free space, where walls were seen). When the skeleton
  // ICP of two non-adjacent submaps succeeds, ICP on their obstacle points refines it
  // (pairs within loop_icp_max_correspondence_m); a result with a residual of at most
  // loop_max_error_m over at least loop_min_pairs pairs that moved the newer submap at
  // most loop_max_correction_m from the chain's placement becomes a constraint between
  // the two frames, and the best combination's frames (permanent ones included) are
  // adjusted to agree with the constraints (pose graph: chain transforms with
  // segment_sigma_*, loops with loop_sigma_* behind a robust kernel of scale
  // loop_robust_chi: Dynamic Covariance Scaling, frame_graph.h). false (the default) = the paper's top level only; the accurate
  // profile (sdp_profile.h) turns it on with the wide search below. ICP alone only closes
  // loops the bottom level has kept within its reach, which is why the wide search exists.
  bool loop_closure = false;
  std::uint32_t loop_points = 300U;  // obstacle points per submap, 16 .. capacity::kMaxIcpPoints
  double loop_icp_max_correspondence_m = 0.3;
  double loop_max_error_m = 0.12;
  std::uint32_t loop_min_pairs = 60U;
  double loop_max_correction_m = 1.0;
  double segment_sigma_xy_m = 0.10;
  double segment_sigma_theta_rad = 0.02;
  double loop_sigma_xy_m = 0.10;
  double loop_sigma_theta_rad = 0.02;
  // Direction-aware loop information (icp2d.h, frame_graph.h FrameInfo): a refined match
  // fixes the newer frame well only in the directions its wall points constrain; along a
  // corridor it slides, by a metre and more, at a small residual. With
  // loop_normal_radius_m > 0 the obstacle-point ICP measures the direction information M
  // of its final pairing (point-to-line normals of the older submap's walls fitted within
  // that radius; trace 1, ½ I when every direction is fixed) and the constraint's
  // translation information is (1/loop_sigma_xy_m²) × clamp(2 λ, loop_weak_direction_floor, 1)
  // along each eigenvector of M (eigenvalue λ): never more than the isotropic
  // constraint, and in the weak direction of a corridor little more than the floor.
  // The floor only keeps the solve well posed (σ about 3 m along a bare corridor): a
  // featureless corridor is matched along itself wherever the chain put it, so every
  // such match repeats the chain's own drift, and many of them must not add up to a
  // certainty the walls never gave. 0 = isotropic constraints.
  double loop_normal_radius_m = 0.4;       // [0, 2]
  double loop_weak_direction_floor = 0.001;  // [1e-4, 1]
  double loop_robust_chi = 3.0;
  std::uint32_t max_loop_constraints = 1024U;  // 1 .. capacity::kMaxLoopConstraints
  std::uint32_t graph_iterations = 5U;         // Gauss-Newton steps per adjustment, 1 .. 50
  // [sdp] wide loop search, beyond the paper (correlative_matcher.h; needs
  // loop_closure). The constraints above come from the top level's ICP, which only
  // converges when the chain already placed the two submaps within a few decimetres;
  // after a long loop it is metres off. So once per level, the best combination's
  // submap is searched against up to loop_search_candidates older, non-adjacent
  // submaps whose boxes, grown by the window the pair is searched with (below), overlap
  // its own: exhaustively within ±loop_search_window_m and ±loop_search_window_rad on
  // their obstacle points;
  // an unambiguous peak (mean likelihood >= loop_search_min_score over the newer
  // submap's points that fall on the older one's grid, at least loop_min_pairs of
  // them: two submaps overlap in part; no distinct peak
  // reaching loop_search_max_ambiguity × it) refined by obstacle ICP with the
  // loop_max_error_m / loop_min_pairs tests becomes a loop constraint. 0 = off.
  double loop_search_window_m = 0.0;           // [0, 20]
  // The window grows beyond loop_search_window_m, up to this, for a pair of levels whose
  // chain can have drifted farther (loop_search_drift_m × √hops, below): the search is
  // exact in its window, so a window narrower than the drift leaves the true place
  // unsearched and an alias inside it unique. A wider window sees both, and a repeated
  // structure becomes ambiguous instead of a wrong loop. Peaks beyond half of
  // loop_search_window_m are searched again around themselves. Cost: the grid reads grow
  // as the window squared, spread over scans by loop_search_reads_per_scan. 0 = no growth.
  double loop_search_max_window_m = 0.0;       // [0, 50]
  // ±0.6 rad: a cheap robot's heading is commonly 30° off after a long loop, and a single
  // bad turn of the bottom level can leave a quarter radian; the search is exact within
  // its window, so a drift just outside it is a loop lost.
  double loop_search_window_rad = 0.6;         // [0, pi]
  double loop_search_min_score = 0.45;         // (0, 1]
  double loop_search_max_ambiguity = 0.9;      // (0, 1]
  // A peak (however well it scores) that would move the newer submap (its box centre,
  // from where the best combination's frames put it now) farther than
  // loop_search_drift_m × √hops is refused; hops = the fewest steps between the two
  // levels along the chain and the other loop constraints already recorded (the chain
  // drifts like a random walk; a recorded loop is a short cut). Repeated structure
  // (doors, pillars at a regular pitch) makes peaks that are metres off and would pull
  // the map apart; a true loop's correction grows like the chain's random-walk drift.
  // A credible peak that moves the newer submap by more than half the window is kept
  // only if a second search, centred on it, finds it the unique best too (loop_closure.h).
  // A refused or weak peak is not retried against another older submap: the candidates
  // all overlap the newer submap, so they overlap each other too and see the same
  // repeated structure, and an aliased peak against one recurs against the next. 0: off.
  double loop_search_drift_m = 2.0;            // [0, 100]
  // Older submaps searched per level, largest overlaps first. A place revisited after a
  // long loop overlaps many older submaps (a corridor walked several times, rooms along
  // it), and the one that the drifted chain puts nearest is often not the one the robot
  // is really in, so by default every overlapping submap is a candidate, up to the fixed
  // capacity. Each is one exact search, spread over scans by
  // loop_search_reads_per_scan, and one more chance for a false peak, which the
  // verification above has to catch. The search takes the newest level first
  // (loop_closure.h), so a long list costs the search no lag behind the robot: the
  // candidates a newer level preempts are dropped, and so are those beyond this many
  // (both counted: loop_search_candidates_dropped).
  std::uint32_t loop_search_candidates = 32U;  // 1 .. kMaxLoopSearchCandidates
  // Grid reads of the search per process() call (about 1 ns each): a search is spread
  // over as many calls as it needs, whole headings at a time (at least one per call).
  std::uint32_t loop_search_reads_per_scan = 3000000U;  // [10000, 1e9]
  static constexpr std::uint32_t kMaxLoopSearchCandidates = 32U;

  SdpOptions() {
    icp.max_iterations = 15U;
    icp.max_correspondence_m = 0.6;
    icp.nn_cell_m = 0.3;
    icp.min_pairs = 20U;
  }

  // Every key of the [sdp] section: its field, range, unit and doc.
  static OptionTable<SdpOptions> table();
  // True iff every field is in its table's range and the fields agree; otherwise writes
  // "sdp.field: ..." into `why` (may be null).
  bool validate(char* why, std::size_t n) const;
};

}  // namespace sdpslam
