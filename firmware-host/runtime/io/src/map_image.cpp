// Occupancy map images (see map_image.h).
//
// ROS map_server convention (wiki.ros.org/map_server, "YAML format"): with negate = 0 a
// pixel value v reads back as occupancy p = (255 - v) / 255; p > occupied_thresh is
// occupied, p < free_thresh is free, anything between is unknown. Writing v = (1 - p)·255
// and 205 for unknown (p = 0.196, not below the default free_thresh) round-trips. With
// negate = 1 map_server reads p = v / 255, so the writer stores v = p·255 and unknown as
// 50 (= 255 - 205) to keep the same meaning. Image row 0 is the top (north) of the map,
// i.e. the grid's highest row.
#include "sdpslam/io/map_image.h"

#include <png.h>

#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "sdpslam/io/atomic_file.h"
#include "sdpslam/io/figures.h"

namespace sdpslam::io {
namespace {

constexpr std::uint8_t kUnknownPixel = 205;

// Grey value of one cell in the map_server convention (negate = 0).
std::uint8_t cell_to_pixel(float p, bool negate) {
  if (!(p >= 0.0F)) return negate ? static_cast<std::uint8_t>(255 - kUnknownPixel) : kUnknownPixel;  // <0 or NaN
  const double clamped = p > 1.0F ? 1.0 : static_cast<double>(p);
  const double v = negate ? clamped * 255.0 : (1.0 - clamped) * 255.0;
  return static_cast<std::uint8_t>(std::lround(v));
}

// Shortest decimal text that reads back to exactly `v` (YAML numbers).
std::string format_number(double v) {
  char buf[40];
  for (int precision = 15; precision <= 17; ++precision) {
    std::snprintf(buf, sizeof buf, "%.*g", precision, v);
    if (std::strtod(buf, nullptr) == v) break;
  }
  std::string s = buf;
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";  // keep it a float in YAML
  return s;
}

bool check_map(const std::string& path, const OccupancyImage& map, std::string* error) {
  std::string why;
  if (map.width == 0 || map.height == 0) {
    why = "map is empty (" + std::to_string(map.width) + " x " + std::to_string(map.height) + ")";
  } else if (map.occupancy.size() != static_cast<std::size_t>(map.width) * map.height) {
    why = "occupancy has " + std::to_string(map.occupancy.size()) + " cells, width x height is " +
          std::to_string(static_cast<std::size_t>(map.width) * map.height);
  } else if (!(map.resolution_m > 0.0) || !std::isfinite(map.resolution_m)) {
    why = "resolution must be a positive number of metres";
  } else if (!std::isfinite(map.origin_x_m) || !std::isfinite(map.origin_y_m)) {
    why = "origin is not finite";
  }
  if (why.empty()) return true;
  if (error != nullptr) *error = "cannot write '" + path + "': " + why;
  return false;
}

// Grey image, top row first.
std::vector<std::uint8_t> grey_pixels(const OccupancyImage& map, bool negate) {
  std::vector<std::uint8_t> px(map.occupancy.size());
  for (std::uint32_t r = 0; r < map.height; ++r) {
    const std::size_t src = static_cast<std::size_t>(map.height - 1U - r) * map.width;
    const std::size_t dst = static_cast<std::size_t>(r) * map.width;
    for (std::uint32_t c = 0; c < map.width; ++c) px[dst + c] = cell_to_pixel(map.occupancy[src + c], negate);
  }
  return px;
}

// ---- trajectory overlay ----------------------------------------------------------------

constexpr int kMarkerHalfSize = 2;  // markers are 5 x 5 pixel squares

class RgbCanvas {
 public:
  RgbCanvas(std::uint32_t w, std::uint32_t h, const std::vector<std::uint8_t>& grey)
      : w_(static_cast<long>(w)), h_(static_cast<long>(h)), px_(grey.size() * 3U) {
    for (std::size_t i = 0; i < grey.size(); ++i) px_[3 * i] = px_[3 * i + 1] = px_[3 * i + 2] = grey[i];
  }
  void put(long x, long y, Rgb8 c) {
    if (x < 0 || y < 0 || x >= w_ || y >= h_) return;
    const std::size_t i = 3U * (static_cast<std::size_t>(y) * static_cast<std::size_t>(w_) + static_cast<std::size_t>(x));
    px_[i] = c.r;
    px_[i + 1] = c.g;
    px_[i + 2] = c.b;
  }
  // Bresenham's line algorithm (integer, all octants) between two pixel centres.
  void line(long x0, long y0, long x1, long y1, Rgb8 c) {
    const long dx = std::labs(x1 - x0);
    const long dy = -std::labs(y1 - y0);
    const long sx = x0 < x1 ? 1 : -1;
    const long sy = y0 < y1 ? 1 : -1;
    long err = dx + dy;
    for (;;) {
      put(x0, y0, c);
      if (x0 == x1 && y0 == y1) break;
      const long e2 = 2 * err;
      if (e2 >= dy) {
        err += dy;
        x0 += sx;
      }
      if (e2 <= dx) {
        err += dx;
        y0 += sy;
      }
    }
  }
  void square(long x, long y, Rgb8 c) {
    for (long dy = -kMarkerHalfSize; dy <= kMarkerHalfSize; ++dy)
      for (long dx = -kMarkerHalfSize; dx <= kMarkerHalfSize; ++dx) put(x + dx, y + dy, c);
  }
  const std::vector<std::uint8_t>& pixels() const { return px_; }
  long width() const { return w_; }
  long height() const { return h_; }

 private:
  long w_, h_;
  std::vector<std::uint8_t> px_;
};

// Continuous image coordinates (x right, y down, pixel centres at +0.5) of a world point.
void world_to_image(const OccupancyImage& map, double x_m, double y_m, double* u, double* v) {
  *u = (x_m - map.origin_x_m) / map.resolution_m;
  *v = static_cast<double>(map.height) - (y_m - map.origin_y_m) / map.resolution_m;
}

// Liang–Barsky clip of the segment (u0,v0)-(u1,v1) to [-1, umax] x [-1, vmax] (one pixel
// beyond the image on every side); keeps Bresenham's loop bounded when a pose lies far outside the map.
bool clip_segment(double* u0, double* v0, double* u1, double* v1, double umax, double vmax) {
  const double lo = -1.0;
  double t0 = 0.0;
  double t1 = 1.0;
  const double du = *u1 - *u0;
  const double dv = *v1 - *v0;
  const double p[4] = {-du, du, -dv, dv};
  const double q[4] = {*u0 - lo, umax - *u0, *v0 - lo, vmax - *v0};
  for (int i = 0; i < 4; ++i) {
    if (p[i] == 0.0) {
      if (q[i] < 0.0) return false;
      continue;
    }
    const double t = q[i] / p[i];
    if (p[i] < 0.0) {
      if (t > t1) return false;
      if (t > t0) t0 = t;
    } else {
      if (t < t0) return false;
      if (t < t1) t1 = t;
    }
  }
  const double a_u = *u0 + t0 * du;
  const double a_v = *v0 + t0 * dv;
  *u1 = *u0 + t1 * du;
  *v1 = *v0 + t1 * dv;
  *u0 = a_u;
  *v0 = a_v;
  return true;
}

void draw_points(const OccupancyImage& map, const std::vector<Pose2>& points, RgbCanvas* canvas) {
  for (const Pose2& p : points) {
    if (!std::isfinite(p.x_m) || !std::isfinite(p.y_m)) continue;
    double u = 0.0;
    double v = 0.0;
    world_to_image(map, p.x_m, p.y_m, &u, &v);
    if (u < 0.0 || v < 0.0 || u >= static_cast<double>(canvas->width()) || v >= static_cast<double>(canvas->height())) {
      continue;
    }
    canvas->put(std::lround(std::floor(u)), std::lround(std::floor(v)), kFigurePointColour);
  }
}

void draw_trajectory(const OccupancyImage& map, const std::vector<StampedPose>& trajectory, RgbCanvas* canvas) {
  const double umax = static_cast<double>(canvas->width()) + 1.0;
  const double vmax = static_cast<double>(canvas->height()) + 1.0;
  bool have_prev = false;
  double pu = 0.0;
  double pv = 0.0;
  const StampedPose* first = nullptr;
  const StampedPose* last = nullptr;
  for (const StampedPose& sp : trajectory) {
    if (!std::isfinite(sp.pose.x_m) || !std::isfinite(sp.pose.y_m)) continue;
    double u = 0.0;
    double v = 0.0;
    world_to_image(map, sp.pose.x_m, sp.pose.y_m, &u, &v);
    if (first == nullptr) first = &sp;
    last = &sp;
    if (have_prev) {
      double u0 = pu, v0 = pv, u1 = u, v1 = v;
      if (clip_segment(&u0, &v0, &u1, &v1, umax, vmax)) {
        canvas->line(std::lround(std::floor(u0)), std::lround(std::floor(v0)), std::lround(std::floor(u1)),
                     std::lround(std::floor(v1)), kFigurePathColour);
      }
    }
    pu = u;
    pv = v;
    have_prev = true;
  }
  auto mark = [&](const StampedPose* sp, Rgb8 c) {
    if (sp == nullptr) return;
    double u = 0.0;
    double v = 0.0;
    world_to_image(map, sp->pose.x_m, sp->pose.y_m, &u, &v);
    if (u < -10.0 || v < -10.0 || u > umax + 10.0 || v > vmax + 10.0) return;
    canvas->square(std::lround(std::floor(u)), std::lround(std::floor(v)), c);
  };
  mark(last, kFigureEndColour);
  mark(first, kFigureStartColour);  // drawn last: a closed loop still shows where it began
}

// ---- PNG encoding in memory ------------------------------------------------------------

struct PngSink {
  std::string* bytes;
  char message[256];
  std::jmp_buf jump;
};

extern "C" void png_sink_write(png_structp png, png_bytep data, png_size_t length) {
  auto* sink = static_cast<PngSink*>(png_get_io_ptr(png));
  sink->bytes->append(reinterpret_cast<const char*>(data), length);
}
extern "C" void png_sink_flush(png_structp) {}
extern "C" void png_sink_error(png_structp png, png_const_charp msg) {
  auto* sink = static_cast<PngSink*>(png_get_error_ptr(png));
  std::snprintf(sink->message, sizeof sink->message, "%s", msg);
  std::longjmp(sink->jump, 1);
}
extern "C" void png_sink_warning(png_structp, png_const_charp) {}

// Only trivially destructible objects live between setjmp and a possible longjmp.
bool encode_png(std::uint32_t w, std::uint32_t h, int colour_type, png_bytepp rows, PngSink* sink) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, sink, png_sink_error, png_sink_warning);
  if (png == nullptr) {
    std::snprintf(sink->message, sizeof sink->message, "png_create_write_struct failed");
    return false;
  }
  png_infop info = png_create_info_struct(png);
  if (info == nullptr) {
    png_destroy_write_struct(&png, nullptr);
    std::snprintf(sink->message, sizeof sink->message, "png_create_info_struct failed");
    return false;
  }
  if (setjmp(sink->jump) != 0) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_set_write_fn(png, sink, png_sink_write, png_sink_flush);
  png_set_IHDR(png, info, w, h, 8, colour_type, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  png_write_image(png, rows);
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

}  // namespace

bool write_map_pgm_yaml(const std::string& stem, const OccupancyImage& map, const MapWriteOptions& options,
                        std::string* error) {
  const std::string pgm_path = stem + ".pgm";
  const std::string yaml_path = stem + ".yaml";
  if (!check_map(pgm_path, map, error)) return false;
  if (!(options.free_thresh >= 0.0 && options.free_thresh < options.occupied_thresh &&
        options.occupied_thresh <= 1.0)) {
    if (error != nullptr) {
      *error = "cannot write '" + yaml_path + "': thresholds must satisfy 0 <= free_thresh (" +
               format_number(options.free_thresh) + ") < occupied_thresh (" + format_number(options.occupied_thresh) +
               ") <= 1";
    }
    return false;
  }
  const std::vector<std::uint8_t> px = grey_pixels(map, options.negate);
  std::string pgm = "P5\n# sdpslam occupancy map, resolution " + format_number(map.resolution_m) + " m\n" +
                    std::to_string(map.width) + " " + std::to_string(map.height) + "\n255\n";
  pgm.append(reinterpret_cast<const char*>(px.data()), px.size());
  // The image first: the YAML names it, so a reader never finds a YAML without its image.
  if (!write_file_atomic(pgm_path, pgm, error)) return false;

  const std::size_t slash = pgm_path.find_last_of('/');
  const std::string image_name = slash == std::string::npos ? pgm_path : pgm_path.substr(slash + 1);
  const std::string yaml = "image: " + image_name + "\nresolution: " + format_number(map.resolution_m) +
                           "\norigin: [" + format_number(map.origin_x_m) + ", " + format_number(map.origin_y_m) +
                           ", 0.0]\nnegate: " + (options.negate ? "1" : "0") +
                           "\noccupied_thresh: " + format_number(options.occupied_thresh) +
                           "\nfree_thresh: " + format_number(options.free_thresh) + "\n";
  return write_file_atomic(yaml_path, yaml, error);
}

bool write_map_png(const std::string& path, const OccupancyImage& map, const std::vector<StampedPose>& trajectory,
                   std::string* error) {
  return write_map_png(path, map, trajectory, {}, error);
}

bool write_map_png(const std::string& path, const OccupancyImage& map, const std::vector<StampedPose>& trajectory,
                   const std::vector<Pose2>& points, std::string* error) {
  if (!check_map(path, map, error)) return false;
  std::vector<std::uint8_t> grey = grey_pixels(map, false);
  std::vector<std::uint8_t> rgb;
  const bool colour = !trajectory.empty() || !points.empty();
  if (colour) {
    RgbCanvas canvas(map.width, map.height, grey);
    draw_points(map, points, &canvas);
    draw_trajectory(map, trajectory, &canvas);
    rgb = canvas.pixels();
  }
  std::vector<std::uint8_t>& px = colour ? rgb : grey;
  const std::size_t stride = static_cast<std::size_t>(map.width) * (colour ? 3U : 1U);
  std::vector<png_bytep> rows(map.height);
  for (std::uint32_t r = 0; r < map.height; ++r) rows[r] = px.data() + static_cast<std::size_t>(r) * stride;

  std::string bytes;
  PngSink sink{};
  sink.bytes = &bytes;
  if (!encode_png(map.width, map.height, colour ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_GRAY, rows.data(), &sink)) {
    if (error != nullptr) *error = "cannot encode PNG '" + path + "': " + sink.message;
    return false;
  }
  return write_file_atomic(path, bytes, error);
}

}  // namespace sdpslam::io
