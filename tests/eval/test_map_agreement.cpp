// Map agreement (map_agreement.h) and the map_server reader it uses: returns cast from
// the right poses end on the walls, from shifted poses they do not; the reader gives back
// what the writer wrote and names the file and line of what it cannot read.
#include <CppUTest/TestHarness.h>
#include <unistd.h>

#include <cmath>
#include <memory>
#include <string>

#include "sdpslam/eval/map_agreement.h"
#include "sdpslam/io/atomic_file.h"
#include "sdpslam/io/map_image.h"
#include "shared_data.h"

using sdpslam::Pose2;
using sdpslam::RangeScan;
using sdpslam::eval::MapAgreement;
using sdpslam::io::MapWriteOptions;
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

TEST_GROUP(MapRead) {
  std::string dir;
  void setup() override { dir = sdpslam::test::make_temp_dir("map-read"); }
  void teardown() override {
    for (const char* f : {"/m.pgm", "/m.yaml", "/bad.yaml", "/short.pgm", "/short.yaml", "/over.pgm", "/over.yaml",
                          "/bare.pgm", "/bare.yaml", "/edge.pgm", "/edge.yaml"}) {
      ::unlink((dir + f).c_str());
    }
    ::rmdir(dir.c_str());
  }
  std::string put(const char* name, const std::string& text) {
    std::string error;
    const std::string p = dir + "/" + name;
    CHECK_TRUE(sdpslam::io::write_file_atomic(p, text, &error));
    return p;
  }
};

TEST(MapRead, gives_back_what_the_writer_wrote) {
  OccupancyImage m;
  m.width = 3U;
  m.height = 2U;
  m.resolution_m = 0.1;
  m.origin_x_m = -1.5;
  m.origin_y_m = 2.25;
  m.occupancy = {1.0F, 0.0F, -1.0F, 0.8F, 0.1F, 0.4F};  // 0.4 lies between the thresholds: unknown
  std::string error;
  CHECK_TRUE_TEXT(sdpslam::io::write_map_pgm_yaml(dir + "/m", m, MapWriteOptions{}, &error), error.c_str());
  OccupancyImage r;
  MapWriteOptions t;
  t.occupied_thresh = 0.0;
  CHECK_TRUE_TEXT(sdpslam::io::read_map_pgm_yaml(dir + "/m.yaml", &r, &t, &error), error.c_str());
  LONGS_EQUAL(3, r.width);
  LONGS_EQUAL(2, r.height);
  DOUBLES_EQUAL(0.1, r.resolution_m, 1e-12);
  DOUBLES_EQUAL(-1.5, r.origin_x_m, 1e-12);
  DOUBLES_EQUAL(2.25, r.origin_y_m, 1e-12);
  DOUBLES_EQUAL(0.65, t.occupied_thresh, 1e-12);
  const float expect[] = {1.0F, 0.0F, -1.0F, 0.8F, 0.1F, -1.0F};
  for (std::size_t i = 0; i < 6U; ++i) DOUBLES_EQUAL(expect[i], r.occupancy[i], 1.0 / 255.0);
}

TEST(MapRead, names_the_file_and_line_of_what_it_cannot_read) {
  OccupancyImage r;
  std::string error;
  const std::string bad = put("bad.yaml", "image: m.pgm\nresolution: -1\norigin: [0, 0, 0]\n");
  CHECK_FALSE(sdpslam::io::read_map_pgm_yaml(bad, &r, nullptr, &error));
  STRCMP_CONTAINS("bad.yaml:2: resolution must be > 0", error.c_str());
  put("bad.yaml", "image: m.pgm\norigin: [0, 0, 0]\n");
  CHECK_FALSE(sdpslam::io::read_map_pgm_yaml(bad, &r, nullptr, &error));
  STRCMP_CONTAINS("no 'resolution' key", error.c_str());
  put("short.pgm", std::string("P5\n4 4\n255\n") + std::string(10U, '\xff'));
  const std::string shrt = put("short.yaml", "image: short.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n");
  CHECK_FALSE(sdpslam::io::read_map_pgm_yaml(shrt, &r, nullptr, &error));
  STRCMP_CONTAINS("short.pgm: image data short: 10 of 16 bytes", error.c_str());
  CHECK_FALSE(sdpslam::io::read_map_pgm_yaml(dir + "/none.yaml", &r, nullptr, &error));
  STRCMP_CONTAINS("none.yaml: cannot open", error.c_str());
}

// Found by fuzz_map_yaml_pgm: a pixel above maxval read as an occupancy outside [0, 1]
// (-1.9 here, which also posed as "unknown"; above 1 with negate).
TEST(MapRead, a_pixel_above_maxval_is_refused) {
  OccupancyImage r;
  std::string error;
  put("over.pgm", std::string("P5 2 2 15\n\x00\x0f,\x03", 14U));
  const std::string yaml = put("over.yaml", "image: over.pgm\nresolution: 0.1\norigin: [0, 0, 0]\n");
  CHECK_FALSE(sdpslam::io::read_map_pgm_yaml(yaml, &r, nullptr, &error));
  STRCMP_CONTAINS("over.pgm: pixel 2 is 44, above maxval 15", error.c_str());
  LONGS_EQUAL(0, r.width);
}

// What ROS's map savers write: a quoted image name, negate as a boolean, a mode, inline
// comments; a raw mode (pixels as values) is refused by name.
TEST(MapRead, the_yaml_of_ros_map_savers_is_read) {
  OccupancyImage r;
  MapWriteOptions t;
  std::string error;
  put("ros.pgm", std::string("P5 2 1 255\n\x00\xfe", 13U));
  const std::string yaml = put("ros.yaml", "image: \"ros.pgm\"\nmode: trinary\nresolution: 0.05  # m\n"
                                           "origin: [-1.0, 2.0, 0.0]\nnegate: false\noccupied_thresh: 0.65\n"
                                           "free_thresh: '0.25'\n");
  CHECK_TRUE_TEXT(sdpslam::io::read_map_pgm_yaml(yaml, &r, &t, &error), error.c_str());
  LONGS_EQUAL(2, r.width);
  DOUBLES_EQUAL(0.05, r.resolution_m, 1e-12);
  DOUBLES_EQUAL(0.25, t.free_thresh, 1e-12);
  CHECK_FALSE(t.negate);
  DOUBLES_EQUAL(1.0, r.occupancy[0], 1e-6);  // black: occupied
  DOUBLES_EQUAL(1.0 / 255.0, r.occupancy[1], 1e-6);  // near white: free
  const std::string raw = put("raw.yaml", "image: ros.pgm\nmode: raw\nresolution: 0.05\norigin: [0, 0, 0]\n");
  CHECK_FALSE(sdpslam::io::read_map_pgm_yaml(raw, &r, &t, &error));
  STRCMP_CONTAINS("raw.yaml:2: mode 'raw' is not supported", error.c_str());
}

// map_server's rule at the thresholds: pixel 14 of maxval 40 is occupancy exactly 0.65,
// on occupied_thresh, and pixel 32 exactly 0.2, on free_thresh: both unknown.
TEST(MapRead, a_cell_exactly_on_a_threshold_is_unknown) {
  OccupancyImage r;
  std::string error;
  put("on.pgm", "P5 2 1 40\n\x0e\x20");
  const std::string yaml = put("on.yaml", "image: on.pgm\nresolution: 0.1\norigin: [0, 0, 0]\n"
                                          "occupied_thresh: 0.65\nfree_thresh: 0.2\n");
  CHECK_TRUE_TEXT(sdpslam::io::read_map_pgm_yaml(yaml, &r, nullptr, &error), error.c_str());
  LONGS_EQUAL(2, r.occupancy.size());
  DOUBLES_EQUAL(-1.0, r.occupancy[0], 0.0);
  DOUBLES_EQUAL(-1.0, r.occupancy[1], 0.0);
}

// Found by fuzz_map_yaml_pgm: a class decided in double was lost in the float kept.
// Occupancy 0.65 (pixel 14 of 40) is above occupied_thresh 0.64999999 but rounds to
// 0.6499999762F, below it; 0.2 (pixel 32 of 40) is below free_thresh 0.2000000001 but
// rounds to 0.2000000030F, above it. Each float must stay in its class, as a reader
// applying the same rule (MapAgreement) sees it.
TEST(MapRead, a_cell_next_to_a_threshold_keeps_its_class_in_float) {
  OccupancyImage r;
  MapWriteOptions t;
  std::string error;
  put("edge.pgm", "P5 2 1 40\n\x0e\x20");
  const std::string yaml = put("edge.yaml", "image: edge.pgm\nresolution: 0.1\norigin: [0, 0, 0]\n"
                                            "occupied_thresh: 0.64999999\nfree_thresh: 0.2000000001\n");
  CHECK_TRUE_TEXT(sdpslam::io::read_map_pgm_yaml(yaml, &r, &t, &error), error.c_str());
  LONGS_EQUAL(2, r.occupancy.size());
  CHECK_TRUE(static_cast<float>(0.65) < t.occupied_thresh);  // the rounding this test is about
  CHECK_TRUE(static_cast<float>(0.2) > t.free_thresh);
  CHECK_TRUE(r.occupancy[0] > t.occupied_thresh);
  DOUBLES_EQUAL(0.65, r.occupancy[0], 1e-7);
  CHECK_TRUE(r.occupancy[1] >= 0.0F && r.occupancy[1] < t.free_thresh);
  DOUBLES_EQUAL(0.2, r.occupancy[1], 1e-7);
}

// A header ending the file without the whitespace after maxval: the count of bytes
// present was 2^64 - 1.
TEST(MapRead, a_header_without_pixels_reports_zero_bytes_present) {
  OccupancyImage r;
  std::string error;
  put("bare.pgm", "P5 2 2 255");
  const std::string yaml = put("bare.yaml", "image: bare.pgm\nresolution: 0.1\norigin: [0, 0, 0]\n");
  CHECK_FALSE(sdpslam::io::read_map_pgm_yaml(yaml, &r, nullptr, &error));
  STRCMP_CONTAINS("bare.pgm: image data short: 0 of 4 bytes", error.c_str());
}
