#pragma once
// 2D point-to-point ICP (Besl & McKay 1992, the paper's [10]) for the top-level matching
// of overlapping submaps (SDP-SLAM §III, Algorithm 1 line 11).
//
// Each iteration pairs every source point, mapped through the current transform, with
// its nearest target point within the rejection distance (exact nearest neighbour: a
// uniform grid hash over the target with cells of nn_cell_m, searched in square rings
// around the query cell until no closer point can exist), then applies the closed-form
// SE(2) least-squares update: centroids of the pairs and the rotation
// atan2(Σ cross, Σ dot) of the centred cross-covariance.
//
// Point-to-point ICP converges to a local minimum, so the initial guess (the composed
// submap poses, Fig. 3 (l)) must lie in its basin. On grid-sampled lines such as
// skeletons of corridors the basin is only a few cells wide (in the tests, ~7 cm and
// ~1° on a 5 cm grid; from 12 cm off it settles 9 cm away), and two sets made of the
// very same regular samples can lock onto a pairing shifted by one sample.
//
// Direction information (direction_information(), after a match): how well a pairing
// fixes each direction of the translation. Point-to-point residuals hide it: along a
// straight wall a source point slides between target samples at little cost, so a match
// in a corridor is weak along the corridor however small its error. For every pair the
// target point's local line is fitted (principal axes of the target points within a
// radius); a line-like neighbourhood contributes n nᵀ (n its unit normal: the
// point-to-line constraint of Chen & Medioni 1992, whose sum is the translation block of
// ICP's Hessian in Censi, ICRA 2007), any other ½ I (a corner or a lone point fixes both
// directions). The mean is a symmetric 2×2 matrix of trace 1 in target coordinates:
// eigenvalues ½ and ½ for a well-constrained match, near 1 and 0 for a corridor.
//
// The result carries the paper's "ICP nearest neighbour error": the mean distance, in
// metres, between matched pairs after convergence (one final pairing pass with the
// final transform). No overlap is not a good match: when fewer than min_pairs pairs are
// found the status says so and mean_nn_error_m is +infinity.
//
// Memory: all state lives inside the Icp2d object (about 90 KiB at the default
// capacities: hash heads, chain links, pair list); put it in static storage or inside a
// larger fixed object, not on a small stack. match() never allocates.
// Determinism: IEEE +,-,*,/, sqrt and det::atan2/sin/cos only, fixed iteration orders,
// nearest-neighbour ties go to the lowest target index: same input → same bits.
// Cost per iteration: O(source points × points in the rings searched); a source point
// without a neighbour costs (2·ceil(reject/nn_cell_m)+1)² cell probes.
#include <cstddef>
#include <cstdint>

#include "sdpslam/core/capacities.h"
#include "sdpslam/core/pose2.h"
#include "sdpslam/core/state_io.h"

namespace sdpslam {

struct Point2 {
  double x_m = 0.0;
  double y_m = 0.0;
};

struct Icp2dOptions {
  std::uint32_t max_iterations = 50U;
  // Pairs farther apart than this are rejected.
  double max_correspondence_m = 0.5;
  // Side of the nearest-neighbour hash cells: about the spacing of the target points
  // (cost per query grows with the points per cell and with the rings searched).
  double nn_cell_m = 0.1;
  // Optional shrinking (trimmed ICP in the manner of Zhang 1994): after each iteration
  // the rejection distance is multiplied by shrink_factor (in (0, 1]) but never drops
  // below min_correspondence_m. 1.0 disables it.
  double shrink_factor = 1.0;
  double min_correspondence_m = 0.05;
  // Converged when one iteration moves the estimate by less than both of these.
  double translation_epsilon_m = 1.0e-6;
  double rotation_epsilon_rad = 1.0e-6;
  // Fewer matched pairs than this (in any iteration or the final pass) means the sets do
  // not overlap enough to say anything. At least 2 (SE(2) needs two points).
  std::uint32_t min_pairs = 10U;

  // True iff every field is in range: max_iterations >= 1, 0 < min_correspondence_m <=
  // max_correspondence_m <= 1e3, 1e-3 <= nn_cell_m <= 1e3 (so that hash cell indices fit
  // 32 bits) with max_correspondence_m / nn_cell_m <= 1000 (bounded ring search),
  // 0 < shrink_factor <= 1, finite epsilons >= 0, min_pairs >= 2.
  bool valid() const;
};

struct Icp2dResult {
  enum class Status : std::uint8_t {
    kConverged,            // estimate stopped moving; all fields meaningful
    kMaxIterations,        // ran out of iterations; transform and error still meaningful
    kInsufficientOverlap,  // fewer than min_pairs pairs at some iteration: no match
    kTooFewPoints,         // a set has fewer than min_pairs points
    kTooManyPoints,        // a set has more than capacity::kMaxIcpPoints points
    kInvalidInput,         // null pointer with a count, or a non-finite / huge coordinate
    kInvalidOptions,       // options.valid() is false
  };
  Status status = Status::kInvalidOptions;
  // Maps source coordinates into target coordinates (target_point = transform ⊕ source).
  Pose2 transform;
  std::uint32_t iterations = 0U;
  // Pairs within the final rejection distance in the final pass.
  std::uint32_t matched_pairs = 0U;
  // matched_pairs / source count (0 when nothing was matched).
  double overlap_fraction = 0.0;
  // Mean pair distance after convergence (m); +infinity unless status is kConverged or
  // kMaxIterations.
  double mean_nn_error_m = 0.0;
  // Root-mean-square pair distance in the same pass (m); +infinity likewise.
  double rms_nn_error_m = 0.0;
  bool converged = false;

  // True iff the transform and errors mean something (kConverged or kMaxIterations).
  bool usable() const { return status == Status::kConverged || status == Status::kMaxIterations; }
};

const char* to_string(Icp2dResult::Status status);

// Mean of the pairs' constraint directions (see the header), target coordinates:
// [xx xy; xy yy], trace 1 when pairs > 0.
struct Icp2dInformation {
  double xx = 0.5;
  double xy = 0.0;
  double yy = 0.5;
  std::uint32_t pairs = 0U;       // source points with a target point within reach
  std::uint32_t line_pairs = 0U;  // ... whose target neighbourhood was line-like
};

class Icp2d {
 public:
  Icp2d() = default;
  Icp2d(const Icp2d&) = delete;
  Icp2d& operator=(const Icp2d&) = delete;

  // Aligns `source` onto `target`, starting from `initial_guess` (source → target).
  // Both arrays are read only during the call and are not retained. Coordinates must be
  // finite with |x|, |y| < 1e6 m. Failure conditions are exactly those of Status.
  Icp2dResult match(const Point2* target, std::size_t target_count, const Point2* source,
                    std::size_t source_count, const Pose2& initial_guess, const Icp2dOptions& options);

  // Direction information of the pairing of `source`, mapped through `transform`, onto
  // `target` (each source point with its nearest target point within max_correspondence_m
  // of `options`); target neighbourhoods are fitted within normal_radius_m. False (and
  // *out untouched) when an input is invalid as for match(), when normal_radius_m is not
  // in (0, 100 × nn_cell_m], or when no pair is found. Cost: one pairing pass plus one
  // neighbourhood search per distinct paired target point.
  bool direction_information(const Point2* target, std::size_t target_count, const Point2* source,
                             std::size_t source_count, const Pose2& transform, const Icp2dOptions& options,
                             double normal_radius_m, Icp2dInformation* out);

  // Diagnostics over the object's lifetime (never decrease).
  std::uint32_t match_count() const { return match_count_; }
  std::uint32_t failed_match_count() const { return failed_match_count_; }

  // The mutable state, for snapshots (core/state_io.h): what init() did not fix.
  void transfer_state(StateIo& io);

 private:
  static constexpr std::uint32_t kNone = 0xFFFFFFFFU;

  struct Pair {
    std::uint32_t source = 0U;
    std::uint32_t target = 0U;
  };

  void build_index(const Point2* target, std::uint32_t count, double cell_m);
  // Nearest target point to (x, y) within sqrt(max_d2); kNone if none. Writes d2.
  std::uint32_t nearest(const Point2* target, double x_m, double y_m, double max_d, double& out_d2) const;
  void scan_cell(const Point2* target, std::int64_t qx, std::int64_t qy, double x_m, double y_m, std::uint32_t& best,
                 double& best_d2) const;
  std::uint32_t bucket_of(std::int64_t cx, std::int64_t cy) const;
  // Unit normal of the target's local line at target point i (see the header), cached
  // in normal_state_ for one direction_information() call; false when the neighbourhood
  // is not line-like.
  bool line_normal(const Point2* target, std::uint32_t i, double radius_m, double& nx, double& ny);

  std::uint32_t heads_[capacity::kIcpHashBuckets] = {};
  std::uint32_t next_[capacity::kMaxIcpPoints] = {};
  // Cell coordinates of each target point (so chains can skip hash collisions cheaply).
  std::int32_t cell_x_[capacity::kMaxIcpPoints] = {};
  std::int32_t cell_y_[capacity::kMaxIcpPoints] = {};
  Pair pairs_[capacity::kMaxIcpPoints] = {};
  // Per target point, during direction_information(): 0 = not fitted yet, 1 = line,
  // 2 = not a line.
  std::uint8_t normal_state_[capacity::kMaxIcpPoints] = {};
  double normal_x_[capacity::kMaxIcpPoints] = {};
  double normal_y_[capacity::kMaxIcpPoints] = {};
  double cell_m_ = 1.0;
  std::uint32_t match_count_ = 0U;
  std::uint32_t failed_match_count_ = 0U;
};

}  // namespace sdpslam
