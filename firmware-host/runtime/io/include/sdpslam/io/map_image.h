#pragma once
// Occupancy map outputs: PGM + YAML in the ROS map_server convention, and PNG (libpng),
// optionally with a trajectory drawn on it. All writes are atomic.
#include <cstdint>
#include <string>
#include <vector>

#include "sdpslam/io/trajectory_io.h"

namespace sdpslam::io {

// A rectangular occupancy grid. Cell (col, row) covers world x in
// [origin_x_m + col*res, origin_x_m + (col+1)*res), y likewise with row; row 0 is the
// lowest y (the image is flipped on output so north is up, as map_server expects).
struct OccupancyImage {
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  double resolution_m = 0.05;
  double origin_x_m = 0.0;
  double origin_y_m = 0.0;
  // Probability of occupancy in [0, 1] per cell, row-major from row 0; negative = unknown.
  std::vector<float> occupancy;
};

struct MapWriteOptions {
  double occupied_thresh = 0.65;
  double free_thresh = 0.196;
  bool negate = false;
};

// Writes `<stem>.pgm` and `<stem>.yaml` (image: basename of the pgm, resolution, origin
// [x, y, 0], negate, occupied_thresh, free_thresh). Pixel = (1 - p) * 255, unknown 205.
bool write_map_pgm_yaml(const std::string& stem, const OccupancyImage& map, const MapWriteOptions& options,
                        std::string* error);

// Reading maps back (this writer's, map_server's, nav2's): map_read.h.

// Writes a grey PNG of the map; if `trajectory` is non-empty it is drawn in colour
// (RGB PNG) on top, with the start and end marked.
bool write_map_png(const std::string& path, const OccupancyImage& map, const std::vector<StampedPose>& trajectory,
                   std::string* error);
// The same with `points` (e.g. a particle filter's particles) drawn as orange pixels under
// the start and end marks; an empty trajectory and no points give the grey PNG.
bool write_map_png(const std::string& path, const OccupancyImage& map, const std::vector<StampedPose>& trajectory,
                   const std::vector<Pose2>& points, std::string* error);

}  // namespace sdpslam::io
