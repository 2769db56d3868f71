#pragma once
// Ray casting against a World's wall segments, accelerated by a uniform grid: each cell
// lists the segments whose bounding box touches it, and a ray visits cells in order
// (Amanatides & Woo, "A fast voxel traversal algorithm", 1987), stopping at the first
// cell that contains a hit nearer than the cell's exit. Cost per ray: the cells crossed
// up to the hit (or max range) times the segments per cell.
//
// Hits are exact up to floating point: a ray hits a segment iff it crosses it at a
// distance t >= 0 with the crossing inside the segment's closed extent (end points and
// corners included, with a 1e-12 relative tolerance on the segment parameter). A ray
// parallel to a segment does not hit it (grazing along a wall is not a return).
// The caster copies the segments; the World may be destroyed afterwards.
#include <cstdint>
#include <limits>
#include <vector>

#include "sdpslam/sim/world.h"

namespace sdpslam::sim {

class RayCaster {
 public:
  // `cell_m` <= 0 chooses ~0.5 m, enlarged if needed to keep the grid under ~4M cells.
  explicit RayCaster(const World& world, double cell_m = 0.0);

  // Distance along the ray from (x, y) in direction `angle_rad` to the first wall, or
  // +infinity if none is hit within `max_range_m`.
  double cast(double x_m, double y_m, double angle_rad,
              double max_range_m = std::numeric_limits<double>::infinity()) const;

  // The same answer by testing every segment (reference for tests; O(segments)).
  double cast_brute_force(double x_m, double y_m, double angle_rad,
                          double max_range_m = std::numeric_limits<double>::infinity()) const;

  std::uint32_t grid_width() const { return nx_; }
  std::uint32_t grid_height() const { return ny_; }
  double cell_m() const { return cell_m_; }

 private:
  std::vector<Segment> segments_;
  double cell_m_ = 0.5;
  double min_x_ = 0.0;
  double min_y_ = 0.0;
  std::uint32_t nx_ = 0;
  std::uint32_t ny_ = 0;
  // CSR: segments of cell c are cell_items_[cell_start_[c] .. cell_start_[c+1]).
  std::vector<std::uint32_t> cell_start_;
  std::vector<std::uint32_t> cell_items_;
};

}  // namespace sdpslam::sim
