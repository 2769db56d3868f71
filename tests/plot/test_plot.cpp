// tools/plot: 1-2-5 ticks, scale-bar lengths and tick labels; a chart and a map figure
// written, decoded back (libpng) and looked at: size, text where the title and the axis
// labels go, the series and the marks in their colours, the scale bar; no data, no map
// and an unwritable path are errors that name the file.
#include <CppUTest/TestHarness.h>
#include <png.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "sdpslam/io/figures.h"
#include "sdpslam/plot/plot.h"
#include "shared_data.h"

using namespace sdpslam;

namespace {

struct Rgb {
  std::uint32_t width = 0, height = 0;
  std::vector<std::uint8_t> px;  // RGB
  bool ok() const { return width > 0U; }
  const std::uint8_t* at(std::uint32_t x, std::uint32_t y) const { return &px[(static_cast<std::size_t>(y) * width + x) * 3U]; }
  // Pixels of the rectangle [x0, x1) × [y0, y1) within `tol` of the colour.
  int count(std::uint32_t x0, std::uint32_t y0, std::uint32_t x1, std::uint32_t y1, io::Rgb8 c, int tol) const {
    int n = 0;
    for (std::uint32_t y = y0; y < y1 && y < height; ++y) {
      for (std::uint32_t x = x0; x < x1 && x < width; ++x) {
        const std::uint8_t* p = at(x, y);
        if (std::abs(p[0] - c.r) <= tol && std::abs(p[1] - c.g) <= tol && std::abs(p[2] - c.b) <= tol) ++n;
      }
    }
    return n;
  }
  // Pixels whose red exceeds green and blue by 80 (the path, even where it is blended).
  int reddish(std::uint32_t x0, std::uint32_t y0, std::uint32_t x1, std::uint32_t y1) const {
    int n = 0;
    for (std::uint32_t y = y0; y < y1 && y < height; ++y) {
      for (std::uint32_t x = x0; x < x1 && x < width; ++x) {
        const std::uint8_t* p = at(x, y);
        if (p[0] > p[1] + 80 && p[0] > p[2] + 80) ++n;
      }
    }
    return n;
  }
  // Pixels darker than mid-grey: text and lines.
  int dark(std::uint32_t x0, std::uint32_t y0, std::uint32_t x1, std::uint32_t y1) const {
    return count(x0, y0, x1, y1, io::Rgb8{0, 0, 0}, 100);
  }
};

Rgb decode(const std::string& path) {
  Rgb d;
  png_image img;
  std::memset(&img, 0, sizeof img);
  img.version = PNG_IMAGE_VERSION;
  if (png_image_begin_read_from_file(&img, path.c_str()) == 0) return d;
  img.format = PNG_FORMAT_RGB;
  d.px.resize(PNG_IMAGE_SIZE(img));
  if (png_image_finish_read(&img, nullptr, d.px.data(), 0, nullptr) == 0) return Rgb{};
  d.width = img.width;
  d.height = img.height;
  return d;
}

io::Chart error_chart() {
  io::Chart c;
  c.title = "ICP error";
  c.x_label = "time (s)";
  c.y_label = "error (m)";
  io::ChartSeries band = io::ChartSeries::named("spread", io::Rgb8{0, 160, 0}, io::ChartSeries::Style::kBand);
  io::ChartSeries line = io::ChartSeries::named("mean", io::Rgb8{230, 0, 0});
  for (int k = 0; k <= 100; ++k) {
    const double t = k * 0.5;
    band.x.push_back(t);
    band.y.push_back(0.2);
    band.y_high.push_back(0.4);
    line.x.push_back(t);
    line.y.push_back(k == 50 ? std::nan("") : 0.3);  // a gap: left out, not drawn as 0
  }
  c.series = {band, line};
  return c;
}

// 40 m × 20 m at 0.1 m: free inside, walls around, unknown outside a border.
io::OccupancyImage room_map() {
  io::OccupancyImage m;
  m.width = 400;
  m.height = 200;
  m.resolution_m = 0.1;
  m.origin_x_m = -5.0;
  m.origin_y_m = -2.0;
  m.occupancy.assign(400U * 200U, -1.0F);
  for (std::uint32_t y = 20; y < 180; ++y) {
    for (std::uint32_t x = 20; x < 380; ++x) {
      const bool wall = x == 20 || x == 379 || y == 20 || y == 179;
      m.occupancy[y * 400U + x] = wall ? 1.0F : 0.0F;
    }
  }
  return m;
}

}  // namespace

TEST_GROUP(Plot) {
  std::string dir;
  void setup() override { dir = test::make_temp_dir("plot"); }
  void teardown() override {
    for (const char* f : {"/c.png", "/m.png", "/e.png"}) ::unlink((dir + f).c_str());
    ::rmdir(dir.c_str());
  }
};

TEST(Plot, ticks_are_one_two_five_steps_inside_the_range) {
  const std::vector<double> a = plot::nice_ticks(0.0, 1.0, 6);
  CHECK_EQUAL(6U, a.size());  // 0, 0.2, ... 1
  DOUBLES_EQUAL(0.0, a.front(), 1e-12);
  DOUBLES_EQUAL(0.2, a[1], 1e-12);
  DOUBLES_EQUAL(1.0, a.back(), 1e-12);
  const std::vector<double> b = plot::nice_ticks(3.0, 217.0, 10);  // step 50: 50 .. 200
  CHECK_EQUAL(4U, b.size());
  DOUBLES_EQUAL(50.0, b.front(), 1e-9);
  DOUBLES_EQUAL(200.0, b.back(), 1e-9);
  const std::vector<double> c = plot::nice_ticks(-0.37, 0.41, 8);  // step 0.2, through 0
  CHECK_EQUAL(4U, c.size());
  DOUBLES_EQUAL(-0.2, c.front(), 1e-12);
  DOUBLES_EQUAL(0.4, c.back(), 1e-12);
  for (const double t : c) CHECK(t >= -0.37 && t <= 0.41);
  CHECK_TRUE(plot::nice_ticks(1.0, 1.0, 5).empty());
  CHECK_TRUE(plot::nice_ticks(2.0, 1.0, 5).empty());
  CHECK_TRUE(plot::nice_ticks(0.0, std::nan(""), 5).empty());
  CHECK_TRUE(plot::nice_ticks(0.0, 1.0, 1).empty());
}

TEST(Plot, scale_bars_and_tick_labels_are_round) {
  DOUBLES_EQUAL(10.0, plot::nice_length(13.7), 1e-12);
  DOUBLES_EQUAL(5.0, plot::nice_length(9.99), 1e-12);
  DOUBLES_EQUAL(2.0, plot::nice_length(2.0), 1e-12);
  DOUBLES_EQUAL(0.5, plot::nice_length(0.7), 1e-12);
  DOUBLES_EQUAL(0.0, plot::nice_length(0.0), 0.0);
  DOUBLES_EQUAL(0.0, plot::nice_length(-1.0), 0.0);
  STRCMP_EQUAL("10", plot::tick_label(10.0, 5.0).c_str());
  STRCMP_EQUAL("0.2", plot::tick_label(0.2, 0.1).c_str());
  STRCMP_EQUAL("0.25", plot::tick_label(0.25, 0.25).c_str());
  STRCMP_EQUAL("0.0", plot::tick_label(-1e-17, 0.1).c_str());  // never "-0.0"
}

TEST(Plot, a_chart_has_its_title_axes_labels_series_and_legend) {
  std::string error;
  CHECK_TRUE_TEXT(plot::write_chart_png(dir + "/c.png", error_chart(), &error), error.c_str());
  const Rgb img = decode(dir + "/c.png");
  CHECK_TRUE(img.ok());
  CHECK_EQUAL(900U, img.width);
  CHECK_EQUAL(500U, img.height);
  CHECK(img.dark(300, 0, 600, 45) > 50);      // the title
  CHECK(img.dark(300, 470, 600, 500) > 50);   // the x label, under the tick labels
  CHECK(img.dark(0, 150, 30, 350) > 50);      // the y label, turned
  CHECK(img.dark(40, 60, 84, 420) > 50);      // the y tick labels
  // The line in its colour; the band as a light tint of its own (alpha 0.3 on white).
  CHECK(img.count(90, 50, 870, 430, io::Rgb8{230, 0, 0}, 40) > 500);
  CHECK(img.count(90, 50, 870, 430, io::Rgb8{179, 227, 179}, 20) > 5000);
  // No value is drawn at 0 for the gap: the bottom rows of the plot area stay white.
  CHECK_EQUAL(0, img.count(90, 420, 870, 434, io::Rgb8{230, 0, 0}, 60));
}

TEST(Plot, a_map_figure_has_its_map_path_marks_scale_bar_and_legend) {
  const io::OccupancyImage m = room_map();
  io::MapFigure f;
  f.title = "A room";
  f.map = &m;
  std::vector<io::StampedPose> path;
  for (int k = 0; k <= 200; ++k) path.push_back(io::StampedPose{k, Pose2{0.0 + 0.1 * k, 5.0, 0.0}});
  const std::vector<Pose2> points = {Pose2{20.0, 10.0, 0.0}, Pose2{20.1, 10.0, 0.0}};
  f.path = &path;
  f.points = &points;
  std::string error;
  CHECK_TRUE_TEXT(plot::write_map_figure_png(dir + "/m.png", f, &error), error.c_str());
  const Rgb img = decode(dir + "/m.png");
  CHECK_TRUE(img.ok());
  // 400 cells wide at one pixel per cell is narrower than the legend needs: the figure is
  // wider than the map, which is centred; 40 px title band, 60 px under the map.
  CHECK_EQUAL(560U, img.width);
  CHECK_EQUAL(40U + 200U + 60U, img.height);
  const std::uint32_t x0 = 80U;  // (560 - 400) / 2
  CHECK(img.dark(200, 0, 360, 38) > 30);                               // the title
  CHECK_EQUAL(0, img.count(x0 + 30, 40 + 30, x0 + 370, 40 + 150, io::Rgb8{0, 0, 0}, 10));  // free inside
  CHECK(img.count(x0 + 30, 40 + 179, x0 + 370, 40 + 180, io::Rgb8{0, 0, 0}, 10) > 300);    // the south wall (grid row 20)
  CHECK(img.reddish(x0, 40, x0 + 400, 240) > 150);  // the path: 20 m = 200 px
  // Start and end marks on the map, and again in the legend under it.
  CHECK(img.count(x0, 40, x0 + 400, 240, io::kFigureStartColour, 30) > 20);
  CHECK(img.count(x0, 40, x0 + 400, 240, io::kFigureEndColour, 30) > 20);
  CHECK(img.count(0, 240, 560, 300, io::kFigureStartColour, 30) > 20);
  CHECK(img.count(0, 240, 560, 300, io::kFigureEndColour, 30) > 20);
  CHECK(img.count(0, 240, 560, 300, io::kFigurePointColour, 30) > 5);
  // The scale bar: a quarter of 40 m is 10 m = 100 px of black line, with its label.
  CHECK(img.count(x0, 258, x0 + 110, 266, io::Rgb8{0, 0, 0}, 40) >= 100);
  CHECK(img.dark(x0 + 20, 268, x0 + 90, 285) > 10);
}

TEST(Plot, nothing_to_draw_is_an_error_that_names_the_file) {
  std::string error;
  io::Chart empty = error_chart();
  for (io::ChartSeries& s : empty.series) s.y.assign(s.y.size(), std::nan(""));
  CHECK_FALSE(plot::write_chart_png(dir + "/e.png", empty, &error));
  CHECK(error.find(dir + "/e.png") != std::string::npos);
  CHECK(::access((dir + "/e.png").c_str(), F_OK) != 0);
  CHECK_FALSE(io::chart_has_data(empty));
  io::MapFigure f;
  error.clear();
  CHECK_FALSE(plot::write_map_figure_png(dir + "/e.png", f, &error));
  CHECK(error.find(dir + "/e.png") != std::string::npos);
  error.clear();
  CHECK_FALSE(plot::write_chart_png(dir + "/no/such/dir/c.png", error_chart(), &error));
  CHECK(error.find("no/such/dir") != std::string::npos);
}

TEST(Plot, the_same_figure_gives_the_same_bytes) {
  std::string error;
  CHECK_TRUE(plot::write_chart_png(dir + "/c.png", error_chart(), &error));
  CHECK_TRUE(plot::write_chart_png(dir + "/e.png", error_chart(), &error));
  const Rgb a = decode(dir + "/c.png");
  const Rgb b = decode(dir + "/e.png");
  CHECK_TRUE(a.ok() && a.px == b.px);
}
