#pragma once
// Correlative matching of two 2D point sets over a wide window, for loop closure in
// SDP-SLAM (beyond the paper). ICP (icp2d.h) converges only from a guess inside its
// basin, a few decimetres; after a long loop the chain of submaps can be metres off.
// This searches the whole window exhaustively, in the manner of Olson's correlative
// scan matching ("Real-time correlative scan matching", ICRA 2009) with the two-level
// branch and bound of Hess et al. ("Real-time loop closure in 2D LIDAR SLAM", ICRA
// 2016, §V-C), and leaves the last centimetres to ICP.
//
// Target: a likelihood grid (resolution_m) where each target point spreads
// 255·exp(-d²/2σ²) (σ = kernel_sigma_m, cut at 3σ; the maximum where points meet).
// Score of a pose: the sum of the grid values under the source points it maps (uint8
// values, integer sums: exact and order-independent). Search:
//   - headings: ±window_theta_rad around the guess, in steps that move the source
//     point farthest from the source centroid by one grid cell; rotation is about the
//     source centroid so that heading and translation separate;
//   - coarse pass: translations ±window_xy_m (of the source centroid from where the
//     guess puts it) in steps of coarse_cells cells, scored on
//     the grid max-pooled over coarse_cells × coarse_cells cells: an upper bound of
//     every fine translation of the block;
//   - fine pass: the `candidates` best blocks, best bound first, every cell of the
//     block scored exactly, while a block's bound can still beat max_ambiguity × the
//     best exact score.
// The best pose is judged on its overlap: the source points it puts on the target's grid
// (the target's bounding box grown by the kernel's reach). Two submaps of one building
// overlap in part, and a source point beyond everything the target holds says nothing
// for or against the pose; one inside the box that lands where the target has no wall
// counts against it. The pose is returned if at least min_overlap_points lie on the
// grid, their mean value (score / (255·overlap)) is at least min_score, and no distinct
// peak (farther than distinct_m or distinct_rad from it) scores max_ambiguity × as
// much: a corridor, where any shift along the walls fits as well, is ambiguous, not a
// loop. The search itself ranks poses by their whole sum, so a larger overlap wins.
//
// Memory: two grids of max_grid_side² bytes, 2 × max_points int32 and max_steps²
// uint32 block sums (max_steps = steps_for(the largest window)), carved
// from the arena at init; match() never allocates. Deterministic: det:: trigonometry,
// integer scores, ties broken by a fixed order.
// Cost: (2·window_xy/(coarse·res) + 1)² × headings × source points grid reads for the
// coarse pass (~5 M for ±3 m, ±0.35 rad, 300 points 10 m from their centroid).
#include <cstddef>
#include <cstdint>

#include "sdpslam/core/arena.h"
#include "sdpslam/core/top/icp2d.h"
#include "sdpslam/core/pose2.h"
#include "sdpslam/core/state_io.h"

namespace sdpslam {

struct CorrelativeOptions {
  double resolution_m = 0.1;         // likelihood grid cell, [0.01, 1]
  double kernel_sigma_m = 0.15;      // spread of a target point, [0.5 cell, 2 m]
  std::uint32_t coarse_cells = 4U;   // coarse translation step in cells, 1 .. 16
  double window_xy_m = 3.0;          // ± translation searched, [0, 50]
  double window_theta_rad = 0.35;    // ± heading searched, [0, pi]
  double min_score = 0.45;           // mean value per overlapping source point of the best pose, (0, 1]
  std::uint32_t min_overlap_points = 3U;  // source points the best pose must put on the target's grid, >= 1
  double max_ambiguity = 0.9;        // a distinct peak scoring this × the best: ambiguous, (0, 1]
  double distinct_m = 0.5;           // peaks at least this far apart (or distinct_rad) are distinct
  double distinct_rad = 0.1;
  std::uint32_t candidates = 32U;    // coarse blocks refined, 1 .. kMaxCandidates
  static constexpr std::uint32_t kMaxCandidates = 64U;
  static constexpr std::uint32_t kMaxHeadings = 1024U;
  bool valid() const;
  // Whether two poses this far apart (translation, heading difference) are distinct peaks.
  bool distinct(double dx_m, double dy_m, double dheading_rad) const {
    return dx_m * dx_m + dy_m * dy_m > distinct_m * distinct_m ||
           (dheading_rad < 0.0 ? -dheading_rad : dheading_rad) > distinct_rad;
  }
};

struct CorrelativeResult {
  enum class Status : std::uint8_t {
    kFound,         // transform is the best pose, unambiguous and above min_score
    kWeak,          // the best pose scored below min_score (transform still filled)
    kAmbiguous,     // a distinct peak scored max_ambiguity × the best (transform filled)
    kTooFewPoints,  // fewer than 3 points in a set
    kTooManyPoints, // more source points than init's max_points
    kTooLarge,      // the target's grid would exceed max_grid_side, or the window max_steps
    kInvalidInput,  // null pointer with a count, non-finite coordinate, invalid options
  };
  Status status = Status::kInvalidInput;
  Pose2 transform;            // maps source coordinates into target coordinates
  double score = 0.0;         // mean grid value per overlapping source point at transform, [0, 1]
  double second_score = 0.0;  // best distinct peak seen: its sum over the same overlap count
  std::uint32_t overlap_points = 0U;  // source points transform puts on the target's grid
  std::uint32_t poses_scored = 0U;
  bool found() const { return status == Status::kFound; }
};

class CorrelativeMatcher {
 public:
  // Coarse offsets per axis for a window (init's max_steps must cover the largest).
  static std::uint32_t steps_for(double window_xy_m, double resolution_m, std::uint32_t coarse_cells);
  static std::size_t required_bytes(std::uint32_t max_grid_side, std::uint32_t max_points, std::uint32_t max_steps);
  // False iff the arena is too small or a size is zero.
  bool init(std::uint32_t max_grid_side, std::uint32_t max_points, std::uint32_t max_steps, Arena& arena);

  // Finds the transform mapping `source` onto `target` within the window around `guess`.
  CorrelativeResult match(const Point2* target, std::uint32_t target_count, const Point2* source,
                          std::uint32_t source_count, const Pose2& guess, const CorrelativeOptions& options);

  // The same search in slices, for a bounded time per call: begin() checks the input
  // and builds the target's grids (false: the result, with its status, is ready in
  // result()); advance() runs the coarse pass over up to max_headings more headings
  // (true when all are done); finish() completes the coarse pass if needed and runs the
  // fine pass. `source` must stay valid and unchanged until finish(); the target is
  // not used after begin(). The result is the same as match()'s, bit for bit.
  bool begin(const Point2* target, std::uint32_t target_count, const Point2* source, std::uint32_t source_count,
             const Pose2& guess, const CorrelativeOptions& options);
  bool advance(std::uint32_t max_headings);
  CorrelativeResult finish();
  bool active() const { return active_; }
  const CorrelativeResult& result() const { return result_; }
  // Grid reads of one heading's coarse pass (source points × blocks), for budgets.
  std::uint64_t heading_cost() const;

  // The mutable state, for snapshots (core/state_io.h): what init() did not fix.
  void transfer_state(StateIo& io);

 private:
  struct Candidate {
    std::uint32_t bound;
    std::uint32_t heading;
    std::int32_t dx;  // cells
    std::int32_t dy;
  };
  std::uint32_t score_at(const std::uint8_t* grid, std::int32_t dx, std::int32_t dy, std::uint32_t n) const;
  std::uint32_t on_grid(std::int32_t dx, std::int32_t dy, std::uint32_t n) const;  // of the placed points
  template <class F>
  void visit_on_grid(std::int32_t dx, std::int32_t dy, std::uint32_t n, F&& f) const;
  double heading_of(std::uint32_t k) const;
  void place(std::uint32_t k);  // cells_ = source points at heading k, guess translation

  // The search in progress (begin .. finish).
  CorrelativeOptions options_{};
  CorrelativeResult result_{};
  const Point2* source_ = nullptr;
  std::uint32_t source_count_ = 0U;
  Pose2 guess_{};
  double cx_ = 0.0;   // source centroid
  double cy_ = 0.0;
  double gcx_ = 0.0;  // ... where the guess puts it
  double gcy_ = 0.0;
  double ox_ = 0.0;   // grid origin
  double oy_ = 0.0;
  double step_rad_ = 0.0;
  std::uint32_t half_headings_ = 0U;
  std::uint32_t headings_ = 0U;
  std::uint32_t next_heading_ = 0U;
  std::int32_t nq_ = 0;  // coarse offsets -nq .. nq (× coarse_cells)
  std::uint32_t steps_ = 0U;
  Candidate best_[CorrelativeOptions::kMaxCandidates] = {};
  std::uint32_t nbest_ = 0U;
  bool active_ = false;

  std::uint32_t max_side_ = 0U;
  std::uint32_t max_points_ = 0U;
  std::uint32_t w_ = 0U;
  std::uint32_t h_ = 0U;
  std::uint8_t* fine_ = nullptr;    // likelihood grid, w_ × h_
  std::uint8_t* pooled_ = nullptr;  // fine_ max-pooled over coarse × coarse (towards +x, +y)
  std::int32_t* cells_ = nullptr;   // rotated source points, (x, y) cell pairs
  std::uint32_t* sums_ = nullptr;   // coarse block sums of one heading, max_steps²
  std::size_t max_blocks_ = 0U;
};

}  // namespace sdpslam
