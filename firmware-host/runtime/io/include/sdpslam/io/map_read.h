#pragma once
// Reading an occupancy map saved in the ROS map_server convention: what this project's
// writer (map_image.h), ROS's map_saver and nav2's map_saver_cli write.
//
// The YAML (yaml-cpp) is read as nav2_map_server's map_io.cpp reads it
// (loadMapYaml / loadMapFromFile in ros-navigation/navigation2; wiki.ros.org/map_server,
// "YAML format"):
//   image            the image file, relative to the YAML's folder unless absolute
//   resolution       metres per cell (> 0)
//   origin           [x, y, yaw] of the lower-left pixel; a yaw other than 0 is refused
//                    (nothing here rotates maps)
//   negate           0, 1, false or true (default 0)
//   occupied_thresh  default 0.65
//   free_thresh      default 0.196 (0 <= free_thresh < occupied_thresh <= 1)
//   mode             trinary (default), scale or raw
// Strings may be quoted or not; other keys are ignored.
//
// The image is a binary PGM (P5, maxval <= 255) or a PNG (libpng; grey, grey+alpha, RGB,
// RGBA or palette, 8 or 16 bits). A pixel's shade s in [0, 1] is the mean of its red,
// green and blue over the maximum value (a grey pixel counts as three equal channels),
// and its occupancy p is 1 - s, or s with negate. Then, per mode:
//   trinary  p > occupied_thresh: occupied; p < free_thresh: free; anything else unknown.
//            The alpha of a PNG with one is averaged in with the colours, as map_io does.
//   scale    a pixel that is not fully opaque is unknown; otherwise occupied and free as
//            trinary, and a p between the thresholds is kept (map_server writes it as a
//            grey level between free and occupied).
//   raw      the pixel value round(255 s) is the occupancy in percent: 0..100 gives
//            p = value / 100, any other value unknown; negate does not apply.
// OccupancyImage keeps p for every known cell and -1 for unknown. The class of a cell is
// decided in double and the float kept stays in it (p > occupied_thresh, p < free_thresh or
// between, compared in double), whatever the thresholds' digits, so a reader applying the
// same rule to the float (eval::MapAgreement, the localizer) classes it as map_server does.
#include <istream>
#include <string>

#include "sdpslam/io/map_image.h"

namespace sdpslam::io {

enum class MapMode { kTrinary, kScale, kRaw };

// What the YAML says.
struct MapYaml {
  std::string image;  // as written: relative to the YAML's folder unless it starts with '/'
  double resolution_m = 0.0;
  double origin_x_m = 0.0;
  double origin_y_m = 0.0;
  MapMode mode = MapMode::kTrinary;
  MapWriteOptions thresholds;  // negate, occupied_thresh, free_thresh
};

// Parses YAML text; `name` stands for the file in messages. False, with "name:line: why"
// (or "name: why" for a missing key), on text that is not YAML, a document that is not a
// mapping, a missing image / resolution / origin, or a bad value; *out is then untouched.
bool parse_map_yaml(std::istream& yaml, const std::string& name, MapYaml* out, std::string* error);

// Decodes the bytes of a PGM or PNG image with the geometry, mode and thresholds of `yaml`.
// False, with "name: why", on an image that is neither, a bad header, truncated or corrupt
// data, a PGM pixel above maxval, more cells than the file could hold (a PNG cannot
// inflate beyond 1032:1, zlib's limit, and a pixel takes at least one bit) or than memory
// can; *map is then untouched.
bool decode_map_image(const std::string& bytes, const std::string& name, const MapYaml& yaml, OccupancyImage* map,
                      std::string* error);

// Reads the YAML at `yaml_path` and the image it names. `thresholds` (may be null) gets the
// YAML's negate and thresholds, `yaml` (may be null) all of it. False, with "file[:line]:
// why" in `error`, when either file cannot be opened or is refused as above.
bool read_map_yaml(const std::string& yaml_path, OccupancyImage* map, MapWriteOptions* thresholds,
                   std::string* error, MapYaml* yaml = nullptr);

}  // namespace sdpslam::io
