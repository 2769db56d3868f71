// Charts and map figures with cairo (plot.h).
#include "sdpslam/plot/plot.h"

#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>

#include "sdpslam/io/atomic_file.h"

// In sanitizer builds: fontconfig, which cairo's text goes through, keeps its
// configuration and font cache for the life of the process by design and never frees
// them; LeakSanitizer is told so here, for every program that draws figures.
#if defined(__SANITIZE_ADDRESS__)
#define SDPSLAM_PLOT_LSAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SDPSLAM_PLOT_LSAN 1
#endif
#endif
#ifdef SDPSLAM_PLOT_LSAN
extern "C" const char* __lsan_default_suppressions();
extern "C" const char* __lsan_default_suppressions() { return "leak:libfontconfig.so\n"; }
#endif

namespace sdpslam::plot {
namespace {

constexpr const char* kFont = "DejaVu Sans";
constexpr double kTitleSize = 17.0;
constexpr double kLabelSize = 13.0;
constexpr double kTickSize = 11.0;
constexpr int kMaxMapSidePx = 2400;  // larger maps are drawn scaled down
constexpr int kMinMapFigureWidthPx = 560;  // room for the scale bar and the legend

struct SurfaceDeleter {
  void operator()(cairo_surface_t* s) const { cairo_surface_destroy(s); }
};
struct ContextDeleter {
  void operator()(cairo_t* c) const { cairo_destroy(c); }
};
using Surface = std::unique_ptr<cairo_surface_t, SurfaceDeleter>;
using Context = std::unique_ptr<cairo_t, ContextDeleter>;

void colour(cairo_t* c, io::Rgb8 rgb, double alpha = 1.0) {
  cairo_set_source_rgba(c, rgb.r / 255.0, rgb.g / 255.0, rgb.b / 255.0, alpha);
}

void grey(cairo_t* c, double v) { cairo_set_source_rgb(c, v, v, v); }

void font(cairo_t* c, double size, bool bold = false) {
  cairo_select_font_face(c, kFont, CAIRO_FONT_SLANT_NORMAL, bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(c, size);
}

// Text at (x, y) aligned by ax (0 left, 0.5 centre, 1 right) and ay (0 top, 0.5
// middle, 1 baseline-bottom), optionally turned a quarter to the left (a y label).
void text(cairo_t* c, const std::string& s, double x, double y, double ax, double ay, bool vertical = false) {
  cairo_text_extents_t e;
  cairo_text_extents(c, s.c_str(), &e);
  cairo_save(c);
  cairo_translate(c, x, y);
  if (vertical) cairo_rotate(c, -M_PI / 2.0);
  cairo_move_to(c, -e.x_bearing - ax * e.width, -e.y_bearing - ay * e.height);
  cairo_show_text(c, s.c_str());
  cairo_restore(c);
}

double text_width(cairo_t* c, const std::string& s) {
  cairo_text_extents_t e;
  cairo_text_extents(c, s.c_str(), &e);
  return e.x_advance;
}

cairo_status_t append_png(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

bool write_png(cairo_surface_t* surface, const std::string& path, std::string* error) {
  cairo_surface_flush(surface);
  std::string bytes;
  cairo_status_t st = cairo_surface_status(surface);
  if (st == CAIRO_STATUS_SUCCESS) st = cairo_surface_write_to_png_stream(surface, append_png, &bytes);
  if (st != CAIRO_STATUS_SUCCESS) {
    if (error != nullptr) *error = "cannot draw '" + path + "': " + cairo_status_to_string(st);
    return false;
  }
  return io::write_file_atomic(path, bytes, error);
}

bool finite_point(const io::ChartSeries& s, std::size_t k) {
  return k < s.x.size() && k < s.y.size() && std::isfinite(s.x[k]) && std::isfinite(s.y[k]) &&
         (s.style != io::ChartSeries::Style::kBand || (k < s.y_high.size() && std::isfinite(s.y_high[k])));
}

// ---- chart ---------------------------------------------------------------------------

struct Range {
  double lo = 0.0;
  double hi = 0.0;
  bool any = false;
  void add(double v) {
    if (!any) {
      lo = hi = v;
      any = true;
    }
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
};

struct Axes {
  double left, top, width, height;  // the plot area (px)
  double x0, x1, y0, y1;            // its data range
  double u(double x) const { return left + (x - x0) / (x1 - x0) * width; }
  double v(double y) const { return top + height - (y - y0) / (y1 - y0) * height; }
};

// Each finite run of a band as one filled polygon: the upper edge forward, the lower back.
void draw_band(cairo_t* c, const Axes& a, const io::ChartSeries& s) {
  colour(c, s.colour, 0.3);
  std::size_t k = 0;
  while (k < s.x.size()) {
    while (k < s.x.size() && !finite_point(s, k)) ++k;
    const std::size_t first = k;
    while (k < s.x.size() && finite_point(s, k)) ++k;
    if (k == first) continue;
    cairo_move_to(c, a.u(s.x[first]), a.v(s.y_high[first]));
    for (std::size_t i = first + 1U; i < k; ++i) cairo_line_to(c, a.u(s.x[i]), a.v(s.y_high[i]));
    for (std::size_t i = k; i-- > first;) cairo_line_to(c, a.u(s.x[i]), a.v(s.y[i]));
    cairo_close_path(c);
    cairo_fill(c);
  }
}

void draw_line(cairo_t* c, const Axes& a, const io::ChartSeries& s) {
  colour(c, s.colour);
  cairo_set_line_width(c, 1.6);
  cairo_set_line_join(c, CAIRO_LINE_JOIN_ROUND);
  bool pen_down = false;
  for (std::size_t k = 0; k < s.x.size(); ++k) {
    if (!finite_point(s, k)) {
      pen_down = false;
      continue;
    }
    if (pen_down) {
      cairo_line_to(c, a.u(s.x[k]), a.v(s.y[k]));
    } else {
      cairo_move_to(c, a.u(s.x[k]), a.v(s.y[k]));
      pen_down = true;
    }
  }
  cairo_stroke(c);
}

void draw_points(cairo_t* c, const Axes& a, const io::ChartSeries& s) {
  colour(c, s.colour, 0.8);
  for (std::size_t k = 0; k < s.x.size(); ++k) {
    if (!finite_point(s, k)) continue;
    cairo_new_sub_path(c);
    cairo_arc(c, a.u(s.x[k]), a.v(s.y[k]), 1.8, 0.0, 2.0 * M_PI);
  }
  cairo_fill(c);
}

void legend_sample(cairo_t* c, const io::ChartSeries& s, double x, double y) {
  switch (s.style) {
    case io::ChartSeries::Style::kBand:
      colour(c, s.colour, 0.3);
      cairo_rectangle(c, x, y - 5.0, 22.0, 10.0);
      cairo_fill(c);
      break;
    case io::ChartSeries::Style::kPoints:
      colour(c, s.colour);
      cairo_arc(c, x + 11.0, y, 2.5, 0.0, 2.0 * M_PI);
      cairo_fill(c);
      break;
    case io::ChartSeries::Style::kLine:
      colour(c, s.colour);
      cairo_set_line_width(c, 2.0);
      cairo_move_to(c, x, y);
      cairo_line_to(c, x + 22.0, y);
      cairo_stroke(c);
      break;
  }
}

void draw_legend(cairo_t* c, const Axes& a, const io::Chart& chart) {
  font(c, kTickSize);
  double w = 0.0;
  int n = 0;
  for (const io::ChartSeries& s : chart.series) {
    if (s.label.empty()) continue;
    w = std::max(w, text_width(c, s.label));
    ++n;
  }
  if (n == 0) return;
  constexpr double kRow = 18.0;
  const double bw = 22.0 + 8.0 + w + 16.0;
  const double bh = kRow * n + 8.0;
  const double bx = a.left + a.width - bw - 8.0;
  const double by = a.top + 8.0;
  cairo_set_source_rgba(c, 1.0, 1.0, 1.0, 0.85);
  cairo_rectangle(c, bx, by, bw, bh);
  cairo_fill_preserve(c);
  grey(c, 0.6);
  cairo_set_line_width(c, 1.0);
  cairo_stroke(c);
  double y = by + 4.0 + kRow / 2.0;
  for (const io::ChartSeries& s : chart.series) {
    if (s.label.empty()) continue;
    legend_sample(c, s, bx + 8.0, y);
    grey(c, 0.1);
    text(c, s.label, bx + 8.0 + 22.0 + 8.0, y, 0.0, 0.5);
    y += kRow;
  }
}

}  // namespace

std::vector<double> nice_ticks(double lo, double hi, int max_count) {
  std::vector<double> ticks;
  if (!(std::isfinite(lo) && std::isfinite(hi) && hi > lo) || max_count < 2) return ticks;
  const double raw = (hi - lo) / (max_count - 1);
  double step = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * step >= raw) {
      step *= m;
      break;
    }
  }
  // The multiples of step in [lo, hi], counted in integers so that no error accumulates.
  const double first = std::ceil(lo / step - 1e-9);
  const double last = std::floor(hi / step + 1e-9);
  for (double k = first; k <= last; k += 1.0) ticks.push_back(k * step == 0.0 ? 0.0 : k * step);
  while (static_cast<int>(ticks.size()) > max_count) {  // rounding at the edges
    ticks.pop_back();
  }
  return ticks;
}

double nice_length(double max_value) {
  if (!(std::isfinite(max_value) && max_value > 0.0)) return 0.0;
  const double p = std::pow(10.0, std::floor(std::log10(max_value)));
  for (const double m : {5.0, 2.0, 1.0}) {
    if (m * p <= max_value * (1.0 + 1e-12)) return m * p;
  }
  return p;
}

std::string tick_label(double value, double step) {
  int decimals = 0;
  if (step > 0.0 && std::isfinite(step)) {
    decimals = static_cast<int>(std::ceil(-std::log10(step) - 1e-9));
    // 0.25, 2.5: a step of 2.5 × 10^k needs one decimal more.
    const double scaled = step * std::pow(10.0, decimals);
    if (std::fabs(scaled - std::round(scaled)) > 1e-6) ++decimals;
    decimals = std::clamp(decimals, 0, 9);
  }
  // Rounded first, so that a value that rounds to zero prints without a sign.
  const double unit = std::pow(10.0, decimals);
  double shown = std::round(value * unit) / unit;
  if (shown == 0.0 || !std::isfinite(shown)) shown = std::isfinite(value) ? 0.0 : value;
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, shown);
  return buf;
}

bool write_chart_png(const std::string& path, const io::Chart& chart, std::string* error) {
  constexpr int kW = 900, kH = 500;
  Range xr;
  Range yr;
  yr.add(0.0);
  for (const io::ChartSeries& s : chart.series) {
    for (std::size_t k = 0; k < s.x.size(); ++k) {
      if (!finite_point(s, k)) continue;
      xr.add(s.x[k]);
      yr.add(s.y[k]);
      if (s.style == io::ChartSeries::Style::kBand) yr.add(s.y_high[k]);
    }
  }
  if (!xr.any) {
    if (error != nullptr) *error = "cannot draw '" + path + "': the chart '" + chart.title + "' has no data";
    return false;
  }
  if (!(xr.hi > xr.lo)) xr.hi = xr.lo + 1.0;
  yr.hi += 0.05 * (yr.hi - yr.lo);
  if (!(yr.hi > yr.lo)) yr.hi = yr.lo + 1.0;

  Surface surface(cairo_image_surface_create(CAIRO_FORMAT_RGB24, kW, kH));
  Context ctx(cairo_create(surface.get()));
  cairo_t* c = ctx.get();
  cairo_set_source_rgb(c, 1.0, 1.0, 1.0);
  cairo_paint(c);

  const Axes a{86.0, 48.0, kW - 86.0 - 24.0, kH - 48.0 - 64.0, xr.lo, xr.hi, yr.lo, yr.hi};
  const std::vector<double> xt = nice_ticks(a.x0, a.x1, 10);
  const std::vector<double> yt = nice_ticks(a.y0, a.y1, 8);
  // Grid, then the data clipped to the plot area, then axes, ticks and text.
  cairo_set_line_width(c, 1.0);
  grey(c, 0.9);
  for (const double x : xt) {
    cairo_move_to(c, std::round(a.u(x)) + 0.5, a.top);
    cairo_line_to(c, std::round(a.u(x)) + 0.5, a.top + a.height);
  }
  for (const double y : yt) {
    cairo_move_to(c, a.left, std::round(a.v(y)) + 0.5);
    cairo_line_to(c, a.left + a.width, std::round(a.v(y)) + 0.5);
  }
  cairo_stroke(c);
  cairo_save(c);
  cairo_rectangle(c, a.left, a.top, a.width, a.height);
  cairo_clip(c);
  for (const io::ChartSeries& s : chart.series) {
    if (s.style == io::ChartSeries::Style::kBand) draw_band(c, a, s);
  }
  for (const io::ChartSeries& s : chart.series) {
    if (s.style == io::ChartSeries::Style::kPoints) draw_points(c, a, s);
  }
  for (const io::ChartSeries& s : chart.series) {
    if (s.style == io::ChartSeries::Style::kLine) draw_line(c, a, s);
  }
  cairo_restore(c);

  grey(c, 0.0);
  cairo_set_line_width(c, 1.0);
  cairo_rectangle(c, a.left + 0.5, a.top + 0.5, a.width - 1.0, a.height - 1.0);
  cairo_stroke(c);
  font(c, kTickSize);
  const double xstep = xt.size() > 1U ? xt[1] - xt[0] : 1.0;
  const double ystep = yt.size() > 1U ? yt[1] - yt[0] : 1.0;
  for (const double x : xt) {
    cairo_move_to(c, std::round(a.u(x)) + 0.5, a.top + a.height);
    cairo_line_to(c, std::round(a.u(x)) + 0.5, a.top + a.height + 5.0);
    cairo_stroke(c);
    text(c, tick_label(x, xstep), a.u(x), a.top + a.height + 8.0, 0.5, 0.0);
  }
  for (const double y : yt) {
    cairo_move_to(c, a.left - 5.0, std::round(a.v(y)) + 0.5);
    cairo_line_to(c, a.left, std::round(a.v(y)) + 0.5);
    cairo_stroke(c);
    text(c, tick_label(y, ystep), a.left - 8.0, a.v(y), 1.0, 0.5);
  }
  font(c, kLabelSize);
  text(c, chart.x_label, a.left + a.width / 2.0, kH - 12.0, 0.5, 1.0);
  text(c, chart.y_label, 18.0, a.top + a.height / 2.0, 0.5, 0.0, true);
  font(c, kTitleSize, true);
  text(c, chart.title, kW / 2.0, 14.0, 0.5, 0.0);
  draw_legend(c, a, chart);
  return write_png(surface.get(), path, error);
}

// ---- map -----------------------------------------------------------------------------

bool write_map_figure_png(const std::string& path, const io::MapFigure& f, std::string* error) {
  const io::OccupancyImage* m = f.map;
  if (m == nullptr || m->width == 0U || m->height == 0U ||
      m->occupancy.size() != static_cast<std::size_t>(m->width) * m->height || !(m->resolution_m > 0.0)) {
    if (error != nullptr) *error = "cannot draw '" + path + "': no map or an inconsistent one";
    return false;
  }
  const int mw = static_cast<int>(m->width);
  const int mh = static_cast<int>(m->height);
  const double scale = std::min(1.0, static_cast<double>(kMaxMapSidePx) / std::max(mw, mh));
  const int draw_w = std::max(1, static_cast<int>(std::lround(mw * scale)));
  const int draw_h = std::max(1, static_cast<int>(std::lround(mh * scale)));
  constexpr int kTop = 40;
  constexpr int kBottom = 60;
  constexpr int kSide = 12;
  const int fig_w = std::max(draw_w + 2 * kSide, kMinMapFigureWidthPx);
  const int fig_h = kTop + draw_h + kBottom;
  const double off_x = (fig_w - draw_w) / 2.0;
  const double off_y = kTop;

  // The map at one pixel per cell, grey as map_server reads it (unknown 205), north up: as
  // an 8-bit mask of darkness (255 - grey) that paints black over the white figure, which
  // gives the grey back exactly, in a quarter of an RGB raster's memory.
  Surface raster(cairo_image_surface_create(CAIRO_FORMAT_A8, mw, mh));
  if (cairo_surface_status(raster.get()) != CAIRO_STATUS_SUCCESS) {
    if (error != nullptr) *error = "cannot draw '" + path + "': " + cairo_status_to_string(cairo_surface_status(raster.get()));
    return false;
  }
  cairo_surface_flush(raster.get());
  unsigned char* px = cairo_image_surface_get_data(raster.get());
  const int stride = cairo_image_surface_get_stride(raster.get());
  for (int row = 0; row < mh; ++row) {
    unsigned char* out = px + static_cast<std::ptrdiff_t>(row) * stride;
    const std::size_t src = static_cast<std::size_t>(mh - 1 - row) * m->width;
    for (int col = 0; col < mw; ++col) {
      const float p = m->occupancy[src + static_cast<std::size_t>(col)];
      long g = 205;
      if (p >= 0.0F) g = std::lround((1.0 - std::min(1.0, static_cast<double>(p))) * 255.0);
      out[col] = static_cast<unsigned char>(255 - g);
    }
  }
  cairo_surface_mark_dirty(raster.get());

  Surface surface(cairo_image_surface_create(CAIRO_FORMAT_RGB24, fig_w, fig_h));
  Context ctx(cairo_create(surface.get()));
  cairo_t* c = ctx.get();
  cairo_set_source_rgb(c, 1.0, 1.0, 1.0);
  cairo_paint(c);
  cairo_save(c);
  cairo_translate(c, off_x, off_y);
  cairo_scale(c, static_cast<double>(draw_w) / mw, static_cast<double>(draw_h) / mh);
  cairo_set_source_rgb(c, 0.0, 0.0, 0.0);
  cairo_pattern_t* mask = cairo_pattern_create_for_surface(raster.get());
  cairo_pattern_set_filter(mask, scale < 1.0 ? CAIRO_FILTER_GOOD : CAIRO_FILTER_NEAREST);
  cairo_mask(c, mask);
  cairo_pattern_destroy(mask);
  cairo_restore(c);
  raster = Surface();  // the figure holds the map now

  const double px_per_m = static_cast<double>(draw_w) / (mw * m->resolution_m);
  auto u = [&](double x_m) { return off_x + (x_m - m->origin_x_m) * px_per_m; };
  auto v = [&](double y_m) { return off_y + draw_h - (y_m - m->origin_y_m) * px_per_m; };
  cairo_save(c);
  cairo_rectangle(c, off_x, off_y, draw_w, draw_h);
  cairo_clip(c);
  colour(c, io::kFigurePointColour, 0.8);
  for (const Pose2& p : f.point_poses()) {
    if (!std::isfinite(p.x_m) || !std::isfinite(p.y_m)) continue;
    cairo_rectangle(c, u(p.x_m) - 0.75, v(p.y_m) - 0.75, 1.5, 1.5);
  }
  cairo_fill(c);
  const io::StampedPose* first = nullptr;
  const io::StampedPose* last = nullptr;
  colour(c, io::kFigurePathColour);
  cairo_set_line_width(c, 1.4);
  cairo_set_line_join(c, CAIRO_LINE_JOIN_ROUND);
  for (const io::StampedPose& sp : f.path_poses()) {
    if (!std::isfinite(sp.pose.x_m) || !std::isfinite(sp.pose.y_m)) continue;
    if (first == nullptr) {
      cairo_move_to(c, u(sp.pose.x_m), v(sp.pose.y_m));
      first = &sp;
    } else {
      cairo_line_to(c, u(sp.pose.x_m), v(sp.pose.y_m));
    }
    last = &sp;
  }
  cairo_stroke(c);
  if (last != nullptr) {
    colour(c, io::kFigureEndColour);
    cairo_rectangle(c, u(last->pose.x_m) - 5.0, v(last->pose.y_m) - 5.0, 10.0, 10.0);
    cairo_fill(c);
  }
  if (first != nullptr) {  // drawn last: a closed loop still shows where it began
    colour(c, io::kFigureStartColour);
    cairo_arc(c, u(first->pose.x_m), v(first->pose.y_m), 5.5, 0.0, 2.0 * M_PI);
    cairo_fill(c);
  }
  cairo_restore(c);
  grey(c, 0.4);
  cairo_set_line_width(c, 1.0);
  cairo_rectangle(c, off_x - 0.5, off_y - 0.5, draw_w + 1.0, draw_h + 1.0);
  cairo_stroke(c);

  // Title, with the map's size and cell.
  char size[96];
  std::snprintf(size, sizeof size, "%.1f m x %.1f m, %.3g m per cell", mw * m->resolution_m, mh * m->resolution_m,
                m->resolution_m);
  grey(c, 0.0);
  font(c, kTitleSize - 2.0, true);
  text(c, f.title, fig_w / 2.0, 6.0, 0.5, 0.0);
  font(c, kTickSize);
  grey(c, 0.3);
  text(c, size, fig_w / 2.0, 26.0, 0.5, 0.0);

  // Scale bar: a 1-2-5 length up to a quarter of the map's width.
  const double bar_m = nice_length(0.25 * mw * m->resolution_m);
  const double bar_px = bar_m * px_per_m;
  const double by = off_y + draw_h + 22.0;
  const double bx = std::max(off_x, static_cast<double>(kSide));
  grey(c, 0.0);
  cairo_set_line_width(c, 2.0);
  cairo_move_to(c, bx, by);
  cairo_line_to(c, bx + bar_px, by);
  cairo_move_to(c, bx, by - 5.0);
  cairo_line_to(c, bx, by + 5.0);
  cairo_move_to(c, bx + bar_px, by - 5.0);
  cairo_line_to(c, bx + bar_px, by + 5.0);
  cairo_stroke(c);
  font(c, kTickSize);
  text(c, tick_label(bar_m, bar_m) + " m", bx + bar_px / 2.0, by + 9.0, 0.5, 0.0);

  // Legend: what the marks are.
  double lx = std::max(bx + bar_px + 36.0, bx + text_width(c, tick_label(bar_m, bar_m) + " m") + 36.0);
  const double ly = by;
  auto entry = [&](const std::string& label, int kind) {
    switch (kind) {
      case 0:
        colour(c, io::kFigurePathColour);
        cairo_set_line_width(c, 2.0);
        cairo_move_to(c, lx, ly);
        cairo_line_to(c, lx + 20.0, ly);
        cairo_stroke(c);
        break;
      case 1:
        colour(c, io::kFigureStartColour);
        cairo_arc(c, lx + 10.0, ly, 5.5, 0.0, 2.0 * M_PI);
        cairo_fill(c);
        break;
      case 2:
        colour(c, io::kFigureEndColour);
        cairo_rectangle(c, lx + 5.0, ly - 5.0, 10.0, 10.0);
        cairo_fill(c);
        break;
      default:
        colour(c, io::kFigurePointColour);
        cairo_rectangle(c, lx + 8.0, ly - 2.0, 4.0, 4.0);
        cairo_fill(c);
        break;
    }
    grey(c, 0.1);
    text(c, label, lx + 26.0, ly, 0.0, 0.5);
    lx += 26.0 + text_width(c, label) + 18.0;
  };
  if (!f.path_poses().empty()) {
    entry(f.path_label, 0);
    entry("start", 1);
    entry("end", 2);
  }
  if (!f.point_poses().empty()) entry(f.points_label, 3);
  grey(c, 0.3);
  text(c, "occupied: black, free: white, unknown: grey", fig_w - static_cast<double>(kSide), by + 24.0, 1.0, 0.0);
  return write_png(surface.get(), path, error);
}

io::Painter painter() { return io::Painter{write_chart_png, write_map_figure_png}; }

}  // namespace sdpslam::plot
