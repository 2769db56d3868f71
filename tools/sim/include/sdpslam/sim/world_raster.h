#pragma once
// The ground-truth occupancy map of a World, for pictures and for map evaluation.
#include "sdpslam/io/map_image.h"
#include "sdpslam/sim/world.h"

namespace sdpslam::sim {

struct RasterOptions {
  double resolution_m = 0.05;
  double margin_m = 1.0;  // added around the walls' bounding box
  // When true, only cells 4-connected to (free_seed_x_m, free_seed_y_m) without crossing
  // a wall are free (0); the rest is unknown (-1): the space the robot can see. When
  // false, every non-wall cell is free.
  bool flood_from_seed = true;
  double free_seed_x_m = 0.0;
  double free_seed_y_m = 0.0;
};

// Cells crossed by a wall are occupied (1). Walls are sampled every resolution/8, which
// keeps every wall 4-connected-tight (a 4-connected flood cannot leak through it).
// Returns an empty image (width 0) iff the world has no segments or resolution <= 0.
io::OccupancyImage rasterize_world(const World& world, const RasterOptions& options);

}  // namespace sdpslam::sim
