// libFuzzer: the map reader of `sdpslam evaluate --map` and `sdpslam localize`
// (io::read_map_yaml, map_read.h) through its two halves: the input up to its first NUL
// byte is the YAML, the rest the image (PGM or PNG) it names. The image is decoded with
// the YAML's geometry, mode and thresholds when the YAML is accepted, else with the
// writer's defaults, so that both halves are always exercised.
// Checks beyond the sanitizers: an accepted YAML has a positive finite resolution, a
// finite origin, an image name and thresholds 0 <= free < occupied <= 1; a refused one is
// named by its file; a decoded map has width x height cells, no more than the bytes could
// hold, each unknown (-1) or an occupancy in [0, 1] that is, as float, above
// occupied_thresh or below free_thresh (map_server's rule) unless mode scale keeps it
// between them.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "sdpslam/io/map_read.h"
#include "fuzz_text.h"

namespace {

using sdpslam::test::fuzz::check;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string input(reinterpret_cast<const char*>(data), size);
  const std::size_t nul = input.find('\0');
  std::istringstream yaml_text(input.substr(0, nul));
  const std::string image = nul == std::string::npos ? std::string() : input.substr(nul + 1U);

  sdpslam::io::MapYaml yaml;
  std::string error;
  if (sdpslam::io::parse_map_yaml(yaml_text, "fuzz.yaml", &yaml, &error)) {
    check(!yaml.image.empty());
    check(yaml.resolution_m > 0.0 && std::isfinite(yaml.resolution_m));
    check(std::isfinite(yaml.origin_x_m) && std::isfinite(yaml.origin_y_m));
    const sdpslam::io::MapWriteOptions& t = yaml.thresholds;
    check(t.free_thresh >= 0.0 && t.free_thresh < t.occupied_thresh && t.occupied_thresh <= 1.0);
  } else {
    check(error.compare(0, 9, "fuzz.yaml") == 0);
    yaml = sdpslam::io::MapYaml{};
    yaml.image = "fuzz.pgm";
    yaml.resolution_m = 0.05;
  }

  sdpslam::io::OccupancyImage map;
  error.clear();
  if (sdpslam::io::decode_map_image(image, "fuzz.img", yaml, &map, &error)) {
    check(map.width >= 1U && map.height >= 1U);
    check(map.occupancy.size() == static_cast<std::size_t>(map.width) * map.height);
    check(map.occupancy.size() <= 8U * 1032U * image.size());
    check(map.resolution_m == yaml.resolution_m);
    const sdpslam::io::MapWriteOptions& t = yaml.thresholds;
    for (const float p : map.occupancy) {
      if (p == -1.0F) continue;
      check(p >= 0.0F && p <= 1.0F);
      if (yaml.mode == sdpslam::io::MapMode::kTrinary) check(p > t.occupied_thresh || p < t.free_thresh);
    }
  } else {
    check(error.compare(0, 10, "fuzz.img: ") == 0);
    check(map.width == 0U && map.occupancy.empty());
  }
  return 0;
}
