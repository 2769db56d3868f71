#include "sdpslam/sim/world_raster.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace sdpslam::sim {

io::OccupancyImage rasterize_world(const World& world, const RasterOptions& options) {
  io::OccupancyImage img;
  if (world.segments.empty() || !(options.resolution_m > 0.0)) return img;
  double min_x = std::numeric_limits<double>::infinity();
  double min_y = min_x;
  double max_x = -min_x;
  double max_y = -min_x;
  for (const Segment& s : world.segments) {
    min_x = std::min({min_x, s.a.x_m, s.b.x_m});
    min_y = std::min({min_y, s.a.y_m, s.b.y_m});
    max_x = std::max({max_x, s.a.x_m, s.b.x_m});
    max_y = std::max({max_y, s.a.y_m, s.b.y_m});
  }
  const double res = options.resolution_m;
  const double margin = std::max(0.0, options.margin_m);
  img.resolution_m = res;
  img.origin_x_m = std::floor((min_x - margin) / res) * res;
  img.origin_y_m = std::floor((min_y - margin) / res) * res;
  img.width = static_cast<std::uint32_t>(std::ceil((max_x + margin - img.origin_x_m) / res));
  img.height = static_cast<std::uint32_t>(std::ceil((max_y + margin - img.origin_y_m) / res));
  const std::size_t w = img.width;
  const std::size_t h = img.height;
  const float background = options.flood_from_seed ? -1.0F : 0.0F;
  img.occupancy.assign(w * h, background);

  auto cell_of = [&](double x, double y, std::size_t* cx, std::size_t* cy) {
    const double fx = std::floor((x - img.origin_x_m) / res);
    const double fy = std::floor((y - img.origin_y_m) / res);
    if (fx < 0.0 || fy < 0.0 || fx >= static_cast<double>(w) || fy >= static_cast<double>(h)) return false;
    *cx = static_cast<std::size_t>(fx);
    *cy = static_cast<std::size_t>(fy);
    return true;
  };
  for (const Segment& s : world.segments) {
    const double len = std::hypot(s.b.x_m - s.a.x_m, s.b.y_m - s.a.y_m);
    const std::size_t n = static_cast<std::size_t>(std::ceil(len / (res / 8.0))) + 1U;
    for (std::size_t i = 0; i <= n; ++i) {
      const double u = static_cast<double>(i) / static_cast<double>(n);
      std::size_t cx = 0;
      std::size_t cy = 0;
      if (cell_of(s.a.x_m + u * (s.b.x_m - s.a.x_m), s.a.y_m + u * (s.b.y_m - s.a.y_m), &cx, &cy)) {
        img.occupancy[cy * w + cx] = 1.0F;
      }
    }
  }
  if (options.flood_from_seed) {
    std::size_t sx = 0;
    std::size_t sy = 0;
    if (cell_of(options.free_seed_x_m, options.free_seed_y_m, &sx, &sy) && img.occupancy[sy * w + sx] < 0.0F) {
      std::vector<std::size_t> stack{sy * w + sx};
      img.occupancy[sy * w + sx] = 0.0F;
      while (!stack.empty()) {
        const std::size_t c = stack.back();
        stack.pop_back();
        const std::size_t x = c % w;
        const std::size_t y = c / w;
        auto visit = [&](std::size_t nc) {
          if (img.occupancy[nc] < 0.0F) {
            img.occupancy[nc] = 0.0F;
            stack.push_back(nc);
          }
        };
        if (x > 0) visit(c - 1);
        if (x + 1 < w) visit(c + 1);
        if (y > 0) visit(c - w);
        if (y + 1 < h) visit(c + w);
      }
    }
  }
  return img;
}

}  // namespace sdpslam::sim
