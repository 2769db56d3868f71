#pragma once
// The top-level particle set of SDP-SLAM (paper §III, Algorithm 1 lines 9-12).
//
// T particles, each a combination of submaps: one PGS node choice per live level
// (segment_graph.h). A particle's error is the ICP nearest-neighbour error of its last
// evaluation (lower is better; the caller measures it and sets it here); one never
// evaluated ranks at prior_error_m, as never-sampled PGS edges do.
//  - rank(): the particles by error, stable (ties keep index order), so every later
//    step is deterministic.
//  - resample_and_diversify(): elitism. The best elite_fraction are kept unchanged; the
//    worst worst_fraction become copies of the elite (choices and error); every particle
//    but the elite then re-samples diversify_levels of its choices, each at a live level
//    drawn uniformly, from the PGS by conditional sampling p(b | a) given its choice at
//    the level before (the oldest live level conditional on the permanent anchor).
//    SegSLAM's topology (§IV) re-samples only the last segslam_window levels, and older
//    choices follow the best particle's.
//  - extend_to_level(): at a segmentation every particle gets a choice for the new
//    level: the best follow_best_fraction (rounded up) take the bottom filter's best
//    submap, the others sample it from the PGS given their choice before it (the bottom
//    filter's best when the PGS cannot sample).
// Randomness comes from the caller's Rng, so the engine's sequence of draws is one.
//
// Memory: init() carves the arrays from an Arena (required_bytes()); nothing else
// allocates. The arrays are all the state: a snapshot of the arena region holds it.
#include <cstddef>
#include <cstdint>

#include "sdpslam/core/arena.h"
#include "sdpslam/core/rng.h"
#include "sdpslam/core/sdp_options.h"
#include "top/segment_graph.h"

namespace sdpslam {

struct TopParticleOptions {
  std::uint32_t particles = 0U;   // T, 1 .. capacity::kMaxTopParticles
  std::uint32_t max_levels = 0U;  // live PGS levels, 2 .. capacity::kMaxPgsLevels
  TopologyMode topology = TopologyMode::kSdp;
  std::uint32_t segslam_window = 0U;  // >= 1
  double elite_fraction = 0.0;        // [0, 1], elite + worst <= 1
  double worst_fraction = 0.0;        // [0, 1]
  std::uint32_t diversify_levels = 0U;  // >= 1
  double follow_best_fraction = 0.0;  // [0, 1]
  double prior_error_m = 0.0;         // > 0, finite

  // The [sdp] options these come from (SdpOptions::validate checks their ranges).
  static TopParticleOptions from(const SdpOptions& sdp);
  bool valid() const;
};

class TopParticles {
 public:
  TopParticles() = default;
  TopParticles(const TopParticles&) = delete;
  TopParticles& operator=(const TopParticles&) = delete;

  // Arena bytes init() carves (0 iff the options are invalid).
  static std::size_t required_bytes(const TopParticleOptions& options);
  // False iff the options are invalid or the arena is too small. Every choice starts at
  // node 0, no particle has an error.
  bool init(const TopParticleOptions& options, Arena& arena);
  const TopParticleOptions& options() const { return options_; }
  std::uint32_t size() const { return options_.particles; }

  std::uint16_t choice(std::uint32_t particle, std::uint32_t level) const {
    return choices_[particle * options_.max_levels + level % options_.max_levels];
  }
  void set_choice(std::uint32_t particle, std::uint32_t level, std::uint32_t node) {
    choices_[particle * options_.max_levels + level % options_.max_levels] = static_cast<std::uint16_t>(node);
  }

  void set_error(std::uint32_t particle, double error_m) {
    error_[particle] = error_m;
    has_error_[particle] = 1U;
  }
  bool has_error(std::uint32_t particle) const { return has_error_[particle] != 0U; }
  // The error a particle ranks by.
  double key(std::uint32_t particle) const {
    return has_error_[particle] != 0U ? error_[particle] : options_.prior_error_m;
  }
  // Mean and standard deviation of the errors of the particles that have one, and their
  // number (each pointer may be null).
  void error_summary(double* mean_m, double* std_m, std::uint32_t* count) const;

  // Ranks the particles; returns the best.
  std::uint32_t rank();
  // The particle at rank r of the last rank() (0 = best).
  std::uint32_t ranked(std::uint32_t r) const { return order_[r]; }

  // Elitism and diversification over the graph's live levels (nothing if none).
  void resample_and_diversify(const SegmentGraph& graph, Rng& rng);
  // Choices for `level` (the graph's newest live level); `bottom_best` is the bottom
  // filter's best particle's node in it.
  void extend_to_level(std::uint32_t level, std::uint32_t bottom_best, const SegmentGraph& graph, Rng& rng);

 private:
  TopParticleOptions options_{};
  std::uint16_t* choices_ = nullptr;   // T × max_levels, by level slot (level % max_levels)
  double* error_ = nullptr;            // T
  std::uint8_t* has_error_ = nullptr;  // T
  std::uint32_t* order_ = nullptr;     // T, rank → particle
};

}  // namespace sdpslam
