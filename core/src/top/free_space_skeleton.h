#pragma once
// Points from the middle of free space of an occupancy-grid patch: the medial axis
// (Voronoi ridge) of the free space, which SDP-SLAM matches with ICP instead of obstacle
// points (paper §III, Fig. 2 (b), following Saeedi et al. [11]); walls seen slightly
// wrong then no longer pair with the wrong wall.
//
// Method:
//  1. Exact Euclidean feature transform (Felzenszwalb & Huttenlocher 2012, "Distance
//     transforms of sampled functions", two separable 1D lower-envelope passes, kept
//     with the arg-min so every cell knows its nearest obstacle cell). Obstacles are
//     occupied cells, and unknown cells when unknown_is_obstacle (default: free space
//     is bounded by what the submap knows). Cells outside the patch are obstacles only
//     when patch_border_is_obstacle (default off: the patch edge is a cut, not a wall,
//     so a corridor crossing the patch keeps a straight centre line to the edge).
//  2. Ridge cells by the integer medial axis rule (Hesselink & Roerdink 2008, IEEE
//     PAMI 30(12)): for each pair of 4-neighbours p, q whose nearest obstacles fp, fq
//     differ, the medial axis crosses between them; the one of p, q nearer to the
//     bisector of fp, fq is marked (both on a tie). Pruning keeps the ridge where it
//     separates two genuinely opposite walls: the angle subtended at the cell by fp and
//     fq must be at least min_ridge_angle_rad (default 120°: a corridor's centre line is
//     180°, the spurious branch into a convex corner of free space is 90°), and the
//     cell's clearance must be at least min_clearance_m.
//  3. Ridge cells are emitted as world points (cell centres) in raster order (row 0
//     first, x ascending), subsampled to at most max_points by a fixed stride.
//
// Memory: init() carves the scratch buffers for patches up to max_width × max_height
// from an Arena (about 9 bytes per cell plus 24 bytes per cell of the longer side);
// extract() never allocates. Cost: O(width × height) per call.
// Determinism: integer arithmetic for distances and the ridge rule; doubles only for the
// envelope intersections (IEEE +,-,*,/) and sqrt. Same patch → same points.
#include <cstddef>
#include <cstdint>

#include "sdpslam/core/arena.h"
#include "sdpslam/core/capacities.h"
#include "sdpslam/core/state_io.h"
#include "sdpslam/core/top/icp2d.h"  // Point2

namespace sdpslam {

enum class CellState : std::uint8_t { kUnknown = 0, kFree = 1, kOccupied = 2 };

// A read-only window onto an occupancy grid. Cell (x, y) covers world
// [origin_x_m + x·res, origin_x_m + (x+1)·res) × [origin_y_m + y·res, ...).
// The state of a cell comes from `cells[y * row_stride + x]` when cells is set,
// otherwise from classify(context, x, y) (e.g. a DP-map query for one particle).
struct GridPatchView {
  std::uint32_t width = 0U;
  std::uint32_t height = 0U;
  double resolution_m = 0.05;
  double origin_x_m = 0.0;
  double origin_y_m = 0.0;
  const CellState* cells = nullptr;
  std::size_t row_stride = 0U;  // 0 means width
  CellState (*classify)(const void* context, std::uint32_t x, std::uint32_t y) = nullptr;
  const void* context = nullptr;
};

struct SkeletonOptions {
  // Ridge cells closer than this to the nearest obstacle are dropped.
  double min_clearance_m = 0.1;
  // Smallest angle at the cell between the directions to the two nearest obstacles
  // that make the ridge, in (0, pi].
  double min_ridge_angle_rad = 2.0943951023931957;  // 120 degrees
  // At most this many points are produced; more ridge cells are subsampled by stride.
  std::uint32_t max_points = 1024U;
  bool unknown_is_obstacle = true;
  bool patch_border_is_obstacle = false;

  // True iff min_clearance_m >= 0 (finite), 0 < min_ridge_angle_rad <= pi, max_points >= 1.
  bool valid() const;
};

struct SkeletonResult {
  enum class Status : std::uint8_t {
    kOk,               // points written (possibly none: no free space / no obstacles)
    kNotInitialised,   // init() has not succeeded
    kPatchTooLarge,    // width or height exceeds what init() provisioned
    kInvalidPatch,     // zero size, no cell source, resolution not in (0, 1e3] m, origin not finite
    kInvalidOptions,   // options.valid() is false
  };
  Status status = Status::kNotInitialised;
  std::uint32_t ridge_cell_count = 0U;   // ridge cells found before subsampling
  std::uint32_t stride = 1U;             // every stride-th ridge cell (raster order) kept
  std::uint32_t point_count = 0U;        // points written to the output array
  std::uint32_t truncated_count = 0U;    // points the output array had no room for
  std::uint32_t free_cell_count = 0U;
  std::uint32_t obstacle_cell_count = 0U;
};

const char* to_string(SkeletonResult::Status status);

class FreeSpaceSkeleton {
 public:
  FreeSpaceSkeleton() = default;
  FreeSpaceSkeleton(const FreeSpaceSkeleton&) = delete;
  FreeSpaceSkeleton& operator=(const FreeSpaceSkeleton&) = delete;

  // Bytes init() takes from the arena for patches up to max_width × max_height
  // (alignment padding included).
  static std::size_t required_bytes(std::uint32_t max_width, std::uint32_t max_height);

  // Returns false iff a side is 0 or above capacity::kMaxSkeletonPatchSide or the arena
  // has too little room (the object then stays uninitialised). Call once.
  bool init(Arena& arena, std::uint32_t max_width, std::uint32_t max_height);
  bool initialised() const { return sq_dist_ != nullptr; }

  // Writes up to out_capacity points (world coordinates of ridge cell centres) to `out`.
  // Points that do not fit are counted in truncated_count and overflow_count(), never
  // written. `out` may be null iff out_capacity is 0 (count-only).
  SkeletonResult extract(const GridPatchView& patch, const SkeletonOptions& options, Point2* out,
                         std::size_t out_capacity);

  // Clearance (distance to the nearest obstacle, m) of cell (x, y) as computed by the
  // last successful extract(); +infinity when the patch had no obstacle, -1 when (x, y)
  // is outside that patch. For diagnostics and tests.
  double clearance_m(std::uint32_t x, std::uint32_t y) const;

  // Diagnostics (never decrease).
  std::uint32_t extract_count() const { return extract_count_; }
  std::uint32_t failed_extract_count() const { return failed_extract_count_; }
  std::uint32_t overflow_count() const { return overflow_count_; }

  // The mutable state, for snapshots (core/state_io.h): what init() did not fix.
  void transfer_state(StateIo& io);

 private:
  static constexpr std::uint32_t kNoFeature = 0xFFFFFFFFU;

  CellState state_at(const GridPatchView& patch, std::uint32_t x, std::uint32_t y) const;

  std::uint32_t max_width_ = 0U;
  std::uint32_t max_height_ = 0U;
  // Per cell: squared distance (cells²) to the nearest obstacle and that obstacle's
  // cell index (y·width + x), kNoFeature if none; ridge mark / cell class.
  std::uint32_t* sq_dist_ = nullptr;
  std::uint32_t* feature_ = nullptr;
  std::uint8_t* mark_ = nullptr;
  // Per line of the longer side: the 1D lower-envelope scratch.
  double* line_f_ = nullptr;
  double* line_z_ = nullptr;
  std::uint32_t* line_v_ = nullptr;
  std::uint32_t* line_feature_ = nullptr;
  // Geometry of the last successful extract (for clearance_m()).
  std::uint32_t last_width_ = 0U;
  std::uint32_t last_height_ = 0U;
  double last_resolution_m_ = 0.0;
  bool last_has_obstacle_ = false;
  std::uint32_t extract_count_ = 0U;
  std::uint32_t failed_extract_count_ = 0U;
  std::uint32_t overflow_count_ = 0U;
};

}  // namespace sdpslam
