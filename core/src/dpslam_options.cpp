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
  void open_low(const char* field, double v, double lo, double hi) {  // (lo, hi]
    if (!ok) return;
    if (!(v > lo && v <= hi)) {
      ok = false;
      if (why != nullptr && n > 0U) std::snprintf(why, n, "%s: %g out of range (%g, %g]", field, v, lo, hi);
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

bool DpSlamOptions::validate(char* why, std::size_t n) const {
  if (why != nullptr && n > 0U) why[0] = '\0';
  Checker c{why, n};
  c.integer("filter.particles", particle_count, 1U, capacity::kMaxBottomParticles);
  c.open_low("filter.resample_neff_ratio", resample_neff_ratio, 0.0, 1.0);
  c.real("filter.update_min_travel_m", update_min_travel_m, 0.0, 10.0);
  c.real("filter.update_min_rotation_rad", update_min_rotation_rad, 0.0, 3.14159);
  c.real("motion.alpha_rot_from_rot", motion.alpha_rot_from_rot, 0.0, 10.0);
  c.real("motion.alpha_rot_from_trans", motion.alpha_rot_from_trans, 0.0, 10.0);
  c.real("motion.alpha_trans_from_trans", motion.alpha_trans_from_trans, 0.0, 10.0);
  c.real("motion.alpha_trans_from_rot", motion.alpha_trans_from_rot, 0.0, 10.0);
  c.real("motion.min_sigma_trans_m", motion.min_sigma_trans_m, 0.0, 1.0);
  c.real("motion.min_sigma_rot_rad", motion.min_sigma_rot_rad, 0.0, 1.0);
  c.open_low("observation.sigma_hit_m", beam.sigma_hit_m, 0.0, 5.0);
  c.open_low("observation.window_m", beam.window_m, 0.0, 5.0);
  c.open_low("observation.prior_hits", beam.prior_hits, 0.0, 1000.0);
  c.open_low("observation.prior_misses", beam.prior_misses, 0.0, 1000.0);
  c.open_low("observation.unknown_stop_probability", beam.unknown_stop_probability, 0.0, 0.99);
  c.open_low("observation.floor_likelihood", beam.floor_likelihood, 0.0, 1.0);
  c.integer("observation.weight_beam_stride", beam.weight_beam_stride, 1U, capacity::kMaxBeams);
  c.open_low("observation.max_update_range_m", beam.max_update_range_m, 0.0, 200.0);
  c.real("observation.no_return_free_m", beam.no_return_free_m, 0.0, 200.0);
  c.real("observation.likelihood_temperature", beam.likelihood_temperature, 1.0, 1000.0);
  c.open_low("proposal.linear_step_m", match.linear_step_m, 0.0, 1.0);
  c.open_low("proposal.angular_step_rad", match.angular_step_rad, 0.0, 0.5);
  c.integer("proposal.refinements", match.refinements, 0U, 10U);
  c.integer("proposal.max_iterations", match.max_iterations, 1U, 100U);
  c.integer("proposal.beam_stride", match.beam_stride, 1U, capacity::kMaxBeams);
  c.integer("proposal.min_beams", match.min_beams, 1U, capacity::kMaxBeams);
  c.real("proposal.min_known_fraction", match.min_known_fraction, 0.0, 1.0);
  c.real("proposal.min_mean_log_likelihood", match.min_mean_log_likelihood, -50.0, 0.0);
  c.real("proposal.sample_sigma_xy_m", proposal_sigma_xy_m, 0.0, 1.0);
  c.real("proposal.sample_sigma_rot_rad", proposal_sigma_rot_rad, 0.0, 0.5);
  c.integer("proposal.kind", static_cast<std::uint64_t>(proposal), 0U, 1U);
  c.integer("proposal.weight", static_cast<std::uint64_t>(proposal_weight), 0U, 1U);
  c.real("map.resolution_m", map_resolution_m, 0.005, 1.0);
  c.real("map.width_m", map_width_m, 1.0, 10000.0);
  c.real("map.height_m", map_height_m, 1.0, 10000.0);
  if (c.ok) {
    // The window must cover the Gaussian and at least one cell; the table must hold it.
    c.real("observation.window_m", beam.window_m, map_resolution_m,
           map_resolution_m * static_cast<double>(BeamModel::kMaxGaussEntries) /
                   static_cast<double>(BeamModel::kGaussSubsteps) - 2.0 * map_resolution_m);
    const double cells = (map_width_m / map_resolution_m) * (map_height_m / map_resolution_m);
    c.real("map.width_m*height_m/resolution_m^2 (cells)", cells, 1.0, 4.0e9);
  }
  c.integer("map.tile_capacity", map_tile_capacity, 0U, capacity::kDpMaxTiles);
  c.integer("map.observations_base", map_observations_base, 0U, capacity::kDpMaxObservations);
  c.integer("map.observations_per_particle", map_observations_per_particle, 1U, 100000000U);
  c.integer("capacity.ancestry_nodes_per_particle", ancestry_nodes_per_particle, 1U, capacity::kDpSlamMaxNodesPerParticle);
  c.integer("capacity.path_entries_per_particle", path_entries_per_particle, 1U, capacity::kDpSlamMaxPathEntriesPerParticle);
  if (c.ok) {
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
  }
  return c.ok;
}

std::uint32_t DpSlamOptions::observation_capacity() const {
  return map_observations_base + particle_count * map_observations_per_particle;
}

std::uint32_t DpSlamOptions::tile_capacity() const {
  return map_tile_capacity != 0U ? map_tile_capacity : static_cast<std::uint32_t>(tiles_of_area(*this));
}

}  // namespace sdpslam
