#pragma once
// Occupancy map outputs: PGM + YAML in the ROS map_server convention, and PNG (libpng),
// optionally with a trajectory drawn on it. All writes are atomic.
#include <cstdint>
#include <istream>
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

// Reads a map written in the map_server convention: the YAML at `yaml_path` (image,
// resolution, origin, negate, occupied_thresh, free_thresh; other keys ignored) and the
// binary PGM (P5, maxval <= 255) it names, relative to the YAML's folder. A pixel's
// occupancy p is (maxval - v) / maxval (v / maxval with negate); as map_server reads it,
// p > occupied_thresh is occupied, p < free_thresh free, anything else unknown (-1). A
// known cell's float keeps its class: occupancy > occupied_thresh or < free_thresh
// compared in double, whatever the thresholds' digits. `thresholds`
// (may be null) gets the YAML's. False, with "file[:line]: why" in `error`, on a missing
// file or key, a bad value, a short image or a pixel above maxval.
bool read_map_pgm_yaml(const std::string& yaml_path, OccupancyImage* map, MapWriteOptions* thresholds,
                       std::string* error);

// The two halves of read_map_pgm_yaml, without file access.
// What the YAML says: the image as written (relative to the YAML's folder unless it starts
// with '/'), the cell size, the origin, and negate / occupied_thresh / free_thresh.
struct MapYaml {
  std::string image;
  double resolution_m = 0.0;
  double origin_x_m = 0.0;
  double origin_y_m = 0.0;
  MapWriteOptions thresholds;
};
// Parses YAML text (`name` stands for the file in messages). False, with
// "name[:line]: why", on a missing key or a bad value, as read_map_pgm_yaml.
bool parse_map_yaml(std::istream& yaml, const std::string& name, MapYaml* out, std::string* error);
// Decodes the bytes of a binary PGM with the geometry and thresholds of `yaml`. False,
// with "name: why", on a bad header, a short image or a pixel above maxval; *map is then
// untouched.
bool decode_map_pgm(const std::string& pgm, const std::string& name, const MapYaml& yaml, OccupancyImage* map,
                    std::string* error);

// Writes a grey PNG of the map; if `trajectory` is non-empty it is drawn in colour
// (RGB PNG) on top, with the start and end marked.
bool write_map_png(const std::string& path, const OccupancyImage& map, const std::vector<StampedPose>& trajectory,
                   std::string* error);
// The same with `points` (e.g. a particle filter's particles) drawn as orange pixels under
// the start and end marks; an empty trajectory and no points give the grey PNG.
bool write_map_png(const std::string& path, const OccupancyImage& map, const std::vector<StampedPose>& trajectory,
                   const std::vector<Pose2>& points, std::string* error);

}  // namespace sdpslam::io
