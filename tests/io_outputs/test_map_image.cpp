// Map images: PGM pixels and orientation, YAML fields in the map_server convention, and
// PNG structure (signature, IHDR, decoded pixels including the drawn trajectory).
#include <CppUTest/TestHarness.h>
#include <png.h>
#include <unistd.h>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "sdpslam/io/atomic_file.h"
#include "sdpslam/io/figures.h"
#include "sdpslam/io/map_image.h"
#include "shared_data.h"

using sdpslam::io::OccupancyImage;
using sdpslam::io::StampedPose;

namespace {
std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::uint32_t be32(const std::string& s, std::size_t at) {
  return (static_cast<std::uint32_t>(static_cast<unsigned char>(s[at])) << 24) |
         (static_cast<std::uint32_t>(static_cast<unsigned char>(s[at + 1])) << 16) |
         (static_cast<std::uint32_t>(static_cast<unsigned char>(s[at + 2])) << 8) |
         static_cast<std::uint32_t>(static_cast<unsigned char>(s[at + 3]));
}

// A 4 x 3 map, row 0 (south) = {0, 1, unknown, 0.5}, rows 1 and 2 unknown except one cell.
OccupancyImage small_map() {
  OccupancyImage m;
  m.width = 4;
  m.height = 3;
  m.resolution_m = 0.05;
  m.origin_x_m = -1.25;
  m.origin_y_m = 2.0;
  m.occupancy.assign(12, -1.0F);
  m.occupancy[0] = 0.0F;
  m.occupancy[1] = 1.0F;
  m.occupancy[3] = 0.5F;
  m.occupancy[2 * 4 + 3] = 0.9F;  // north-east corner
  return m;
}

struct DecodedPng {
  std::uint32_t width = 0, height = 0;
  int channels = 0;
  std::vector<std::uint8_t> px;
};

DecodedPng decode(const std::string& path) {
  DecodedPng d;
  png_image img;
  std::memset(&img, 0, sizeof img);
  img.version = PNG_IMAGE_VERSION;
  if (png_image_begin_read_from_file(&img, path.c_str()) == 0) return d;
  d.channels = (img.format & PNG_FORMAT_FLAG_COLOR) != 0 ? 3 : 1;
  img.format = d.channels == 3 ? PNG_FORMAT_RGB : PNG_FORMAT_GRAY;
  d.px.resize(PNG_IMAGE_SIZE(img));
  if (png_image_finish_read(&img, nullptr, d.px.data(), 0, nullptr) == 0) return DecodedPng{};
  d.width = img.width;
  d.height = img.height;
  return d;
}
}  // namespace

TEST_GROUP(MapImage) {
  std::string dir;
  void setup() override { dir = sdpslam::test::make_temp_dir("map"); }
  void teardown() override {
    for (const char* f : {"/m.pgm", "/m.yaml", "/m.png", "/t.png", "/n.pgm", "/n.yaml", "/far.png"}) {
      ::unlink((dir + f).c_str());
    }
    ::rmdir(dir.c_str());
  }
};

TEST(MapImage, pgm_header_and_pixels_are_flipped_north_up) {
  std::string error;
  CHECK_TRUE_TEXT(sdpslam::io::write_map_pgm_yaml(dir + "/m", small_map(), {}, &error), error.c_str());
  const std::string pgm = slurp(dir + "/m.pgm");
  CHECK(pgm.rfind("P5\n", 0) == 0);
  const std::string tail = "4 3\n255\n";
  const std::size_t at = pgm.find(tail);
  CHECK(at != std::string::npos);
  const std::string px = pgm.substr(at + tail.size());
  LONGS_EQUAL(12, px.size());
  const auto p = [&](int i) { return static_cast<int>(static_cast<unsigned char>(px[static_cast<std::size_t>(i)])); };
  // Top image row = grid row 2: unknown x3 then p = 0.9 -> round(25.5) = 26.
  LONGS_EQUAL(205, p(0));
  LONGS_EQUAL(26, p(3));
  // Bottom image row = grid row 0: free 255, occupied 0, unknown 205, p = 0.5 -> 128.
  LONGS_EQUAL(255, p(8));
  LONGS_EQUAL(0, p(9));
  LONGS_EQUAL(205, p(10));
  LONGS_EQUAL(128, p(11));
}

TEST(MapImage, yaml_has_map_server_fields) {
  std::string error;
  CHECK_TRUE(sdpslam::io::write_map_pgm_yaml(dir + "/m", small_map(), {}, &error));
  STRCMP_EQUAL(
      "image: m.pgm\n"
      "resolution: 0.05\n"
      "origin: [-1.25, 2.0, 0.0]\n"
      "negate: 0\n"
      "occupied_thresh: 0.65\n"
      "free_thresh: 0.196\n",
      slurp(dir + "/m.yaml").c_str());
}

TEST(MapImage, negate_stores_occupancy_directly_and_unknown_as_50) {
  std::string error;
  sdpslam::io::MapWriteOptions opt;
  opt.negate = true;
  CHECK_TRUE(sdpslam::io::write_map_pgm_yaml(dir + "/n", small_map(), opt, &error));
  const std::string pgm = slurp(dir + "/n.pgm");
  const std::string px = pgm.substr(pgm.size() - 12);
  LONGS_EQUAL(50, static_cast<unsigned char>(px[0]));
  LONGS_EQUAL(0, static_cast<unsigned char>(px[8]));
  LONGS_EQUAL(255, static_cast<unsigned char>(px[9]));
  STRCMP_CONTAINS("negate: 1\n", slurp(dir + "/n.yaml").c_str());
}

TEST(MapImage, size_mismatch_is_refused_and_nothing_written) {
  OccupancyImage m = small_map();
  m.occupancy.pop_back();
  std::string error;
  CHECK_FALSE(sdpslam::io::write_map_pgm_yaml(dir + "/m", m, {}, &error));
  STRCMP_CONTAINS("11 cells", error.c_str());
  CHECK(::access((dir + "/m.pgm").c_str(), F_OK) != 0);
  CHECK_FALSE(sdpslam::io::write_map_png(dir + "/m.png", m, {}, &error));
  CHECK(::access((dir + "/m.png").c_str(), F_OK) != 0);
}

TEST(MapImage, empty_map_and_bad_resolution_and_thresholds_are_refused) {
  std::string error;
  OccupancyImage empty;
  CHECK_FALSE(sdpslam::io::write_map_pgm_yaml(dir + "/m", empty, {}, &error));
  STRCMP_CONTAINS("empty", error.c_str());
  OccupancyImage m = small_map();
  m.resolution_m = 0.0;
  CHECK_FALSE(sdpslam::io::write_map_png(dir + "/m.png", m, {}, &error));
  STRCMP_CONTAINS("resolution", error.c_str());
  sdpslam::io::MapWriteOptions opt;
  opt.free_thresh = 0.8;
  CHECK_FALSE(sdpslam::io::write_map_pgm_yaml(dir + "/m", small_map(), opt, &error));
  STRCMP_CONTAINS("thresholds", error.c_str());
}

TEST(MapImage, grey_png_has_signature_and_ihdr_dimensions) {
  std::string error;
  CHECK_TRUE_TEXT(sdpslam::io::write_map_png(dir + "/m.png", small_map(), {}, &error), error.c_str());
  const std::string png = slurp(dir + "/m.png");
  CHECK(png.size() > 33);
  CHECK(png.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0);
  CHECK(png.compare(12, 4, "IHDR") == 0);
  LONGS_EQUAL(4, be32(png, 16));
  LONGS_EQUAL(3, be32(png, 20));
  LONGS_EQUAL(8, png[24]);  // bit depth
  LONGS_EQUAL(0, png[25]);  // colour type grey
  const DecodedPng d = decode(dir + "/m.png");
  LONGS_EQUAL(1, d.channels);
  LONGS_EQUAL(205, d.px[0]);
  LONGS_EQUAL(26, d.px[3]);
  LONGS_EQUAL(0, d.px[9]);
}

TEST(MapImage, trajectory_png_is_rgb_with_line_and_marked_ends) {
  OccupancyImage m;
  m.width = 40;
  m.height = 20;
  m.resolution_m = 0.1;
  m.occupancy.assign(800, 0.0F);  // all free: white
  // From (0.55, 0.55) -> cell (5, 5) to (3.55, 0.55) -> cell (35, 5): a horizontal line
  // on image row 20 - 1 - 5 = 14.
  std::vector<StampedPose> traj{{0, {0.55, 0.55, 0.0}}, {1, {2.05, 0.55, 0.0}}, {2, {3.55, 0.55, 0.0}}};
  std::string error;
  CHECK_TRUE_TEXT(sdpslam::io::write_map_png(dir + "/t.png", m, traj, &error), error.c_str());
  const std::string png = slurp(dir + "/t.png");
  LONGS_EQUAL(2, png[25]);  // colour type RGB
  const DecodedPng d = decode(dir + "/t.png");
  LONGS_EQUAL(3, d.channels);
  LONGS_EQUAL(40, d.width);
  const auto at = [&](int x, int y, int ch) { return static_cast<int>(d.px[static_cast<std::size_t>((y * 40 + x) * 3 + ch)]); };
  // Line pixel in the middle: red.
  LONGS_EQUAL(220, at(20, 14, 0));
  LONGS_EQUAL(20, at(20, 14, 1));
  // Start marker (green) and end marker (blue), 5x5 around the end cells.
  LONGS_EQUAL(170, at(5, 14, 1));
  LONGS_EQUAL(170, at(7, 16, 1));
  LONGS_EQUAL(230, at(35, 14, 2));
  LONGS_EQUAL(0, at(35, 14, 1) > 100 ? 1 : 0);
  // Off the line: still white.
  LONGS_EQUAL(255, at(20, 5, 0));
  LONGS_EQUAL(255, at(20, 5, 1));
}

TEST(MapImage, points_are_drawn_as_orange_pixels_and_off_map_points_are_left_out) {
  OccupancyImage m;
  m.width = 40;
  m.height = 20;
  m.resolution_m = 0.1;
  m.occupancy.assign(800, 0.0F);
  // (1.05, 0.55) -> cell (10, 5) -> image row 14; the others fall outside.
  const std::vector<sdpslam::Pose2> points{{1.05, 0.55, 0.0}, {-5.0, 0.5, 0.0}, {1.0, 90.0, 0.0}};
  std::string error;
  CHECK_TRUE_TEXT(sdpslam::io::write_map_png(dir + "/p.png", m, {}, points, &error), error.c_str());
  const DecodedPng d = decode(dir + "/p.png");
  LONGS_EQUAL(3, d.channels);
  const auto at = [&](int x, int y, int ch) { return static_cast<int>(d.px[static_cast<std::size_t>((y * 40 + x) * 3 + ch)]); };
  LONGS_EQUAL(255, at(10, 14, 0));
  LONGS_EQUAL(140, at(10, 14, 1));
  LONGS_EQUAL(0, at(10, 14, 2));
  LONGS_EQUAL(255, at(11, 14, 2));  // the next pixel: still white
}

TEST(MapImage, trajectory_far_outside_the_map_is_clipped_not_drawn_forever) {
  OccupancyImage m = small_map();
  std::vector<StampedPose> traj{{0, {-1e12, -1e12, 0.0}}, {1, {1e12, 1e12, 0.0}}};
  std::string error;
  CHECK_TRUE(sdpslam::io::write_map_png(dir + "/far.png", m, traj, &error));
  const DecodedPng d = decode(dir + "/far.png");
  LONGS_EQUAL(4, d.width);
  LONGS_EQUAL(3, d.height);
}

TEST(MapImage, png_bytes_are_deterministic) {
  std::string error;
  CHECK_TRUE(sdpslam::io::write_map_png(dir + "/m.png", small_map(), {}, &error));
  const std::string a = slurp(dir + "/m.png");
  CHECK_TRUE(sdpslam::io::write_map_png(dir + "/m.png", small_map(), {}, &error));
  CHECK(a == slurp(dir + "/m.png"));
}

// The plain painter (figures.h), for builds without a drawing library: a chart as its
// series on two axes, without text: the first line series in the path colour, points in
// the point colour, a band in grey; a map figure as write_map_png() draws it.
TEST(MapImage, the_plain_painter_draws_a_chart_and_a_map_without_text) {
  sdpslam::io::Chart chart;
  sdpslam::io::ChartSeries band;
  band.style = sdpslam::io::ChartSeries::Style::kBand;
  sdpslam::io::ChartSeries line;
  sdpslam::io::ChartSeries dots;
  dots.style = sdpslam::io::ChartSeries::Style::kPoints;
  for (int k = 0; k <= 50; ++k) {
    band.x.push_back(k);
    band.y.push_back(1.0);
    band.y_high.push_back(3.0);
    line.x.push_back(k);
    line.y.push_back(2.0);
    dots.x.push_back(k);
    dots.y.push_back(4.0);
  }
  chart.series = {band, line, dots};
  CHECK_TRUE(sdpslam::io::chart_has_data(chart));
  const sdpslam::io::Painter plain = sdpslam::io::plain_painter();
  std::string error;
  CHECK_TRUE_TEXT(plain.chart(dir + "/t.png", chart, &error), error.c_str());
  const DecodedPng d = decode(dir + "/t.png");
  LONGS_EQUAL(640, d.width);
  LONGS_EQUAL(320, d.height);
  LONGS_EQUAL(3, d.channels);
  int red = 0, orange = 0, grey = 0;
  for (std::size_t i = 0; i + 2 < d.px.size(); i += 3) {
    const int r = d.px[i], g = d.px[i + 1], b = d.px[i + 2];
    red += (r == 220 && g == 20 && b == 20) ? 1 : 0;
    orange += (r == 255 && g == 140 && b == 0) ? 1 : 0;
    grey += (r == 128 && g == 128 && b == 128) ? 1 : 0;
  }
  CHECK(red > 500);    // the line across the plot
  CHECK(orange >= 40); // one pixel per point
  CHECK(grey > 1000);  // the band
  const OccupancyImage m = small_map();
  sdpslam::io::MapFigure f;
  f.map = &m;
  CHECK_TRUE_TEXT(plain.map(dir + "/m.png", f, &error), error.c_str());
  CHECK(slurp(dir + "/m.png") == [&] {
    CHECK_TRUE(sdpslam::io::write_map_png(dir + "/far.png", m, {}, &error));
    return slurp(dir + "/far.png");
  }());
  f.map = nullptr;
  CHECK_FALSE(plain.map(dir + "/m.png", f, &error));
  STRCMP_CONTAINS("m.png", error.c_str());
}
