// Map agreement (map_agreement.h): returns cast from the right poses end on the walls,
// from shifted poses they do not. The map reader it uses is tested in
// tests/io_outputs/test_map_read.cpp.
#include <CppUTest/TestHarness.h>

#include <cmath>
#include <memory>
#include <string>

#include "sdpslam/eval/map_agreement.h"
#include "sdpslam/io/map_image.h"

using sdpslam::Pose2;
using sdpslam::RangeScan;
using sdpslam::eval::MapAgreement;
using sdpslam::io::OccupancyImage;

namespace {

// 5 m × 5 m at 5 cm centred on the origin, free, with a wall along x = 1.0 .. 1.05 m.
OccupancyImage wall_map() {
  OccupancyImage m;
  m.width = 100U;
  m.height = 100U;
  m.resolution_m = 0.05;
  m.origin_x_m = -2.5;
  m.origin_y_m = -2.5;
  m.occupancy.assign(10000U, 0.0F);
  for (std::uint32_t r = 0; r < 100U; ++r) m.occupancy[r * 100U + 70U] = 1.0F;  // column 70: x in [1.0, 1.05)
  return m;
}

// 21 beams over ±0.5 rad, each ending on the plane x = 1.02 m seen from the origin.
std::unique_ptr<RangeScan> scan_of_wall() {
  auto s = std::make_unique<RangeScan>();
  s->geometry.angle_min_rad = -0.5F;
  s->geometry.angle_increment_rad = 0.05F;
  s->geometry.range_min_m = 0.05F;
  s->geometry.range_max_m = 10.0F;
  s->beam_count = 23U;
  for (std::uint32_t i = 0; i < 21U; ++i) s->ranges_m[i] = static_cast<float>(1.02 / std::cos(s->beam_angle_rad(i)));
  s->ranges_m[21] = 10.0F;  // no return: not counted
  s->ranges_m[22] = 0.0F;   // invalid: not counted
  return s;
}

}  // namespace

TEST_GROUP(MapAgreement){};

TEST(MapAgreement, returns_cast_from_the_true_pose_end_on_the_wall_and_from_a_shifted_one_do_not) {
  const OccupancyImage map = wall_map();
  const auto scan = scan_of_wall();
  MapAgreement right(map, 0.65);
  right.add_scan(Pose2{0.0, 0.0, 0.0}, *scan);
  LONGS_EQUAL(1, right.result().scans_cast);
  LONGS_EQUAL(21, right.result().return_count);
  LONGS_EQUAL(21, right.result().on_wall_count);
  DOUBLES_EQUAL(1.0, right.result().share(), 0.0);
  // One cell off still counts (the tolerance); four cells off does not.
  MapAgreement near(map, 0.65);
  near.add_scan(Pose2{0.05, 0.0, 0.0}, *scan);
  LONGS_EQUAL(21, near.result().on_wall_count);
  MapAgreement shifted(map, 0.65);
  shifted.add_scan(Pose2{0.2, 0.0, 0.0}, *scan);
  LONGS_EQUAL(21, shifted.result().return_count);
  LONGS_EQUAL(0, shifted.result().on_wall_count);
  // The laser's mounting is applied: mounted 0.2 m behind the centre of a robot standing
  // 0.2 m ahead, the laser is at the origin again and its returns land on the wall.
  auto mounted = scan_of_wall();
  mounted->geometry.laser_in_base = Pose2{-0.2, 0.0, 0.0};
  MapAgreement m(map, 0.65);
  m.add_scan(Pose2{0.2, 0.0, 0.0}, *mounted);
  LONGS_EQUAL(21, m.result().on_wall_count);
  // Returns off the image count as off the walls.
  MapAgreement outside(map, 0.65);
  outside.add_scan(Pose2{10.0, 10.0, 0.0}, *scan);
  LONGS_EQUAL(21, outside.result().return_count);
  LONGS_EQUAL(0, outside.result().on_wall_count);
}
