#pragma once
// Observation model of the bottom-level filter, evaluated through the distributed
// particle map (paper §II-A; Eliazar & Parr, DP-SLAM 2.0, ICRA 2004 §3 "laser
// penetration model").
//
// Choice: DP-SLAM's stopping-probability (penetration) model rather than a log-odds
// beam model, because it is what the DP map's per-node (hits, misses) counts measure:
// the chance that a beam entering a cell stops in it is estimated as
//   p_stop(h, m) = (h + prior_hits) / (h + m + prior_hits + prior_misses)
// (a Beta-prior estimate of DP-SLAM's opacity), and a cell nobody has seen has
// p_stop = unknown_stop_probability. A beam of measured range r is scored by the chance
// that it stops at cell k, having passed cells before it, times the Gaussian chance of
// reading r from that cell, plus a floor for readings the model cannot explain:
//   L = floor + Σ_k p_stop(k) · Π_{j<k} (1 − p_stop(j)) · N(r − d_k; σ)·cell
// The sum runs over the cells the beam crosses within ±window of r (DDA/Bresenham on
// cells), which is where nearly all of the mass is; cells before the window are taken
// as passed (their misses are what the map update writes). This keeps the hot path at
// ~2·window/cell lookups per beam.
//
// Hot path: no transcendental calls per beam. p_stop comes from a LUT over (hits,
// misses) clamped to 0..kStopLutSide−1 (larger counts are scaled down keeping their
// ratio); the Gaussian from a LUT over |error| in 1/16 cell steps; beam directions are
// rotated with one sin/cos per particle; the product over beams is kept as a mantissa
// and a binary exponent (exact bit operations), so a scan costs one det::log.
//
// Map update (all beams, every surviving particle): a miss for every cell from the
// laser to the end point, a hit at the end point (DP-SLAM's d/h counts). Beams longer
// than max_update_range_m mark misses up to that range and no hit; no-return beams mark
// misses up to no_return_free_m (0 = not at all). A dropped update (map pool exhausted,
// outside the area) is counted by DpMap and reported; the map stays consistent.
#include <cstddef>
#include <cstdint>

#include "sdpslam/core/bottom/dp_map.h"
#include "sdpslam/core/pose2.h"
#include "sdpslam/core/range_scan.h"
#include "sdpslam/core/bottom/view_cache.h"

namespace sdpslam {

struct BeamModelOptions {
  double sigma_hit_m = 0.05;             // range error standard deviation
  double window_m = 0.15;                // half-width of the evaluated stretch around r
  double prior_hits = 0.5;               // Beta prior of the stopping probability
  double prior_misses = 1.0;
  double unknown_stop_probability = 0.05;  // p_stop of a cell nobody has observed
  double floor_likelihood = 0.02;        // added to every beam's likelihood (outliers)
  std::uint32_t weight_beam_stride = 2;  // every k-th beam weights particles
  double max_update_range_m = 15.0;      // beams beyond: misses up to here, no hit
  double no_return_free_m = 5.0;         // no-return beams: misses up to here
  double likelihood_temperature = 1.0;   // log-likelihood is divided by this (≥ 1 softens)
};

// Per-scan quantities shared by all particles (computed once per scan, not per particle).
struct ScanRays {
  std::uint32_t count = 0U;
  float range_m[capacity::kMaxBeams] = {};
  double cos_a[capacity::kMaxBeams] = {};  // beam direction in the laser frame
  double sin_a[capacity::kMaxBeams] = {};
  std::uint8_t kind[capacity::kMaxBeams] = {};  // RangeScan::Beam
  Pose2 laser_in_base;
};
void prepare_rays(const RangeScan& scan, ScanRays* out);

// What one strided evaluation looked at (for the scan matcher's failure tests).
struct BeamScore {
  std::uint32_t beams = 0U;        // return beams evaluated
  std::uint32_t known_beams = 0U;  // ... whose window met at least one observed cell
};

class BeamModel {
 public:
  static constexpr std::uint32_t kStopLutSide = 64U;
  static constexpr std::uint32_t kGaussSubsteps = 16U;
  static constexpr std::uint32_t kMaxGaussEntries = 4096U;

  // Builds the tables for `options` and a grid of `resolution_m`. Returns false (and
  // writes a reason) iff an option is out of range.
  bool init(const BeamModelOptions& options, double resolution_m);

  // log p(scan | pose, particle's map), divided by likelihood_temperature. Costs
  // ~(beams / stride) · (2·window / cell) map lookups.
  double log_likelihood(const DpMap& map, NodeId particle, const ScanRays& rays, const Pose2& robot) const;
  // The same on every `stride`-th beam (stride ≥ 1; 0 is taken as 1), filling `score`
  // (may be null). log_likelihood() is this with stride = weight_beam_stride, bit for
  // bit. Used by the scan matcher of the improved proposal (scan_matcher.h).
  double log_likelihood_strided(const DpMap& map, NodeId particle, const ScanRays& rays, const Pose2& robot,
                                std::uint32_t stride, BeamScore* score) const;
  // The same through `view` (view.begin(map, particle) called, map unchanged since):
  // bit-identical, with repeated cells read once.
  double log_likelihood_strided(ViewCache& view, const DpMap& map, const ScanRays& rays, const Pose2& robot,
                                std::uint32_t stride, BeamScore* score) const;

  // Writes the scan into `particle`'s map. Returns the number of cell updates the map
  // dropped (0 normally).
  std::uint32_t update_map(DpMap& map, NodeId particle, const ScanRays& rays, const Pose2& robot) const {
    return update_map(map, particle, rays, robot, options_.max_update_range_m);
  }
  // The same with the update range shortened to `reach_m` (taken within 0 and
  // max_update_range_m): beams beyond it mark misses up to it and no hit, as beyond
  // max_update_range_m. A filter whose pool cannot hold a scan's full writes writes its
  // near part this way.
  std::uint32_t update_map(DpMap& map, NodeId particle, const ScanRays& rays, const Pose2& robot,
                           double reach_m) const {
    return update_map(map, particle, rays, robot, reach_m, nullptr);
  }
  // The same, write-combined through `scratch`: marks_words(max_update_range_m, cell)
  // zeroed words (cells_written()'s scratch; zeroed again on return), or nullptr to
  // write every traced cell as it comes. A scan's beams fan out from the laser, so they
  // cross the cells near it many times over, and every DpMap::add() walks its cell's
  // list. With scratch, the writes to a square of cells around the laser's cell (as many
  // as the scratch has words) are summed and each cell is written with one add(); the
  // cells beyond are written as they come. The map ends the same: counts add, only the
  // order of first records in the pool differs. The near cells are written first, as a
  // scan's beams write them first without scratch, so that a pool that runs out drops
  // far updates. Out-of-map writes count the same. Either way the adds go to the map in
  // runs of distinct cells (the near square's, then each beam's), in the same order
  // (DpMap::add_run(): their cell lists are walked side by side).
  std::uint32_t update_map(DpMap& map, NodeId particle, const ScanRays& rays, const Pose2& robot, double reach_m,
                           std::uint64_t* scratch) const;
  // The new observations one particle's update takes from the pool (its node is fresh)
  // are the distinct cells update_map() writes.
  // - An upper bound at any pose: Bresenham moves one cell along the longer axis per
  //   step, so a beam's d-th cell lies on the square ring d cells around the laser's
  //   cell, and a beam traced to `end` has at most floor(end / cell) + 3 cells (+1 for
  //   each end's rounding to a cell, +1 for floating-point rounding). The first k + 1
  //   cells of every beam lie within the (2k + 1)^2 square, so the scan covers at most
  //   (2k + 1)^2 + sum over beams of max(0, cells - k - 1), taken at the k that makes it
  //   least. O(beams).
  std::uint64_t cells_bound(const ScanRays& rays) const { return cells_bound(rays, options_.max_update_range_m); }
  std::uint64_t cells_bound(const ScanRays& rays, double reach_m) const;
  // - The count at `robot`, traced exactly as update_map() with update range `reach_m`
  //   traces, without touching the map: exact for cells inside the map (a cell outside
  //   it is dropped, and counted here all the same). O(cells). With `into` a node, the
  //   cells it already holds are left out (they take nothing new: a restart's root that
  //   holds earlier scans), at a lookup per cell; kNoNode counts for a fresh node.
  //   `marks` is scratch of marks_words(max_update_range_m, cell) zeroed words (one bit
  //   per cell of the square an update can reach around the laser's cell), zeroed again
  //   on return.
  std::uint64_t cells_written(const DpMap& map, const ScanRays& rays, const Pose2& robot, double reach_m,
                              NodeId into, std::uint64_t* marks) const;
  static std::size_t marks_words(double max_update_range_m, double resolution_m);

  // Stopping probability of a cell with these counts (the LUT the hot path uses).
  double stop_probability(const CellObservation& c) const;
  const BeamModelOptions& options() const { return options_; }

 private:
  double gauss_mass(double abs_error_m) const;
  // How far update_map() traces a beam of this kind and range with update range
  // `reach_m`, and whether it ends in a hit; false iff it traces nothing.
  bool traced_m(RangeScan::Beam kind, double range_m, double reach_m, double* end_m, bool* hit) const;
  struct Tracer;
  template <class Lookup>
  double likelihood(const DpMap& map, const ScanRays& rays, const Pose2& robot, std::uint32_t stride,
                    BeamScore* score, Lookup&& lookup) const;

  BeamModelOptions options_{};
  double resolution_m_ = 0.05;
  double inv_gauss_step_ = 0.0;
  std::uint32_t gauss_entries_ = 0U;
  double stop_lut_[kStopLutSide * kStopLutSide] = {};
  double gauss_lut_[kMaxGaussEntries] = {};
};

}  // namespace sdpslam
