#include "sdpslam/core/sdp_options.h"

#include <cstdio>

namespace sdpslam {
namespace {

struct Check {
  char* why;
  std::size_t n;
  bool ok = true;
  void real(const char* f, double v, double lo, double hi) {
    if (ok && !(v >= lo && v <= hi)) {
      ok = false;
      if (why != nullptr && n > 0U) std::snprintf(why, n, "sdp.%s: %g out of range [%g, %g]", f, v, lo, hi);
    }
  }
  void integer(const char* f, std::uint64_t v, std::uint64_t lo, std::uint64_t hi) {
    if (ok && (v < lo || v > hi)) {
      ok = false;
      if (why != nullptr && n > 0U)
        std::snprintf(why, n, "sdp.%s: %llu out of range [%llu, %llu]", f, static_cast<unsigned long long>(v),
                      static_cast<unsigned long long>(lo), static_cast<unsigned long long>(hi));
    }
  }
  void fail(const char* what) {
    if (ok) {
      ok = false;
      if (why != nullptr && n > 0U) std::snprintf(why, n, "sdp.%s", what);
    }
  }
};

}  // namespace

bool SdpOptions::validate(char* why, std::size_t n) const {
  if (why != nullptr && n > 0U) why[0] = '\0';
  Check c{why, n};
  c.integer("top_particles", top_particles, 1U, capacity::kMaxTopParticles);
  c.integer("segslam_window", segslam_window, 1U, capacity::kMaxPgsLevels);
  c.real("elite_fraction", elite_fraction, 0.0, 1.0);
  c.real("worst_fraction", worst_fraction, 0.0, 1.0);
  c.real("elite_fraction + worst_fraction", elite_fraction + worst_fraction, 0.0, 1.0);
  c.integer("diversify_levels", diversify_levels, 1U, capacity::kMaxPgsLevels);
  c.real("follow_best_fraction", follow_best_fraction, 0.0, 1.0);
  c.integer("rounds_per_segment", rounds_per_segment, 1U, 1000U);
  c.integer("evaluations_per_scan", evaluations_per_scan, 1U, capacity::kMaxTopParticles);
  c.integer("max_pairs_per_sample", max_pairs_per_sample, 1U, 64U);
  c.real("overlap_margin_m", overlap_margin_m, 0.0, 100.0);
  c.real("min_overlap_m2", min_overlap_m2, 0.0, 1.0e6);
  c.real("period_travel_m", period_travel_m, 0.0, 1.0e5);
  c.real("period_time_s", period_time_s, 0.0, 1.0e6);
  c.integer("period_scans", period_scans, 0U, 1000000U);
  c.real("dispersion_threshold_m", dispersion_threshold_m, 0.0, 100.0);
  c.integer("min_segment_scans", min_segment_scans, 1U, 1000000U);
  c.integer("max_segment_scans", max_segment_scans, min_segment_scans, 1000000U);
  if (segmentation == SegmentationMode::kPeriodic && period_travel_m <= 0.0 && period_time_s <= 0.0 &&
      period_scans == 0U) {
    c.fail("periodic segmentation needs period_travel_m, period_time_s or period_scans > 0");
  }
  c.integer("max_levels", max_levels, 2U, capacity::kMaxPgsLevels);
  c.real("prior_error_m", prior_error_m, 1.0e-6, 1.0e6);
  c.integer("max_permanent_submaps", max_permanent_submaps, 1U, capacity::kMaxPermanentSubmaps);
  c.integer("skeleton_points", skeleton_points, 8U, capacity::kMaxIcpPoints);
  c.integer("skeleton_downsample", skeleton_downsample, 1U, 8U);
  c.real("skeleton_pad_m", skeleton_pad_m, 0.0, 100.0);
  c.real("skeleton_max_side_m", skeleton_max_side_m, 1.0, 1000.0);
  c.real("skeleton_min_clearance_m", skeleton_min_clearance_m, 0.0, 10.0);
  c.real("occupied_threshold", occupied_threshold, 0.0, 1.0);
  c.real("free_threshold", free_threshold, 0.0, occupied_threshold);
  c.integer("work_cells_per_scan", work_cells_per_scan, 1024U, 1U << 28U);
  c.integer("map_tile_capacity", map_tile_capacity, 0U, capacity::kDpMaxTiles);
  c.integer("map_observation_capacity", map_observation_capacity, 0U, capacity::kDpMaxObservations);
  c.integer("permanent_map_tiles", permanent_map_tiles, 1U, capacity::kDpMaxTiles);
  c.real("icp_correction_weight", icp_correction_weight, 0.0, 100.0);
  c.real("icp_correction_lever_m", icp_correction_lever_m, 0.0, 100.0);
  c.integer("loop_points", loop_points, 16U, capacity::kMaxIcpPoints);
  c.real("loop_icp_max_correspondence_m", loop_icp_max_correspondence_m, 0.01, 10.0);
  c.real("loop_max_error_m", loop_max_error_m, 0.0, 10.0);
  c.integer("loop_min_pairs", loop_min_pairs, 1U, capacity::kMaxIcpPoints);
  c.real("loop_max_correction_m", loop_max_correction_m, 0.0, 1.0e3);
  c.real("segment_sigma_xy_m", segment_sigma_xy_m, 1.0e-4, 100.0);
  c.real("segment_sigma_theta_rad", segment_sigma_theta_rad, 1.0e-5, 10.0);
  c.real("loop_sigma_xy_m", loop_sigma_xy_m, 1.0e-4, 100.0);
  c.real("loop_sigma_theta_rad", loop_sigma_theta_rad, 1.0e-5, 10.0);
  c.real("loop_normal_radius_m", loop_normal_radius_m, 0.0, 2.0);
  c.real("loop_weak_direction_floor", loop_weak_direction_floor, 1.0e-4, 1.0);
  c.real("loop_robust_chi", loop_robust_chi, 1.0e-3, 1.0e3);
  c.integer("max_loop_constraints", max_loop_constraints, 1U, capacity::kMaxLoopConstraints);
  c.integer("graph_iterations", graph_iterations, 1U, 50U);
  c.real("loop_search_window_m", loop_search_window_m, 0.0, 20.0);
  c.real("loop_search_max_window_m", loop_search_max_window_m, 0.0, 50.0);
  c.real("loop_search_window_rad", loop_search_window_rad, 0.0, 3.14159265358979323846);
  c.real("loop_search_min_score", loop_search_min_score, 1.0e-6, 1.0);
  c.real("loop_search_max_ambiguity", loop_search_max_ambiguity, 1.0e-6, 1.0);
  c.real("loop_search_drift_m", loop_search_drift_m, 0.0, 100.0);
  c.integer("loop_search_candidates", loop_search_candidates, 1U, kMaxLoopSearchCandidates);
  c.integer("loop_search_reads_per_scan", loop_search_reads_per_scan, 10000U, 1000000000U);
  if (c.ok && !icp.valid()) c.fail("icp: options out of range (see icp2d.h Icp2dOptions::valid)");
  if (c.ok && loop_normal_radius_m > 100.0 * icp.nn_cell_m) {
    c.fail("loop_normal_radius_m: more than 100 icp nearest-neighbour cells (see Icp2d::direction_information)");
  }
  return c.ok;
}

}  // namespace sdpslam
