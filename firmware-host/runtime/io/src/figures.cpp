// The plain painter (figures.h): pictures without text, through libpng (map_image.h).
#include "sdpslam/io/figures.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace sdpslam::io {
namespace {

bool finite_point(const ChartSeries& s, std::size_t k) {
  return k < s.y.size() && std::isfinite(s.x[k]) && std::isfinite(s.y[k]) &&
         (s.style != ChartSeries::Style::kBand || (k < s.y_high.size() && std::isfinite(s.y_high[k])));
}

// The chart rasterised on an occupancy canvas (white, black axes, grey bands), the
// first line series as a path and the points as points of write_map_png().
bool plain_chart(const std::string& path, const Chart& chart, std::string* error) {
  constexpr std::uint32_t kW = 640U, kH = 320U, kMargin = 20U;
  double x0 = 0.0, x1 = 0.0, y0 = 0.0, y1 = 0.0;
  bool any = false;
  for (const ChartSeries& s : chart.series) {
    for (std::size_t k = 0; k < s.x.size(); ++k) {
      if (!finite_point(s, k)) continue;
      const double hi = s.style == ChartSeries::Style::kBand ? s.y_high[k] : s.y[k];
      if (!any) {
        x0 = x1 = s.x[k];
        y0 = std::min(0.0, s.y[k]);
        y1 = hi;
        any = true;
      }
      x0 = std::min(x0, s.x[k]);
      x1 = std::max(x1, s.x[k]);
      y0 = std::min(y0, s.y[k]);
      y1 = std::max(y1, hi);
    }
  }
  if (!(x1 > x0)) x1 = x0 + 1.0;
  if (!(y1 > y0)) y1 = y0 + 1.0;
  OccupancyImage img;
  img.width = kW;
  img.height = kH;
  img.resolution_m = 1.0;
  img.occupancy.assign(static_cast<std::size_t>(kW) * kH, 0.0F);
  auto put = [&img](long x, long y, float v) {
    if (x >= 0 && y >= 0 && x < static_cast<long>(kW) && y < static_cast<long>(kH)) {
      img.occupancy[static_cast<std::size_t>(y) * kW + static_cast<std::size_t>(x)] = v;
    }
  };
  for (std::uint32_t x = kMargin; x < kW - kMargin / 2U; ++x) put(static_cast<long>(x), kMargin, 1.0F);
  for (std::uint32_t y = kMargin; y < kH - kMargin / 2U; ++y) put(kMargin, static_cast<long>(y), 1.0F);
  const double sx = static_cast<double>(kW - 2U * kMargin) / (x1 - x0);
  const double sy = static_cast<double>(kH - 2U * kMargin) / (y1 - y0);
  auto u = [&](double x) { return kMargin + (x - x0) * sx; };
  auto v = [&](double y) { return kMargin + (y - y0) * sy; };  // row 0 is the bottom (y up)
  std::vector<StampedPose> line;
  std::vector<Pose2> points;
  bool line_taken = false;
  for (const ChartSeries& s : chart.series) {
    const bool take_line = s.style == ChartSeries::Style::kLine && !line_taken;
    for (std::size_t k = 0; k < s.x.size(); ++k) {
      if (!finite_point(s, k)) continue;
      if (s.style == ChartSeries::Style::kBand) {
        const auto col = static_cast<long>(u(s.x[k]));
        for (auto r = static_cast<long>(v(s.y[k])); r <= static_cast<long>(v(s.y_high[k])); ++r) put(col, r, 0.5F);
      } else if (s.style == ChartSeries::Style::kPoints) {
        points.push_back(Pose2{u(s.x[k]) + 0.5, v(s.y[k]) + 0.5, 0.0});
      } else if (take_line) {
        line.push_back(StampedPose{static_cast<std::int64_t>(k), Pose2{u(s.x[k]) + 0.5, v(s.y[k]) + 0.5, 0.0}});
      }
    }
    line_taken = line_taken || (take_line && !line.empty());
  }
  return write_map_png(path, img, line, points, error);
}

bool plain_map(const std::string& path, const MapFigure& f, std::string* error) {
  if (f.map == nullptr) {
    if (error != nullptr) *error = "cannot draw '" + path + "': no map";
    return false;
  }
  return write_map_png(path, *f.map, f.path_poses(), f.point_poses(), error);
}

}  // namespace

const std::vector<StampedPose>& MapFigure::path_poses() const {
  static const std::vector<StampedPose> kNone;
  return path != nullptr ? *path : kNone;
}

const std::vector<Pose2>& MapFigure::point_poses() const {
  static const std::vector<Pose2> kNone;
  return points != nullptr ? *points : kNone;
}

Painter plain_painter() { return Painter{plain_chart, plain_map}; }

bool chart_has_data(const Chart& chart) {
  for (const ChartSeries& s : chart.series) {
    for (std::size_t k = 0; k < s.x.size(); ++k) {
      if (finite_point(s, k)) return true;
    }
  }
  return false;
}

}  // namespace sdpslam::io
