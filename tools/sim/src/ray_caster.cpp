#include "sdpslam/sim/ray_caster.h"

#include <algorithm>
#include <cmath>

namespace sdpslam::sim {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Distance t >= 0 at which the ray p + t*d crosses segment s, or +inf.
inline double intersect(const Segment& s, double px, double py, double dx, double dy) {
  const double ex = s.b.x_m - s.a.x_m;
  const double ey = s.b.y_m - s.a.y_m;
  const double denom = dx * ey - dy * ex;
  if (denom == 0.0) return kInf;
  const double ax = s.a.x_m - px;
  const double ay = s.a.y_m - py;
  const double t = (ax * ey - ay * ex) / denom;
  const double u = (ax * dy - ay * dx) / denom;
  constexpr double kTol = 1e-12;
  if (t < 0.0 || u < -kTol || u > 1.0 + kTol) return kInf;
  return t;
}

}  // namespace

RayCaster::RayCaster(const World& world, double cell_m) : segments_(world.segments) {
  if (segments_.empty()) return;
  double max_x = -kInf;
  double max_y = -kInf;
  min_x_ = kInf;
  min_y_ = kInf;
  for (const Segment& s : segments_) {
    min_x_ = std::min({min_x_, s.a.x_m, s.b.x_m});
    min_y_ = std::min({min_y_, s.a.y_m, s.b.y_m});
    max_x = std::max({max_x, s.a.x_m, s.b.x_m});
    max_y = std::max({max_y, s.a.y_m, s.b.y_m});
  }
  // A margin so that no wall lies on the grid's outer boundary.
  min_x_ -= 0.01;
  min_y_ -= 0.01;
  max_x += 0.01;
  max_y += 0.01;
  cell_m_ = cell_m > 0.0 ? cell_m : 0.5;
  constexpr double kMaxCells = 4.0e6;
  while ((max_x - min_x_) / cell_m_ * ((max_y - min_y_) / cell_m_) > kMaxCells) cell_m_ *= 2.0;
  nx_ = static_cast<std::uint32_t>(std::ceil((max_x - min_x_) / cell_m_));
  ny_ = static_cast<std::uint32_t>(std::ceil((max_y - min_y_) / cell_m_));
  nx_ = std::max<std::uint32_t>(nx_, 1U);
  ny_ = std::max<std::uint32_t>(ny_, 1U);

  auto cell_range = [&](const Segment& s, std::uint32_t* x0, std::uint32_t* x1, std::uint32_t* y0,
                        std::uint32_t* y1) {
    constexpr double kPad = 1e-9;
    auto cx = [&](double x) {
      const double c = std::floor((x - min_x_) / cell_m_);
      return static_cast<std::uint32_t>(std::clamp(c, 0.0, static_cast<double>(nx_ - 1U)));
    };
    auto cy = [&](double y) {
      const double c = std::floor((y - min_y_) / cell_m_);
      return static_cast<std::uint32_t>(std::clamp(c, 0.0, static_cast<double>(ny_ - 1U)));
    };
    *x0 = cx(std::min(s.a.x_m, s.b.x_m) - kPad);
    *x1 = cx(std::max(s.a.x_m, s.b.x_m) + kPad);
    *y0 = cy(std::min(s.a.y_m, s.b.y_m) - kPad);
    *y1 = cy(std::max(s.a.y_m, s.b.y_m) + kPad);
  };
  const std::size_t cells = static_cast<std::size_t>(nx_) * ny_;
  cell_start_.assign(cells + 1U, 0U);
  for (const Segment& s : segments_) {
    std::uint32_t x0 = 0, x1 = 0, y0 = 0, y1 = 0;
    cell_range(s, &x0, &x1, &y0, &y1);
    for (std::uint32_t y = y0; y <= y1; ++y)
      for (std::uint32_t x = x0; x <= x1; ++x) ++cell_start_[static_cast<std::size_t>(y) * nx_ + x + 1U];
  }
  for (std::size_t c = 0; c < cells; ++c) cell_start_[c + 1U] += cell_start_[c];
  cell_items_.resize(cell_start_[cells]);
  std::vector<std::uint32_t> fill(cell_start_.begin(), cell_start_.end() - 1);
  for (std::uint32_t i = 0; i < segments_.size(); ++i) {
    std::uint32_t x0 = 0, x1 = 0, y0 = 0, y1 = 0;
    cell_range(segments_[i], &x0, &x1, &y0, &y1);
    for (std::uint32_t y = y0; y <= y1; ++y)
      for (std::uint32_t x = x0; x <= x1; ++x) cell_items_[fill[static_cast<std::size_t>(y) * nx_ + x]++] = i;
  }
}

double RayCaster::cast_brute_force(double x_m, double y_m, double angle_rad, double max_range_m) const {
  const double dx = std::cos(angle_rad);
  const double dy = std::sin(angle_rad);
  double best = kInf;
  for (const Segment& s : segments_) best = std::min(best, intersect(s, x_m, y_m, dx, dy));
  return best <= max_range_m ? best : kInf;
}

double RayCaster::cast(double x_m, double y_m, double angle_rad, double max_range_m) const {
  if (segments_.empty()) return kInf;
  const double dx = std::cos(angle_rad);
  const double dy = std::sin(angle_rad);
  const double w = static_cast<double>(nx_) * cell_m_;
  const double h = static_cast<double>(ny_) * cell_m_;
  const double ox = x_m - min_x_;
  const double oy = y_m - min_y_;

  // Clip the ray to the grid's box (slab method); t_enter is where it enters the box.
  double t_enter = 0.0;
  double t_leave = max_range_m;
  auto slab = [&](double o, double d, double size) {
    if (d == 0.0) return o >= 0.0 && o <= size;
    double t0 = (0.0 - o) / d;
    double t1 = (size - o) / d;
    if (t0 > t1) std::swap(t0, t1);
    t_enter = std::max(t_enter, t0);
    t_leave = std::min(t_leave, t1);
    return t_enter <= t_leave;
  };
  if (!slab(ox, dx, w) || !slab(oy, dy, h)) return kInf;

  const double ex = ox + dx * t_enter;
  const double ey = oy + dy * t_enter;
  auto clamp_cell = [](double v, std::uint32_t n) {
    return static_cast<std::int64_t>(std::clamp(std::floor(v), 0.0, static_cast<double>(n - 1U)));
  };
  std::int64_t cx = clamp_cell(ex / cell_m_, nx_);
  std::int64_t cy = clamp_cell(ey / cell_m_, ny_);
  const std::int64_t step_x = dx > 0.0 ? 1 : -1;
  const std::int64_t step_y = dy > 0.0 ? 1 : -1;
  // Ray parameter t (from the original origin) at the next x / y cell boundary.
  double t_max_x = kInf;
  double t_max_y = kInf;
  if (dx != 0.0) {
    const double bx = static_cast<double>(cx + (step_x > 0 ? 1 : 0)) * cell_m_;
    t_max_x = (bx - ox) / dx;
  }
  if (dy != 0.0) {
    const double by = static_cast<double>(cy + (step_y > 0 ? 1 : 0)) * cell_m_;
    t_max_y = (by - oy) / dy;
  }
  const double t_delta_x = dx != 0.0 ? cell_m_ / std::fabs(dx) : kInf;
  const double t_delta_y = dy != 0.0 ? cell_m_ / std::fabs(dy) : kInf;

  double best = kInf;
  for (;;) {
    const std::size_t c = static_cast<std::size_t>(cy) * nx_ + static_cast<std::size_t>(cx);
    for (std::uint32_t k = cell_start_[c]; k < cell_start_[c + 1U]; ++k) {
      best = std::min(best, intersect(segments_[cell_items_[k]], x_m, y_m, dx, dy));
    }
    const double t_exit = std::min(t_max_x, t_max_y);
    if (best <= t_exit || t_exit > t_leave) break;
    if (t_max_x < t_max_y) {
      cx += step_x;
      t_max_x += t_delta_x;
      if (cx < 0 || cx >= static_cast<std::int64_t>(nx_)) break;
    } else {
      cy += step_y;
      t_max_y += t_delta_y;
      if (cy < 0 || cy >= static_cast<std::int64_t>(ny_)) break;
    }
  }
  return best <= max_range_m ? best : kInf;
}

}  // namespace sdpslam::sim
