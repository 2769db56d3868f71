// Reading maps in the map_server convention (io/map_read.h): what the writer wrote comes
// back; what ROS's map savers write is read (quoted strings, negate as a boolean, mode,
// PNG images) with nav2's meaning of trinary, scale and raw; what cannot be read is named
// with its file and, where the YAML gives it, its line.
#include <CppUTest/TestHarness.h>
#include <png.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "sdpslam/io/atomic_file.h"
#include "sdpslam/io/map_image.h"
#include "sdpslam/io/map_read.h"
#include "shared_data.h"
#include "yaml_statics.h"

using sdpslam::io::MapMode;
using sdpslam::io::MapWriteOptions;
using sdpslam::io::MapYaml;
using sdpslam::io::OccupancyImage;
using sdpslam::io::read_map_yaml;

namespace {

// An 8-bit PNG written by libpng's simplified API: `channels` 1 (grey), 2 (grey + alpha),
// 3 (RGB) or 4 (RGBA), rows top first.
void write_png(const std::string& path, std::uint32_t w, std::uint32_t h, int channels,
               const std::vector<std::uint8_t>& px) {
  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  image.width = w;
  image.height = h;
  image.format = channels == 1 ? PNG_FORMAT_GRAY
                 : channels == 2 ? PNG_FORMAT_GA
                 : channels == 3 ? PNG_FORMAT_RGB
                                 : PNG_FORMAT_RGBA;
  CHECK_TRUE_TEXT(png_image_write_to_file(&image, path.c_str(), 0, px.data(), 0, nullptr) != 0, image.message);
}

bool parse(const std::string& text, MapYaml* y, std::string* error) {
  std::istringstream in(text);
  return sdpslam::io::parse_map_yaml(in, "t.yaml", y, error);
}

}  // namespace

TEST_GROUP(MapRead) {
  std::string dir;
  void setup() override { dir = sdpslam::test::make_temp_dir("map-read"); }
  void teardown() override {
    const std::string cmd = "rm -rf '" + dir + "'";
    CHECK_EQUAL(0, std::system(cmd.c_str()));
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
  CHECK_TRUE_TEXT(read_map_yaml(dir + "/m.yaml", &r, &t, &error), error.c_str());
  LONGS_EQUAL(3, r.width);
  LONGS_EQUAL(2, r.height);
  DOUBLES_EQUAL(0.1, r.resolution_m, 1e-12);
  DOUBLES_EQUAL(-1.5, r.origin_x_m, 1e-12);
  DOUBLES_EQUAL(2.25, r.origin_y_m, 1e-12);
  DOUBLES_EQUAL(0.65, t.occupied_thresh, 1e-12);
  const float expect[] = {1.0F, 0.0F, -1.0F, 0.8F, 0.1F, -1.0F};
  for (std::size_t i = 0; i < 6U; ++i) DOUBLES_EQUAL(expect[i], r.occupancy[i], 1.0 / 255.0);
}

// The ROS map savers' YAML (quoted image name, negate: false, mode: trinary) naming a PNG
// gives, cell for cell, the occupancy of the same map saved as PGM with this project's
// YAML; an absolute image path is taken as it is.
TEST(MapRead, a_map_server_yaml_naming_a_png_gives_the_occupancy_of_the_pgm) {
  OccupancyImage m;
  m.width = 4U;
  m.height = 3U;
  m.resolution_m = 0.05;
  m.origin_x_m = -0.5;
  m.origin_y_m = 1.0;
  m.occupancy = {1.0F, 0.0F, -1.0F, 0.5F, 0.9F, 0.1F, 0.7F, 0.15F, -1.0F, 0.66F, 0.2F, 0.0F};
  std::string error;
  CHECK_TRUE_TEXT(sdpslam::io::write_map_pgm_yaml(dir + "/m", m, MapWriteOptions{}, &error), error.c_str());
  CHECK_TRUE_TEXT(sdpslam::io::write_map_png(dir + "/m.png", m, {}, &error), error.c_str());
  const std::string ros = put("ros.yaml",
                              "image: \"m.png\"\nmode: trinary\nresolution: 0.05\norigin: [-0.5, 1.0, 0.0]\n"
                              "negate: false\noccupied_thresh: 0.65\nfree_thresh: 0.196\n");
  OccupancyImage pgm;
  OccupancyImage png;
  CHECK_TRUE_TEXT(read_map_yaml(dir + "/m.yaml", &pgm, nullptr, &error), error.c_str());
  CHECK_TRUE_TEXT(read_map_yaml(ros, &png, nullptr, &error), error.c_str());
  LONGS_EQUAL(pgm.width, png.width);
  LONGS_EQUAL(pgm.height, png.height);
  DOUBLES_EQUAL(pgm.origin_x_m, png.origin_x_m, 0.0);
  DOUBLES_EQUAL(pgm.origin_y_m, png.origin_y_m, 0.0);
  LONGS_EQUAL(pgm.occupancy.size(), png.occupancy.size());
  int known = 0;
  for (std::size_t i = 0; i < pgm.occupancy.size(); ++i) {
    DOUBLES_EQUAL(pgm.occupancy[i], png.occupancy[i], 0.0);
    if (png.occupancy[i] >= 0.0F) ++known;
  }
  LONGS_EQUAL(8, known);  // 0.5, 0.2 and the two unknown cells read as unknown
  const std::string absolute =
      put("abs.yaml", "image: '" + dir + "/m.png'\nresolution: 0.05\norigin: [-0.5, 1.0, 0]\nnegate: 0\n");
  OccupancyImage again;
  CHECK_TRUE_TEXT(read_map_yaml(absolute, &again, nullptr, &error), error.c_str());
  for (std::size_t i = 0; i < pgm.occupancy.size(); ++i) DOUBLES_EQUAL(pgm.occupancy[i], again.occupancy[i], 0.0);
}

TEST(MapRead, negate_is_0_1_false_or_true) {
  const char* const spellings[][2] = {{"0", "0"}, {"1", "1"}, {"false", "0"}, {"true", "1"}, {"'true'", "1"},
                                      {"False", "0"}};
  for (const auto& s : spellings) {
    MapYaml y;
    std::string error;
    CHECK_TRUE_TEXT(parse(std::string("image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: ") + s[0] + "\n",
                          &y, &error),
                    error.c_str());
    CHECK_EQUAL(s[1][0] == '1', y.thresholds.negate);
  }
  for (const char* bad : {"2", "maybe", "[0]"}) {
    MapYaml y;
    std::string error;
    CHECK_FALSE(parse(std::string("image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: ") + bad + "\n", &y,
                      &error));
    STRCMP_EQUAL("t.yaml:4: negate must be 0, 1, false or true", error.c_str());
  }
}

TEST(MapRead, mode_is_trinary_scale_or_raw) {
  MapYaml y;
  std::string error;
  CHECK_TRUE_TEXT(parse("image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n", &y, &error), error.c_str());
  CHECK(y.mode == MapMode::kTrinary);
  CHECK_TRUE_TEXT(parse("image: m.pgm\nmode: \"scale\"\nresolution: 0.05\norigin: [0, 0, 0]\n", &y, &error),
                  error.c_str());
  CHECK(y.mode == MapMode::kScale);
  CHECK_TRUE_TEXT(parse("image: m.pgm\nmode: raw\nresolution: 0.05\norigin: [0, 0, 0]\n", &y, &error), error.c_str());
  CHECK(y.mode == MapMode::kRaw);
  CHECK_FALSE(parse("image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nmode: Trinary\n", &y, &error));
  STRCMP_EQUAL("t.yaml:4: mode must be trinary, scale or raw", error.c_str());
}

TEST(MapRead, names_the_file_and_line_of_what_it_cannot_read) {
  OccupancyImage r;
  std::string error;
  const std::string bad = put("bad.yaml", "image: m.pgm\nresolution: -1\norigin: [0, 0, 0]\n");
  CHECK_FALSE(read_map_yaml(bad, &r, nullptr, &error));
  STRCMP_EQUAL((bad + ":2: resolution must be > 0").c_str(), error.c_str());
  put("bad.yaml", "image: m.pgm\norigin: [0, 0, 0]\n");
  CHECK_FALSE(read_map_yaml(bad, &r, nullptr, &error));
  STRCMP_EQUAL((bad + ": no 'resolution' key").c_str(), error.c_str());
  put("bad.yaml", "image: m.pgm\nresolution: 0.05\norigin: [0, 0]\n");
  CHECK_FALSE(read_map_yaml(bad, &r, nullptr, &error));
  STRCMP_EQUAL((bad + ":3: origin must be [x, y, yaw]").c_str(), error.c_str());
  put("short.pgm", std::string("P5\n4 4\n255\n") + std::string(10U, '\xff'));
  const std::string shrt = put("short.yaml", "image: short.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n");
  CHECK_FALSE(read_map_yaml(shrt, &r, nullptr, &error));
  STRCMP_EQUAL((dir + "/short.pgm: image data short: 10 of 16 bytes").c_str(), error.c_str());
  CHECK_FALSE(read_map_yaml(dir + "/none.yaml", &r, nullptr, &error));
  STRCMP_EQUAL((dir + "/none.yaml: cannot open").c_str(), error.c_str());
  const std::string gif = put("gif.yaml", "image: m.gif\nresolution: 0.05\norigin: [0, 0, 0]\n");
  put("m.gif", "GIF89a\x01\x00\x01\x00");
  CHECK_FALSE(read_map_yaml(gif, &r, nullptr, &error));
  STRCMP_EQUAL((dir + "/m.gif: not a binary PGM (P5) or a PNG image").c_str(), error.c_str());
  LONGS_EQUAL(0, r.width);
}

// Text that is not YAML, or YAML that is not a mapping, is refused with the file, the line
// yaml-cpp stopped at and its reason.
TEST(MapRead, malformed_yaml_is_refused_naming_the_file_and_line) {
  OccupancyImage r;
  std::string error;
  const std::string open_list = put("open.yaml", "image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0\nnegate: 0\n");
  CHECK_FALSE(read_map_yaml(open_list, &r, nullptr, &error));
  STRCMP_CONTAINS((open_list + ":").c_str(), error.c_str());
  STRCMP_CONTAINS("end of sequence flow not found", error.c_str());
  const std::string bad_indent = put("indent.yaml", "image: m.pgm\n  resolution: 0.05\norigin: [0, 0, 0]\n");
  CHECK_FALSE(read_map_yaml(bad_indent, &r, nullptr, &error));
  STRCMP_CONTAINS((bad_indent + ":2: ").c_str(), error.c_str());
  const std::string list = put("list.yaml", "- image: m.pgm\n- resolution: 0.05\n");
  CHECK_FALSE(read_map_yaml(list, &r, nullptr, &error));
  STRCMP_EQUAL((list + ":1: not a YAML mapping (image: ..., resolution: ...)").c_str(), error.c_str());
  const std::string empty = put("empty.yaml", "");
  CHECK_FALSE(read_map_yaml(empty, &r, nullptr, &error));
  STRCMP_CONTAINS((empty + ": not a YAML mapping").c_str(), error.c_str());
  LONGS_EQUAL(0, r.width);
}

// Found by fuzz_map_yaml_pgm: a pixel above maxval read as an occupancy outside [0, 1]
// (-1.9 here, which also posed as "unknown"; above 1 with negate).
TEST(MapRead, a_pixel_above_maxval_is_refused) {
  OccupancyImage r;
  std::string error;
  put("over.pgm", std::string("P5 2 2 15\n\x00\x0f,\x03", 14U));
  const std::string yaml = put("over.yaml", "image: over.pgm\nresolution: 0.1\norigin: [0, 0, 0]\n");
  CHECK_FALSE(read_map_yaml(yaml, &r, nullptr, &error));
  STRCMP_CONTAINS("over.pgm: pixel 2 is 44, above maxval 15", error.c_str());
  LONGS_EQUAL(0, r.width);
}

// What ROS's map savers write: a quoted image name, negate as a boolean, a mode, inline
// comments, a quoted number.
TEST(MapRead, the_yaml_of_ros_map_savers_is_read) {
  OccupancyImage r;
  MapWriteOptions t;
  std::string error;
  put("ros.pgm", std::string("P5 2 1 255\n\x00\xfe", 13U));
  const std::string yaml = put("ros.yaml", "image: \"ros.pgm\"\nmode: trinary\nresolution: 0.05  # m\n"
                                           "origin: [-1.0, 2.0, 0.0]\nnegate: false\noccupied_thresh: 0.65\n"
                                           "free_thresh: '0.25'\n");
  CHECK_TRUE_TEXT(read_map_yaml(yaml, &r, &t, &error), error.c_str());
  LONGS_EQUAL(2, r.width);
  DOUBLES_EQUAL(0.05, r.resolution_m, 1e-12);
  DOUBLES_EQUAL(-1.0, r.origin_x_m, 1e-12);
  DOUBLES_EQUAL(0.25, t.free_thresh, 1e-12);
  CHECK_FALSE(t.negate);
  DOUBLES_EQUAL(1.0, r.occupancy[0], 1e-6);          // black: occupied
  DOUBLES_EQUAL(1.0 / 255.0, r.occupancy[1], 1e-6);  // near white: free
}

// mode: scale (nav2's map_io): a pixel that is not fully opaque is unknown, and an
// occupancy between the thresholds is kept. mode: trinary on the same PNG averages alpha
// in with the colours and reads between the thresholds as unknown.
TEST(MapRead, scale_keeps_values_between_the_thresholds_and_reads_transparency_as_unknown) {
  // RGBA, one row: opaque black, opaque white, opaque grey 128, transparent black,
  // half-transparent black, transparent white, opaque red (mean (255+0+0)/3 = 85).
  write_png(dir + "/s.png", 7U, 1U, 4,
            {0, 0, 0, 255, 255, 255, 255, 255, 128, 128, 128, 255, 0, 0, 0, 0,
             0, 0, 0, 200, 255, 255, 255, 0, 255, 0, 0, 255});
  const std::string head = "image: s.png\nresolution: 0.1\norigin: [0, 0, 0]\noccupied_thresh: 0.65\nfree_thresh: 0.196\n";
  OccupancyImage r;
  std::string error;
  CHECK_TRUE_TEXT(read_map_yaml(put("scale.yaml", head + "mode: scale\n"), &r, nullptr, &error), error.c_str());
  LONGS_EQUAL(7, r.occupancy.size());
  DOUBLES_EQUAL(1.0, r.occupancy[0], 0.0);
  DOUBLES_EQUAL(0.0, r.occupancy[1], 0.0);
  DOUBLES_EQUAL(127.0 / 255.0, r.occupancy[2], 1e-7);  // between the thresholds: kept
  DOUBLES_EQUAL(-1.0, r.occupancy[3], 0.0);
  DOUBLES_EQUAL(-1.0, r.occupancy[4], 0.0);
  DOUBLES_EQUAL(-1.0, r.occupancy[5], 0.0);
  DOUBLES_EQUAL(170.0 / 255.0, r.occupancy[6], 1e-7);  // red reads as its mean grey
  // Trinary: p = (1020 - (R + G + B + A)) / 1020.
  CHECK_TRUE_TEXT(read_map_yaml(put("trinary.yaml", head + "mode: trinary\n"), &r, nullptr, &error), error.c_str());
  DOUBLES_EQUAL(765.0 / 1020.0, r.occupancy[0], 1e-7);  // opaque black
  DOUBLES_EQUAL(0.0, r.occupancy[1], 0.0);
  DOUBLES_EQUAL(-1.0, r.occupancy[2], 0.0);              // 381 / 1020: between
  DOUBLES_EQUAL(1.0, r.occupancy[3], 0.0);               // colour 0 and alpha 0: all dark
  DOUBLES_EQUAL(820.0 / 1020.0, r.occupancy[4], 1e-7);
  DOUBLES_EQUAL(-1.0, r.occupancy[5], 0.0);              // 255 / 1020 = 0.25: between
  DOUBLES_EQUAL(-1.0, r.occupancy[6], 0.0);              // 510 / 1020: between
}

// mode: raw: the pixel value is the occupancy in percent; above 100 is unknown, and
// negate does not apply (nav2's map_io).
TEST(MapRead, raw_takes_the_pixel_value_as_percent) {
  put("raw.pgm", std::string("P5 5 1 255\n\x00\x41\x64\x65\xff", 16U));
  OccupancyImage r;
  std::string error;
  for (const char* negate : {"false", "true"}) {
    const std::string yaml = put("raw.yaml", std::string("image: raw.pgm\nmode: raw\nresolution: 0.1\n"
                                                         "origin: [0, 0, 0]\nnegate: ") + negate + "\n");
    CHECK_TRUE_TEXT(read_map_yaml(yaml, &r, nullptr, &error), error.c_str());
    LONGS_EQUAL(5, r.occupancy.size());
    DOUBLES_EQUAL(0.0, r.occupancy[0], 0.0);
    DOUBLES_EQUAL(0.65, r.occupancy[1], 1e-7);
    DOUBLES_EQUAL(1.0, r.occupancy[2], 0.0);
    DOUBLES_EQUAL(-1.0, r.occupancy[3], 0.0);
    DOUBLES_EQUAL(-1.0, r.occupancy[4], 0.0);
  }
}

// map_server's rule at the thresholds: pixel 14 of maxval 40 is occupancy exactly 0.65,
// on occupied_thresh, and pixel 32 exactly 0.2, on free_thresh: both unknown.
TEST(MapRead, a_cell_exactly_on_a_threshold_is_unknown) {
  OccupancyImage r;
  std::string error;
  put("on.pgm", "P5 2 1 40\n\x0e\x20");
  const std::string yaml = put("on.yaml", "image: on.pgm\nresolution: 0.1\norigin: [0, 0, 0]\n"
                                          "occupied_thresh: 0.65\nfree_thresh: 0.2\n");
  CHECK_TRUE_TEXT(read_map_yaml(yaml, &r, nullptr, &error), error.c_str());
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
  CHECK_TRUE_TEXT(read_map_yaml(yaml, &r, &t, &error), error.c_str());
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
  CHECK_FALSE(read_map_yaml(yaml, &r, nullptr, &error));
  STRCMP_CONTAINS("bare.pgm: image data short: 0 of 4 bytes", error.c_str());
}
