#include "sdpslam/core/sdp_options.h"

#include <cstdio>

namespace sdpslam {
namespace {

constexpr OptionChoice kTopologies[] = {{"sdp", static_cast<std::uint8_t>(TopologyMode::kSdp)},
                                        {"segslam", static_cast<std::uint8_t>(TopologyMode::kSegSlam)}};
constexpr OptionChoice kSegmentations[] = {{"periodic", static_cast<std::uint8_t>(SegmentationMode::kPeriodic)},
                                           {"dispersion", static_cast<std::uint8_t>(SegmentationMode::kDispersion)}};
constexpr OptionChoice kAccumulations[] = {{"sum", static_cast<std::uint8_t>(PgsAccumulation::kSum)},
                                           {"mean", static_cast<std::uint8_t>(PgsAccumulation::kMean)}};
constexpr double kPi = 3.14159265358979323846;
constexpr double kU32Max = 4294967295.0;

#define REAL(KEY, MIN, MAX, UNIT, DOC) SDPSLAM_OPTION_REAL(SdpOptions, "sdp", #KEY, KEY, MIN, MAX, UNIT, DOC)
#define U32(KEY, MIN, MAX, UNIT, DOC) SDPSLAM_OPTION_U32(SdpOptions, "sdp", #KEY, KEY, MIN, MAX, UNIT, DOC)
#define BOOL(KEY, DOC) SDPSLAM_OPTION_BOOL(SdpOptions, "sdp", #KEY, KEY, DOC)
#define CHOICE(KEY, CHOICES, DOC) SDPSLAM_OPTION_CHOICE(SdpOptions, "sdp", #KEY, KEY, CHOICES, DOC)

const OptionSpec<SdpOptions> kRows[] = {
    // top level (Algorithm 1 lines 9-12)
    U32(top_particles, 1U, capacity::kMaxTopParticles, "", "top-level particles (submap combinations)"),
    CHOICE(topology, kTopologies, "sdp: re-sample anywhere in the chain; segslam: only the last segslam_window segments"),
    U32(segslam_window, 1U, capacity::kMaxPgsLevels, "", "segments SegSLAM's local analysis re-samples"),
    REAL(elite_fraction, 0.0, 1.0, "", "best particles kept unchanged per round"),
    REAL(worst_fraction, 0.0, 1.0, "", "worst particles replaced by copies of the elite (elite + worst <= 1)"),
    U32(diversify_levels, 1U, capacity::kMaxPgsLevels, "", "submap choices re-sampled from the PGS per diversified particle"),
    REAL(follow_best_fraction, 0.0, 1.0, "", "share that extends its combination with the bottom filter's best submap"),
    U32(rounds_per_segment, 1U, 1000U, "", "evaluation rounds after a segmentation"),
    U32(evaluations_per_scan, 1U, capacity::kMaxTopParticles, "", "top-level samples evaluated per scan (time budget)"),
    U32(max_pairs_per_sample, 1U, 64U, "", "overlapping submap pairs matched by ICP per sample"),
    REAL(overlap_margin_m, 0.0, 100.0, "m", "bounding boxes grown by this before the overlap test"),
    REAL(min_overlap_m2, 0.0, 1.0e6, "m^2", "smaller box overlaps are ignored"),
    // segmentation (line 4)
    CHOICE(segmentation, kSegmentations, "periodic: every period_*; dispersion: when the bottom particles spread"),
    REAL(period_travel_m, 0.0, 1.0e5, "m", "periodic: travel per segment (0 = unused)"),
    REAL(period_time_s, 0.0, 1.0e6, "s", "periodic: log time per segment (0 = unused)"),
    U32(period_scans, 0U, 1000000U, "", "periodic: processed scans per segment (0 = unused)"),
    REAL(dispersion_threshold_m, 0.0, 100.0, "m", "dispersion: RMS spread of the bottom particles' positions"),
    U32(min_segment_scans, 1U, 1000000U, "", "processed scans before any segmentation"),
    U32(max_segment_scans, 1U, 1000000U, "", "processed scans after which a segment always ends (>= min_segment_scans)"),
    // PGS
    U32(max_levels, 2U, capacity::kMaxPgsLevels, "", "live PGS levels; older ones become permanent"),
    CHOICE(accumulation, kAccumulations, "PGS edge error: sum (the paper's) or mean"),
    REAL(prior_error_m, 1.0e-6, 1.0e6, "m", "error of never-sampled edges and never-evaluated samples"),
    U32(max_permanent_submaps, 1U, capacity::kMaxPermanentSubmaps, "", "permanent submaps kept for loop closures"),
    // skeleton
    U32(skeleton_points, 8U, capacity::kMaxIcpPoints, "", "free-space skeleton points per submap"),
    U32(skeleton_downsample, 1U, 8U, "", "skeleton grid cell = map cell x this"),
    REAL(skeleton_pad_m, 0.0, 100.0, "m", "skeleton patch = the submap's path bounds + this"),
    REAL(skeleton_max_side_m, 1.0, 1000.0, "m", "largest skeleton patch side (sizes the work buffers)"),
    REAL(skeleton_min_clearance_m, 0.0, 10.0, "m", "skeleton points closer to an obstacle are dropped"),
    REAL(occupied_threshold, 0.0, 1.0, "", "occupancy >= this is an obstacle"),
    REAL(free_threshold, 0.0, 1.0, "", "occupancy <= this is free space (<= occupied_threshold)"),
    U32(work_cells_per_scan, 1024U, 1U << 28U, "", "map cells read per scan by anchorage work (time budget)"),
    BOOL(defer_top_work, "the top level's work waits while the bottom level processes scans"),
    U32(map_tile_capacity, 0U, capacity::kDpMaxTiles, "", "DP map tiles in SDP mode (0 = [map] tile_capacity), 1 KiB each"),
    U32(map_observation_capacity, 0U, capacity::kDpMaxObservations, "",
        "DP map observations in SDP mode (0 = [map] values), 24 B each"),
    U32(permanent_map_tiles, 1U, capacity::kDpMaxTiles, "", "tiles of the global map's permanent part, 2 KiB each"),
    BOOL(map_owner_cell_index, "the DP map's (owner, cell) index in SDP mode"),
    // ICP (Icp2dOptions; Icp2dOptions::valid joins them)
    SDPSLAM_OPTION_U32(SdpOptions, "sdp", "icp_max_iterations", icp.max_iterations, 1U, kU32Max, "",
                       "ICP iterations per match"),
    SDPSLAM_OPTION_REAL_OPEN(SdpOptions, "sdp", "icp_max_correspondence_m", icp.max_correspondence_m, 0.0, 1.0e3, "m",
                             "pairs farther apart are rejected; a failed match counts as this error"),
    SDPSLAM_OPTION_REAL(SdpOptions, "sdp", "icp_nn_cell_m", icp.nn_cell_m, 1.0e-3, 1.0e3, "m",
                        "side of ICP's nearest-neighbour hash cells"),
    SDPSLAM_OPTION_U32(SdpOptions, "sdp", "icp_min_pairs", icp.min_pairs, 2U, kU32Max, "",
                       "fewer matched pairs: the submaps do not overlap"),
    REAL(icp_correction_weight, 0.0, 100.0, "", "beyond the paper: also charge ICP's correction (0 = the paper's error)"),
    REAL(icp_correction_lever_m, 0.0, 100.0, "m", "metres per radian of heading correction"),
    // loop closure (beyond the paper)
    BOOL(loop_closure, "adjust the best combination's frames to loop constraints"),
    U32(loop_points, 16U, capacity::kMaxIcpPoints, "", "obstacle points per submap"),
    REAL(loop_icp_max_correspondence_m, 0.01, 10.0, "m", "obstacle-point ICP refining a match: pairs within this"),
    REAL(loop_max_error_m, 0.0, 10.0, "m", "a refined match is a constraint iff its mean pair distance <= this"),
    U32(loop_min_pairs, 1U, capacity::kMaxIcpPoints, "", "... over at least this many pairs"),
    REAL(loop_max_correction_m, 0.0, 1.0e3, "m", "... moving the newer submap at most this far from the chain's placement"),
    REAL(segment_sigma_xy_m, 1.0e-4, 100.0, "m", "pose graph: chain transform between consecutive submaps, std dev"),
    REAL(segment_sigma_theta_rad, 1.0e-5, 10.0, "rad", "... its heading std dev"),
    REAL(loop_sigma_xy_m, 1.0e-4, 100.0, "m", "pose graph: loop constraint std dev"),
    REAL(loop_sigma_theta_rad, 1.0e-5, 10.0, "rad", "... its heading std dev"),
    REAL(loop_normal_radius_m, 0.0, 2.0, "m", "direction-aware loops: wall normals fitted within this (0 = isotropic)"),
    REAL(loop_weak_direction_floor, 1.0e-4, 1.0, "", "share of a loop's information kept along a direction it does not fix"),
    REAL(loop_robust_chi, 1.0e-3, 1.0e3, "", "Dynamic Covariance Scaling kernel scale, in std devs"),
    U32(max_loop_constraints, 1U, capacity::kMaxLoopConstraints, "", "loop constraints kept (one per pair of levels)"),
    U32(graph_iterations, 1U, 50U, "", "Gauss-Newton steps per adjustment"),
    // wide loop search (beyond the paper)
    REAL(loop_search_window_m, 0.0, 20.0, "m", "+- translation searched per pair of submaps (0 = off)"),
    REAL(loop_search_max_window_m, 0.0, 50.0, "m", "the window grows to the chain's drift bound, up to this (0 = never)"),
    REAL(loop_search_window_rad, 0.0, kPi, "rad", "+- heading searched"),
    SDPSLAM_OPTION_REAL_OPEN(SdpOptions, "sdp", "loop_search_min_score", loop_search_min_score, 0.0, 1.0, "", "best pose's mean likelihood per obstacle point"),
    SDPSLAM_OPTION_REAL_OPEN(SdpOptions, "sdp", "loop_search_max_ambiguity", loop_search_max_ambiguity, 0.0, 1.0, "", "a distinct peak this close to the best: ambiguous"),
    REAL(loop_search_drift_m, 0.0, 100.0, "m", "a peak moving its submap more than this x sqrt(hops) is refused (0 = off)"),
    U32(loop_search_candidates, 1U, SdpOptions::kMaxLoopSearchCandidates, "", "older submaps searched per level"),
    U32(loop_search_reads_per_scan, 10000U, 1000000000U, "", "search grid reads per scan (~1 ns each)"),
};

#undef REAL
#undef U32
#undef BOOL
#undef CHOICE

struct Check {
  char* why;
  std::size_t n;
  bool ok = true;
  void fail(const char* what) {
    if (ok) {
      ok = false;
      if (why != nullptr && n > 0U) std::snprintf(why, n, "sdp.%s", what);
    }
  }
};

}  // namespace

OptionTable<SdpOptions> SdpOptions::table() { return {kRows, sizeof kRows / sizeof kRows[0]}; }

bool SdpOptions::validate(char* why, std::size_t n) const {
  if (why != nullptr && n > 0U) why[0] = '\0';
  if (!options_in_range(table(), *this, why, n)) return false;
  // The checks that join fields.
  Check c{why, n};
  if (elite_fraction + worst_fraction > 1.0) c.fail("elite_fraction + worst_fraction: more than 1");
  if (max_segment_scans < min_segment_scans) c.fail("max_segment_scans: less than min_segment_scans");
  if (segmentation == SegmentationMode::kPeriodic && period_travel_m <= 0.0 && period_time_s <= 0.0 &&
      period_scans == 0U) {
    c.fail("period_travel_m: periodic segmentation needs period_travel_m, period_time_s or period_scans > 0");
  }
  if (free_threshold > occupied_threshold) c.fail("free_threshold: more than occupied_threshold");
  if (!icp.valid()) c.fail("icp: options out of range (see icp2d.h Icp2dOptions::valid)");
  if (loop_normal_radius_m > 100.0 * icp.nn_cell_m) {
    c.fail("loop_normal_radius_m: more than 100 icp nearest-neighbour cells (see Icp2d::direction_information)");
  }
  return c.ok;
}

}  // namespace sdpslam
