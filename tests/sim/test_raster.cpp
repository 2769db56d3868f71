// Ground-truth occupancy of the world.
#include <CppUTest/TestHarness.h>

#include "sdpslam/sim/world_raster.h"

using namespace sdpslam::sim;

namespace {
float at(const sdpslam::io::OccupancyImage& m, double x, double y) {
  const auto cx = static_cast<std::size_t>((x - m.origin_x_m) / m.resolution_m);
  const auto cy = static_cast<std::size_t>((y - m.origin_y_m) / m.resolution_m);
  return m.occupancy[cy * m.width + cx];
}
RasterOptions builtin_raster() {
  RasterOptions o;
  o.free_seed_x_m = builtin_route().waypoints[0].x_m;
  o.free_seed_y_m = builtin_route().waypoints[0].y_m;
  return o;
}
}  // namespace

TEST_GROUP(SimRaster){};

TEST(SimRaster, walls_are_occupied_and_the_corridors_free) {
  const auto m = rasterize_world(builtin_world(), builtin_raster());
  DOUBLES_EQUAL(1.0, at(m, 10.0, -0.9 + 0.01), 0.0);  // south outer wall
  DOUBLES_EQUAL(0.0, at(m, 10.0, 0.0), 0.0);          // south corridor
  DOUBLES_EQUAL(0.0, at(m, 24.0, 8.0), 0.0);          // east corridor
  DOUBLES_EQUAL(0.0, at(m, 4.0, 6.0), 0.0);           // inner loop's north corridor
}

TEST(SimRaster, space_the_robot_cannot_reach_stays_unknown) {
  const auto m = rasterize_world(builtin_world(), builtin_raster());
  DOUBLES_EQUAL(-1.0, at(m, 4.0, 3.0), 0.0);    // inside the inner block
  DOUBLES_EQUAL(-1.0, at(m, 16.0, 8.0), 0.0);   // inside the L-shaped block
  DOUBLES_EQUAL(-1.0, at(m, -1.5, 8.0), 0.0);   // outside the outer wall: no leak
}

TEST(SimRaster, without_flood_every_non_wall_cell_is_free) {
  RasterOptions o = builtin_raster();
  o.flood_from_seed = false;
  const auto m = rasterize_world(builtin_world(), o);
  DOUBLES_EQUAL(0.0, at(m, 4.0, 3.0), 0.0);
}

TEST(SimRaster, map_covers_the_walls_with_the_margin_at_the_resolution) {
  const auto m = rasterize_world(builtin_world(), builtin_raster());
  DOUBLES_EQUAL(0.05, m.resolution_m, 0.0);
  CHECK(m.origin_x_m <= -0.9 - 1.0 + 1e-9);
  CHECK(m.origin_x_m + m.width * m.resolution_m >= 25.5 + 1.0 - 1e-9);
  LONGS_EQUAL(static_cast<long>(m.width) * m.height, static_cast<long>(m.occupancy.size()));
}

TEST(SimRaster, empty_world_gives_an_empty_map) {
  const auto m = rasterize_world(World{}, RasterOptions{});
  LONGS_EQUAL(0, m.width);
  CHECK(m.occupancy.empty());
}
