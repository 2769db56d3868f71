#include "sdpslam/core/dpslam_options.h"

#include <cstdio>

namespace sdpslam {
namespace {

struct Checker {
  char* why;
  std::size_t n;
  bool ok = true;

  void real(const char* field, double v, double lo, double hi) {
    if (!ok) return;
    if (!(v >= lo && v <= hi)) {
      ok = false;
      if (why != nullptr && n > 0U) std::snprintf(why, n, "%s: %g out of range [%g, %g]", field, v, lo, hi);
    }
  }
  void integer(const char* field, std::uint64_t v, std::uint64_t lo, std::uint64_t hi) {
    if (!ok) return;
    if (v < lo || v > hi) {
      ok = false;
      if (why != nullptr && n > 0U)
        std::snprintf(why, n, "%s: %llu out of range [%llu, %llu]", field, static_cast<unsigned long long>(v),
                      static_cast<unsigned long long>(lo), static_cast<unsigned long long>(hi));
    }
  }
};

std::uint64_t tiles_of_area(const DpSlamOptions& o) {
  const double side = o.map_resolution_m * static_cast<double>(capacity::kDpTileSideCells);
  const double tx = o.map_width_m / side + 1.0;
  const double ty = o.map_height_m / side + 1.0;
  return static_cast<std::uint64_t>(tx) * static_cast<std::uint64_t>(ty);
}

}  // namespace

namespace {

constexpr OptionChoice kProposals[] = {{"odometry", static_cast<std::uint8_t>(DpSlamOptions::Proposal::kOdometry)},
                                       {"scan_match", static_cast<std::uint8_t>(DpSlamOptions::Proposal::kScanMatch)}};
constexpr OptionChoice kWeights[] = {
    {"match", static_cast<std::uint8_t>(DpSlamOptions::ProposalWeight::kMatch)},
    {"neighbourhood", static_cast<std::uint8_t>(DpSlamOptions::ProposalWeight::kNeighbourhood)}};

#define REAL(SEC, KEY, MEMBER, MIN, MAX, UNIT, DOC) SDPSLAM_OPTION_REAL(DpSlamOptions, SEC, KEY, MEMBER, MIN, MAX, UNIT, DOC)
#define OPEN(SEC, KEY, MEMBER, MIN, MAX, UNIT, DOC) \
  SDPSLAM_OPTION_REAL_OPEN(DpSlamOptions, SEC, KEY, MEMBER, MIN, MAX, UNIT, DOC)
#define U32(SEC, KEY, MEMBER, MIN, MAX, UNIT, DOC) SDPSLAM_OPTION_U32(DpSlamOptions, SEC, KEY, MEMBER, MIN, MAX, UNIT, DOC)

const OptionSpec<DpSlamOptions> kRows[] = {
    U32("filter", "particles", particle_count, 1U, capacity::kMaxBottomParticles, "", "bottom-level particles"),
    OPEN("filter", "resample_neff_ratio", resample_neff_ratio, 0.0, 1.0, "", "resample iff N_eff < ratio x particles"),
    REAL("filter", "update_min_travel_m", update_min_travel_m, 0.0, 10.0, "m", "process a scan after this much travel"),
    REAL("filter", "update_min_rotation_rad", update_min_rotation_rad, 0.0, 3.14159, "rad", "... or this much rotation"),
    REAL("motion", "alpha_rot_from_rot", motion.alpha_rot_from_rot, 0.0, 10.0, "rad^2/rad^2", "odometry model a1"),
    REAL("motion", "alpha_rot_from_trans", motion.alpha_rot_from_trans, 0.0, 10.0, "rad^2/m^2", "odometry model a2"),
    REAL("motion", "alpha_trans_from_trans", motion.alpha_trans_from_trans, 0.0, 10.0, "m^2/m^2", "odometry model a3"),
    REAL("motion", "alpha_trans_from_rot", motion.alpha_trans_from_rot, 0.0, 10.0, "m^2/rad^2", "odometry model a4"),
    REAL("motion", "min_sigma_trans_m", motion.min_sigma_trans_m, 0.0, 1.0, "m", "noise floor on trans"),
    REAL("motion", "min_sigma_rot_rad", motion.min_sigma_rot_rad, 0.0, 1.0, "rad", "noise floor on rot1 and rot2"),
    OPEN("observation", "sigma_hit_m", beam.sigma_hit_m, 0.0, 5.0, "m", "range error standard deviation"),
    OPEN("observation", "window_m", beam.window_m, 0.0, 5.0, "m", "evaluated stretch around the reading"),
    OPEN("observation", "prior_hits", beam.prior_hits, 0.0, 1000.0, "", "Beta prior of the stopping probability"),
    OPEN("observation", "prior_misses", beam.prior_misses, 0.0, 1000.0, "", "Beta prior of the stopping probability"),
    OPEN("observation", "unknown_stop_probability", beam.unknown_stop_probability, 0.0, 0.99, "",
         "stopping probability of an unobserved cell"),
    OPEN("observation", "floor_likelihood", beam.floor_likelihood, 0.0, 1.0, "", "per-beam floor for unexplained readings"),
    U32("observation", "weight_beam_stride", beam.weight_beam_stride, 1U, capacity::kMaxBeams, "",
        "every k-th beam weights particles"),
    OPEN("observation", "max_update_range_m", beam.max_update_range_m, 0.0, 200.0, "m",
         "longer beams mark free space up to here, no hit"),
    REAL("observation", "no_return_free_m", beam.no_return_free_m, 0.0, 200.0, "m",
         "no-return beams mark free space up to here (0 = off)"),
    REAL("observation", "likelihood_temperature", beam.likelihood_temperature, 1.0, 1000.0, "",
         "log-likelihood divided by this"),
    SDPSLAM_OPTION_CHOICE(DpSlamOptions, "proposal", "kind", proposal, kProposals,
                          "odometry (the paper's) or scan_match (improved proposal, Grisetti et al. 2007)"),
    SDPSLAM_OPTION_CHOICE(DpSlamOptions, "proposal", "weight", proposal_weight, kWeights,
                          "scan_match weight: match (likelihood at the match) or neighbourhood (mean over the finest level)"),
    OPEN("proposal", "linear_step_m", match.linear_step_m, 0.0, 1.0, "m", "first hill-climbing step in x and y"),
    OPEN("proposal", "angular_step_rad", match.angular_step_rad, 0.0, 0.5, "rad", "first hill-climbing step in heading"),
    U32("proposal", "refinements", match.refinements, 0U, 10U, "", "step halvings after the first level"),
    U32("proposal", "max_iterations", match.max_iterations, 1U, 100U, "", "moves per level"),
    U32("proposal", "beam_stride", match.beam_stride, 1U, capacity::kMaxBeams, "", "every k-th beam scores a candidate"),
    U32("proposal", "min_beams", match.min_beams, 1U, capacity::kMaxBeams, "", "fewer return beams: odometry proposal"),
    REAL("proposal", "min_known_fraction", match.min_known_fraction, 0.0, 1.0, "",
         "fewer beams meeting mapped cells: odometry proposal"),
    REAL("proposal", "min_mean_log_likelihood", match.min_mean_log_likelihood, -50.0, 0.0, "",
         "per-beam mean log-likelihood at the match below this: odometry proposal"),
    REAL("proposal", "sample_sigma_xy_m", proposal_sigma_xy_m, 0.0, 1.0, "m", "noise of the sample around the match"),
    REAL("proposal", "sample_sigma_rot_rad", proposal_sigma_rot_rad, 0.0, 0.5, "rad", "... in heading"),
    REAL("map", "resolution_m", map_resolution_m, 0.005, 1.0, "m", "cell side"),
    REAL("map", "width_m", map_width_m, 1.0, 10000.0, "m", "mode dpslam: the area; sdp mode: least window of the moving DP map"),
    REAL("map", "height_m", map_height_m, 1.0, 10000.0, "m", "the same across"),
    U32("map", "tile_capacity", map_tile_capacity, 0U, capacity::kDpMaxTiles, "", "16x16-cell tiles that may hold data (0 = the whole area)"),
    U32("map", "observations_base", map_observations_base, 0U, capacity::kDpMaxObservations, "",
        "DP map observations shared by all particles"),
    U32("map", "observations_per_particle", map_observations_per_particle, 1U, 100000000U, "",
        "plus this many per particle"),
    U32("capacity", "ancestry_nodes_per_particle", ancestry_nodes_per_particle, 1U,
        capacity::kDpSlamMaxNodesPerParticle, "", "ancestry-tree nodes per particle"),
    U32("capacity", "path_entries_per_particle", path_entries_per_particle, 1U,
        capacity::kDpSlamMaxPathEntriesPerParticle, "", "uncommitted poses per particle"),
};

#undef REAL
#undef OPEN
#undef U32

}  // namespace

OptionTable<DpSlamOptions> DpSlamOptions::table() { return {kRows, sizeof kRows / sizeof kRows[0]}; }

bool DpSlamOptions::validate(char* why, std::size_t n) const {
  if (why != nullptr && n > 0U) why[0] = '\0';
  if (!options_in_range(table(), *this, why, n)) return false;
  // The checks that join fields.
  Checker c{why, n};
  // The window must cover the Gaussian and at least one cell; the table must hold it.
  c.real("observation.window_m", beam.window_m, map_resolution_m,
         map_resolution_m * static_cast<double>(BeamModel::kMaxGaussEntries) /
                 static_cast<double>(BeamModel::kGaussSubsteps) - 2.0 * map_resolution_m);
  const double cells = (map_width_m / map_resolution_m) * (map_height_m / map_resolution_m);
  c.real("map.width_m*height_m/resolution_m^2 (cells)", cells, 1.0, 4.0e9);
  const std::uint64_t obs = static_cast<std::uint64_t>(map_observations_base) +
                            static_cast<std::uint64_t>(particle_count) * map_observations_per_particle;
  c.integer("map.observations_base + particles*observations_per_particle", obs, 1U, capacity::kDpMaxObservations);
  c.integer("particles*capacity.path_entries_per_particle + extra_path_entries",
            static_cast<std::uint64_t>(particle_count) * path_entries_per_particle + extra_path_entries, 1U,
            0xF0000000U);
  c.integer("particles*capacity.ancestry_nodes_per_particle + extra_ancestry_nodes",
            static_cast<std::uint64_t>(particle_count) * ancestry_nodes_per_particle + extra_ancestry_nodes, 1U,
            0x10000000U);
  c.integer("map tiles (0 = whole area)", map_tile_capacity == 0U ? tiles_of_area(*this) : map_tile_capacity, 1U,
            capacity::kDpMaxTiles);
  return c.ok;
}

std::uint32_t DpSlamOptions::observation_capacity() const {
  return map_observations_base + particle_count * map_observations_per_particle;
}

std::uint32_t DpSlamOptions::tile_capacity() const {
  return map_tile_capacity != 0U ? map_tile_capacity : static_cast<std::uint32_t>(tiles_of_area(*this));
}

}  // namespace sdpslam
