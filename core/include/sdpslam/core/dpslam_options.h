#pragma once
// Options of the bottom-level DP-SLAM filter (paper §II-A, Algorithm 1 line 3), validated
// once (Cartographer style): validate() range-checks every field and names the first
// bad one with its allowed range. Every field has a key in firmware-host/runtime/slam/default.ini.
#include <cstddef>
#include <cstdint>

#include "sdpslam/core/bottom/beam_model.h"
#include "sdpslam/core/capacities.h"
#include "sdpslam/core/option_table.h"
#include "sdpslam/core/bottom/motion_model.h"
#include "sdpslam/core/bottom/scan_matcher.h"

namespace sdpslam {

struct DpSlamOptions {
  // [filter]
  std::uint32_t particle_count = 30;        // 1 .. capacity::kMaxBottomParticles
  double resample_neff_ratio = 0.5;         // resample iff N_eff < ratio · N; (0, 1]
  double update_min_travel_m = 0.2;         // process a scan only after this much travel
  double update_min_rotation_rad = 0.15;    // ... or this much rotation
  // [motion]
  MotionModelOptions motion;
  // [observation]
  BeamModelOptions beam;
  // [proposal]: how a particle's new pose is drawn.
  //  kOdometry  — the paper's: sample the odometry motion model (motion_model.h).
  //  kScanMatch — the improved proposal (Grisetti et al. 2007, §IV): from the
  //    odometry-predicted pose, hill-climb the likelihood against the particle's own map
  //    view times the motion model's density along the path (scan_matcher.h,
  //    MotionPrior in motion_model.h), then sample N(match, diag(sample_sigma_xy², ·, sample_sigma_rot²))
  //    and weight by the likelihood at the match (weighting below). A failed match falls
  //    back to the odometry proposal for that particle (counted in DpSlamStats).
  enum class Proposal : std::uint8_t { kOdometry, kScanMatch };
  enum class ProposalWeight : std::uint8_t {
    kMatch,          // observation model at the matched pose (weight_beam_stride beams)
    kNeighbourhood,  // mean likelihood over the finest level's evaluated poses (GMapping)
  };
  Proposal proposal = Proposal::kOdometry;
  ProposalWeight proposal_weight = ProposalWeight::kMatch;
  ScanMatcherOptions match;
  double proposal_sigma_xy_m = 0.01;        // noise around the match, [0, 1]
  double proposal_sigma_rot_rad = 0.005;    // [0, 0.5]
  // [map]: a fixed area centred on the first pose
  double map_resolution_m = 0.05;
  double map_width_m = 120.0;
  double map_height_m = 120.0;
  std::uint32_t map_tile_capacity = 0U;     // 0 = every tile of the area
  std::uint32_t map_observations_base = 2000000U;        // shared (old, committed) map
  std::uint32_t map_observations_per_particle = 20000U;  // each branch's recent cells
  // DpMap's (owner, cell) index: on for large particle counts (DP-SLAM at hundreds of
  // particles), off where memory matters more (SDP-SLAM's bottom level). Same results.
  bool map_owner_cell_index = true;
  // The map as a torus (DpMap::Options::wrap) of at least width × height and at least
  // 8 × (beam.max_update_range_m + 2 cells) on each side: no place is out of the map,
  // provided each lineage keeps its updates within a square of half the window, e.g. its
  // path within window/8 of its start. Set by SDP-SLAM, whose segments bound that
  // (sdp_slam.h); plain DP-SLAM has one lineage for the whole run and keeps the bounded
  // area. No key: it follows from the mode.
  bool map_wrap = false;
  // [capacity]
  std::uint32_t ancestry_nodes_per_particle = capacity::kAncestryNodesPerParticle;
  std::uint32_t path_entries_per_particle = 64U;         // uncommitted poses per particle
  // Extra pool room for callers that keep finished segments alive: SDP-SLAM anchors the
  // leaves of every live segment (Algorithm 1 line 5), whose nodes and poses stay in the
  // tree until the segment is made permanent. 0 for plain DP-SLAM.
  std::uint32_t extra_ancestry_nodes = 0U;
  std::uint32_t extra_path_entries = 0U;

  // True iff every field is in range; otherwise writes "field: value out of range
  // [lo, hi]" (truncated to n bytes, NUL-terminated) into `why` (may be null).
  // Every key of the [filter] [motion] [observation] [proposal] [map] [capacity]
  // sections: its field, range, unit and doc.
  static OptionTable<DpSlamOptions> table();
  // True iff every field is in its table's range and the fields agree; otherwise writes
  // "section.key: ..." into `why` (may be null).
  bool validate(char* why, std::size_t n) const;

  // Derived capacities (valid options only).
  std::uint32_t node_capacity() const { return particle_count * ancestry_nodes_per_particle + extra_ancestry_nodes; }
  std::uint32_t path_entry_capacity() const { return particle_count * path_entries_per_particle + extra_path_entries; }
  std::uint32_t observation_capacity() const;
  std::uint32_t tile_capacity() const;
};

}  // namespace sdpslam
