#pragma once
// Scan matcher of the improved proposal of the bottom-level filter (Grisetti, Stachniss &
// Burgard, "Improved Techniques for Grid Mapping with Rao-Blackwellized Particle
// Filters", IEEE T-RO 2007, §IV; GMapping's ScanMatcher::optimize): one particle's pose
// is refined against THAT particle's own map view, read through the DP map, by hill
// climbing on the filter's own observation model (beam_model.h) evaluated on every
// beam_stride-th beam.
//
// The objective is the tempered log-likelihood plus, when a motion prior is given, the
// log of the motion model's density along the direction of travel (motion_model.h,
// MotionPrior): towards the mode of the improved proposal's target p(z | m, x)·p(x | x', u)
// rather than of the likelihood alone, so that where the map does not fix the position
// along the path (a plain corridor) the match keeps the odometry's travel.
//
// Hill climbing: from `initial`, each iteration scores the six neighbours
// (±linear_step along the robot's x and y, ±angular_step in heading) and moves to the
// best one if it beats the current pose; when no neighbour improves (or max_iterations
// moves were made) both steps are halved, `refinements` times. Bounded: at most
// 1 + 6·max_iterations·(refinements + 1) evaluations, each ~(beams / beam_stride) ·
// (2·window / cell) map lookups. No heap, no state, deterministic (det:: math only).
//
// The match fails, and the caller falls back to the odometry proposal, when:
//  - fewer than min_beams return beams are evaluated (kTooFewBeams);
//  - fewer than min_known_fraction of them meet an observed cell at the initial pose:
//    the particle's map is too empty there, e.g. at the start (kMapTooEmpty);
//  - the per-beam mean of the (untempered) log-likelihood at the match is below
//    min_mean_log_likelihood: the scan does not fit the map anywhere near (kScoreTooLow).
#include <cstdint>

#include "sdpslam/core/bottom/beam_model.h"
#include "sdpslam/core/bottom/dp_map.h"
#include "sdpslam/core/bottom/motion_model.h"
#include "sdpslam/core/pose2.h"

namespace sdpslam {

struct ScanMatcherOptions {
  double linear_step_m = 0.05;             // first hill-climbing step in x and y, (0, 1]
  double angular_step_rad = 0.025;         // first step in heading, (0, 0.5]
  std::uint32_t refinements = 3U;          // step halvings after the first level, 0 .. 10
  std::uint32_t max_iterations = 10U;      // moves per level, 1 .. 100
  std::uint32_t beam_stride = 4U;          // every k-th beam scores a candidate, ≥ 1
  std::uint32_t min_beams = 20U;           // fewer evaluated return beams: fail
  double min_known_fraction = 0.5;         // fewer beams meeting observed cells: fail, [0, 1]
  double min_mean_log_likelihood = -3.5;   // per-beam mean (untempered) at the match, [-50, 0]
};

struct ScanMatch {
  enum class Outcome : std::uint8_t { kMatched, kTooFewBeams, kMapTooEmpty, kScoreTooLow };
  Outcome outcome = Outcome::kTooFewBeams;
  Pose2 pose;                        // the match (== initial unless kMatched or kScoreTooLow)
  double log_likelihood = 0.0;       // at `pose`, beam_stride beams, tempered as the model is
  // log of the mean of likelihood × prior over the poses evaluated in the last (finest)
  // level, GMapping's neighbourhood weight (an estimate of the improved proposal's
  // normaliser), same beams and tempering as log_likelihood.
  double neighbourhood_log_likelihood = 0.0;
  std::uint32_t evaluations = 0U;    // observation-model evaluations spent
  std::uint32_t beams = 0U;          // return beams per evaluation
};

// Refines `initial` for `particle`'s map; see the header comment. Options are taken as
// given (DpSlamOptions::validate() range-checks them). `prior` (may be null: the
// likelihood alone) is the motion model's density around the odometry prediction, which
// is normally `initial`. `view` (may be null) remembers the cells read (view_cache.h):
// same result, each distinct cell looked up in the map once.
ScanMatch match_scan(const BeamModel& model, const DpMap& map, NodeId particle, const ScanRays& rays,
                     const Pose2& initial, const ScanMatcherOptions& options,
                     const MotionPrior* prior = nullptr, ViewCache* view = nullptr);

}  // namespace sdpslam
