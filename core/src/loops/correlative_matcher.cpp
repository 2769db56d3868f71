#include "sdpslam/core/loops/correlative_matcher.h"

#include "sdpslam/core/det_math.h"

namespace sdpslam {

namespace {

bool finite_point(const Point2& p) {
  return p.x_m == p.x_m && p.y_m == p.y_m && p.x_m > -1.0e6 && p.x_m < 1.0e6 && p.y_m > -1.0e6 && p.y_m < 1.0e6;
}

std::int32_t floor_cell(double v) {
  const std::int32_t i = static_cast<std::int32_t>(v);
  return (static_cast<double>(i) > v) ? i - 1 : i;
}

}  // namespace

bool CorrelativeOptions::valid() const {
  return resolution_m >= 0.01 && resolution_m <= 1.0 && kernel_sigma_m >= 0.5 * resolution_m && kernel_sigma_m <= 2.0 &&
         coarse_cells >= 1U && coarse_cells <= 16U && window_xy_m >= 0.0 && window_xy_m <= 50.0 &&
         window_theta_rad >= 0.0 && window_theta_rad <= det::kPi && min_score > 0.0 && min_score <= 1.0 &&
         min_overlap_points >= 1U &&
         max_ambiguity > 0.0 && max_ambiguity <= 1.0 && distinct_m >= 0.0 && distinct_rad >= 0.0 && candidates >= 1U &&
         candidates <= kMaxCandidates && window_xy_m / resolution_m <= 5000.0;
}

std::size_t CorrelativeMatcher::required_bytes(std::uint32_t max_grid_side, std::uint32_t max_points,
                                               std::uint32_t max_steps) {
  const std::size_t cells = static_cast<std::size_t>(max_grid_side) * max_grid_side;
  return 2U * Arena::bytes_for<std::uint8_t>(cells) + Arena::bytes_for<std::int32_t>(2U * std::size_t{max_points}) +
         Arena::bytes_for<std::uint32_t>(static_cast<std::size_t>(max_steps) * max_steps);
}

std::uint32_t CorrelativeMatcher::steps_for(double window_xy_m, double resolution_m, std::uint32_t coarse_cells) {
  return 2U * static_cast<std::uint32_t>(window_xy_m / (resolution_m * static_cast<double>(coarse_cells)) + 0.999999) + 1U;
}

bool CorrelativeMatcher::init(std::uint32_t max_grid_side, std::uint32_t max_points, std::uint32_t max_steps,
                              Arena& arena) {
  if (max_grid_side == 0U || max_points == 0U || max_steps == 0U) return false;
  const std::size_t cells = static_cast<std::size_t>(max_grid_side) * max_grid_side;
  fine_ = arena.allocate_array<std::uint8_t>(cells);
  pooled_ = arena.allocate_array<std::uint8_t>(cells);
  cells_ = arena.allocate_array<std::int32_t>(2U * std::size_t{max_points});
  sums_ = arena.allocate_array<std::uint32_t>(static_cast<std::size_t>(max_steps) * max_steps);
  if (fine_ == nullptr || pooled_ == nullptr || cells_ == nullptr || sums_ == nullptr) return false;
  max_blocks_ = static_cast<std::size_t>(max_steps) * max_steps;
  max_side_ = max_grid_side;
  max_points_ = max_points;
  return true;
}

// Calls f(cell index) for each placed source point that the offset (dx, dy) puts on the grid.
template <class F>
void CorrelativeMatcher::visit_on_grid(std::int32_t dx, std::int32_t dy, std::uint32_t n, F&& f) const {
  const std::int32_t w = static_cast<std::int32_t>(w_);
  const std::int32_t h = static_cast<std::int32_t>(h_);
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::int32_t x = cells_[2U * i] + dx;
    const std::int32_t y = cells_[2U * i + 1U] + dy;
    if (x < 0 || y < 0 || x >= w || y >= h) continue;
    f(static_cast<std::size_t>(y) * w_ + static_cast<std::size_t>(x));
  }
}

std::uint32_t CorrelativeMatcher::score_at(const std::uint8_t* grid, std::int32_t dx, std::int32_t dy,
                                           std::uint32_t n) const {
  std::uint32_t s = 0U;
  visit_on_grid(dx, dy, n, [&](std::size_t cell) { s += grid[cell]; });
  return s;
}

std::uint32_t CorrelativeMatcher::on_grid(std::int32_t dx, std::int32_t dy, std::uint32_t n) const {
  std::uint32_t k = 0U;
  visit_on_grid(dx, dy, n, [&](std::size_t) { ++k; });
  return k;
}

bool CorrelativeMatcher::begin(const Point2* target, std::uint32_t target_count, const Point2* source,
                               std::uint32_t source_count, const Pose2& guess, const CorrelativeOptions& o) {
  active_ = false;
  CorrelativeResult& res = result_;
  res = CorrelativeResult{};
  res.transform = guess;
  if (!o.valid() || fine_ == nullptr || (target == nullptr && target_count > 0U) ||
      (source == nullptr && source_count > 0U) || !finite_point(Point2{guess.x_m, guess.y_m}) ||
      !(guess.heading_rad == guess.heading_rad)) {
    return false;
  }
  if (target_count < 3U || source_count < 3U) {
    res.status = CorrelativeResult::Status::kTooFewPoints;
    return false;
  }
  if (source_count > max_points_) {
    res.status = CorrelativeResult::Status::kTooManyPoints;
    return false;
  }
  // Target grid: bounds of the target plus the kernel's reach.
  double x0 = target[0].x_m, x1 = x0, y0 = target[0].y_m, y1 = y0;
  for (std::uint32_t i = 0; i < target_count; ++i) {
    if (!finite_point(target[i])) return false;
    if (target[i].x_m < x0) x0 = target[i].x_m;
    if (target[i].x_m > x1) x1 = target[i].x_m;
    if (target[i].y_m < y0) y0 = target[i].y_m;
    if (target[i].y_m > y1) y1 = target[i].y_m;
  }
  double cx = 0.0, cy = 0.0;
  for (std::uint32_t i = 0; i < source_count; ++i) {
    if (!finite_point(source[i])) return false;
    cx += source[i].x_m;
    cy += source[i].y_m;
  }
  cx /= static_cast<double>(source_count);
  cy /= static_cast<double>(source_count);
  const double res_m = o.resolution_m;
  const std::int32_t reach = static_cast<std::int32_t>(3.0 * o.kernel_sigma_m / res_m) + 1;
  const double ox = x0 - static_cast<double>(reach + 1) * res_m;
  const double oy = y0 - static_cast<double>(reach + 1) * res_m;
  const double wide = (x1 - x0) / res_m + 2.0 * static_cast<double>(reach + 2);
  const double high = (y1 - y0) / res_m + 2.0 * static_cast<double>(reach + 2);
  if (wide > static_cast<double>(max_side_) || high > static_cast<double>(max_side_)) {
    res.status = CorrelativeResult::Status::kTooLarge;
    return false;
  }
  {
    const double q = o.window_xy_m / (res_m * static_cast<double>(o.coarse_cells)) + 0.999999;
    const std::size_t st = 2U * static_cast<std::size_t>(q) + 1U;
    if (st * st > max_blocks_) {
      res.status = CorrelativeResult::Status::kTooLarge;
      return false;
    }
  }
  w_ = static_cast<std::uint32_t>(wide);
  h_ = static_cast<std::uint32_t>(high);
  const std::size_t cells = static_cast<std::size_t>(w_) * h_;
  for (std::size_t i = 0; i < cells; ++i) fine_[i] = 0U;
  const double inv_2s2 = 1.0 / (2.0 * o.kernel_sigma_m * o.kernel_sigma_m);
  for (std::uint32_t i = 0; i < target_count; ++i) {
    const double gx = (target[i].x_m - ox) / res_m;
    const double gy = (target[i].y_m - oy) / res_m;
    const std::int32_t ix = floor_cell(gx);
    const std::int32_t iy = floor_cell(gy);
    for (std::int32_t dy = -reach; dy <= reach; ++dy) {
      const std::int32_t y = iy + dy;
      if (y < 0 || y >= static_cast<std::int32_t>(h_)) continue;
      for (std::int32_t dx = -reach; dx <= reach; ++dx) {
        const std::int32_t x = ix + dx;
        if (x < 0 || x >= static_cast<std::int32_t>(w_)) continue;
        const double ex = (static_cast<double>(x) + 0.5 - gx) * res_m;
        const double ey = (static_cast<double>(y) + 0.5 - gy) * res_m;
        const double v = 255.0 * det::exp(-(ex * ex + ey * ey) * inv_2s2);
        const std::uint8_t q = static_cast<std::uint8_t>(v + 0.5 > 255.0 ? 255.0 : v + 0.5);
        std::uint8_t& c = fine_[static_cast<std::size_t>(y) * w_ + static_cast<std::size_t>(x)];
        if (q > c) c = q;
      }
    }
  }
  // Max-pool over f × f towards +x, +y: rows, then columns, in place (cell i reads
  // cells i .. i+f-1, none of them written yet).
  const std::uint32_t f = o.coarse_cells;
  for (std::size_t i = 0; i < cells; ++i) pooled_[i] = fine_[i];
  for (std::uint32_t y = 0; y < h_; ++y) {
    std::uint8_t* row = pooled_ + static_cast<std::size_t>(y) * w_;
    for (std::uint32_t x = 0; x < w_; ++x) {
      for (std::uint32_t k = 1; k < f && x + k < w_; ++k) {
        if (row[x + k] > row[x]) row[x] = row[x + k];
      }
    }
  }
  for (std::uint32_t y = 0; y < h_; ++y) {
    for (std::uint32_t x = 0; x < w_; ++x) {
      std::uint8_t& m = pooled_[static_cast<std::size_t>(y) * w_ + x];
      for (std::uint32_t k = 1; k < f && y + k < h_; ++k) {
        const std::uint8_t v = pooled_[static_cast<std::size_t>(y + k) * w_ + x];
        if (v > m) m = v;
      }
    }
  }
  // Headings: one cell of motion at the farthest source point.
  double r2max = 0.0;
  for (std::uint32_t i = 0; i < source_count; ++i) {
    const double dx = source[i].x_m - cx;
    const double dy = source[i].y_m - cy;
    if (dx * dx + dy * dy > r2max) r2max = dx * dx + dy * dy;
  }
  double step_rad = r2max > res_m * res_m ? res_m / det::sqrt(r2max) : 0.1;
  std::uint32_t half = static_cast<std::uint32_t>(o.window_theta_rad / step_rad + 0.999999);
  if (2U * half + 1U > CorrelativeOptions::kMaxHeadings) half = (CorrelativeOptions::kMaxHeadings - 1U) / 2U;
  if (half > 0U) step_rad = o.window_theta_rad / static_cast<double>(half);
  options_ = o;
  source_ = source;
  source_count_ = source_count;
  guess_ = guess;
  cx_ = cx;
  cy_ = cy;
  guess.transform_point(cx, cy, gcx_, gcy_);  // where the guess puts the source centroid
  ox_ = ox;
  oy_ = oy;
  step_rad_ = step_rad;
  half_headings_ = half;
  headings_ = 2U * half + 1U;
  next_heading_ = 0U;
  nq_ = static_cast<std::int32_t>(o.window_xy_m / (res_m * static_cast<double>(f)) + 0.999999);
  steps_ = 2U * static_cast<std::uint32_t>(nq_) + 1U;
  nbest_ = 0U;
  active_ = true;
  return true;
}

double CorrelativeMatcher::heading_of(std::uint32_t k) const {
  return guess_.heading_rad + (static_cast<double>(k) - static_cast<double>(half_headings_)) * step_rad_;
}

void CorrelativeMatcher::place(std::uint32_t k) {
  const double th = heading_of(k);
  const double c = det::cos(th);
  const double s = det::sin(th);
  const double r = options_.resolution_m;
  for (std::uint32_t i = 0; i < source_count_; ++i) {
    const double dx = source_[i].x_m - cx_;
    const double dy = source_[i].y_m - cy_;
    cells_[2U * i] = floor_cell((gcx_ + c * dx - s * dy - ox_) / r);
    cells_[2U * i + 1U] = floor_cell((gcy_ + s * dx + c * dy - oy_) / r);
  }
}

std::uint64_t CorrelativeMatcher::heading_cost() const {
  return static_cast<std::uint64_t>(source_count_) * steps_ * steps_;
}

// Coarse pass over up to max_headings headings: the best `candidates` blocks by bound
// (ties: lower heading, dy, dx). Each point adds its pooled values to every block's
// sum, row by row over the offsets that stay inside the grid (no test per read).
bool CorrelativeMatcher::advance(std::uint32_t max_headings) {
  if (!active_) return true;
  const std::int32_t fs = static_cast<std::int32_t>(options_.coarse_cells);
  const std::int32_t nq = nq_;
  const std::int32_t nw = nq * fs;
  const std::uint32_t steps = steps_;
  const std::size_t blocks = static_cast<std::size_t>(steps) * steps;
  const std::uint32_t kmax = options_.candidates;
  const std::int32_t w = static_cast<std::int32_t>(w_);
  const std::int32_t h = static_cast<std::int32_t>(h_);
  const std::int32_t js = static_cast<std::int32_t>(steps);
  for (std::uint32_t done = 0; done < max_headings && next_heading_ < headings_; ++done) {
    const std::uint32_t k = next_heading_++;
    place(k);
    for (std::size_t b = 0; b < blocks; ++b) sums_[b] = 0U;
    for (std::uint32_t i = 0; i < source_count_; ++i) {
      const std::int32_t x = cells_[2U * i];
      const std::int32_t y = cells_[2U * i + 1U];
      // jx with 0 <= x + (jx - nq) f < w.
      const std::int32_t lo = nw - x > 0 ? (nw - x + fs - 1) / fs : 0;
      std::int32_t hi = w - 1 - x + nw >= 0 ? (w - 1 - x + nw) / fs : -1;
      if (hi > js - 1) hi = js - 1;
      if (lo > hi) continue;
      for (std::int32_t jy = 0; jy < js; ++jy) {
        const std::int32_t yy = y + (jy - nq) * fs;
        if (yy < 0 || yy >= h) continue;
        const std::ptrdiff_t base = static_cast<std::ptrdiff_t>(yy) * w + x - nw;
        std::uint32_t* out = sums_ + static_cast<std::size_t>(jy) * steps;
        for (std::int32_t jx = lo; jx <= hi; ++jx) out[jx] += pooled_[base + jx * fs];
      }
    }
    for (std::int32_t jy = 0; jy < js; ++jy) {
      for (std::int32_t jx = 0; jx < js; ++jx) {
        const std::uint32_t b = sums_[static_cast<std::size_t>(jy) * steps + static_cast<std::size_t>(jx)];
        ++result_.poses_scored;
        if (nbest_ == kmax && b <= best_[nbest_ - 1U].bound) continue;
        std::uint32_t pos = nbest_ < kmax ? nbest_ : kmax - 1U;
        while (pos > 0U && best_[pos - 1U].bound < b) {
          best_[pos] = best_[pos - 1U];
          --pos;
        }
        best_[pos] = Candidate{b, k, (jx - nq) * fs, (jy - nq) * fs};
        if (nbest_ < kmax) ++nbest_;
      }
    }
  }
  return next_heading_ >= headings_;
}

// Fine pass, best bound first, then the verdict.
CorrelativeResult CorrelativeMatcher::finish() {
  if (!active_) return result_;
  advance(0xFFFFFFFFU);
  active_ = false;
  const CorrelativeOptions& o = options_;
  const double res_m = o.resolution_m;
  const std::int32_t fs = static_cast<std::int32_t>(o.coarse_cells);
  const std::int32_t nw = nq_ * fs;
  CorrelativeResult& res = result_;
  struct Peak {
    std::uint32_t score;
    std::uint32_t heading;
    std::int32_t dx;
    std::int32_t dy;
  };
  Peak peaks[CorrelativeOptions::kMaxCandidates];
  std::uint32_t npeaks = 0U;
  std::uint32_t top = 0U;
  for (std::uint32_t c = 0; c < nbest_; ++c) {
    const Candidate& cand = best_[c];
    if (npeaks > 0U && static_cast<double>(cand.bound) < o.max_ambiguity * static_cast<double>(top)) break;
    place(cand.heading);
    Peak pk{0U, cand.heading, cand.dx, cand.dy};
    bool any = false;
    for (std::int32_t dy = cand.dy; dy < cand.dy + fs && dy <= nw; ++dy) {
      for (std::int32_t dx = cand.dx; dx < cand.dx + fs && dx <= nw; ++dx) {
        const std::uint32_t s = score_at(fine_, dx, dy, source_count_);
        ++res.poses_scored;
        if (!any || s > pk.score) {
          pk = Peak{s, cand.heading, dx, dy};
          any = true;
        }
      }
    }
    peaks[npeaks++] = pk;
    if (pk.score > top) top = pk.score;
  }
  if (npeaks == 0U) {
    res.status = CorrelativeResult::Status::kWeak;
    return res;
  }
  // The best peak (first in block order on ties), then the best distinct one.
  std::uint32_t ib = 0U;
  for (std::uint32_t i = 1; i < npeaks; ++i) {
    if (peaks[i].score > peaks[ib].score) ib = i;
  }
  const Peak& pb = peaks[ib];
  std::uint32_t second = 0U;
  for (std::uint32_t i = 0; i < npeaks; ++i) {
    const double ddx = static_cast<double>(peaks[i].dx - pb.dx) * res_m;
    const double ddy = static_cast<double>(peaks[i].dy - pb.dy) * res_m;
    const double dth =
        static_cast<double>(static_cast<std::int32_t>(peaks[i].heading) - static_cast<std::int32_t>(pb.heading)) * step_rad_;
    if (o.distinct(ddx, ddy, dth) && peaks[i].score > second) second = peaks[i].score;
  }
  // Pose: heading, then the translation that puts the centroid where the cells say.
  const double th = heading_of(pb.heading);
  const double c = det::cos(th);
  const double s = det::sin(th);
  const double tcx = gcx_ + static_cast<double>(pb.dx) * res_m;
  const double tcy = gcy_ + static_cast<double>(pb.dy) * res_m;
  res.transform = Pose2{tcx - (c * cx_ - s * cy_), tcy - (s * cx_ + c * cy_), normalize_angle_rad(th)};
  // Judged on the overlap: the source points the best pose puts on the target's grid.
  place(pb.heading);
  res.overlap_points = on_grid(pb.dx, pb.dy, source_count_);
  const double full = 255.0 * static_cast<double>(res.overlap_points > 0U ? res.overlap_points : 1U);
  res.score = static_cast<double>(pb.score) / full;
  res.second_score = static_cast<double>(second) / full;
  if (res.overlap_points < o.min_overlap_points || res.score < o.min_score) {
    res.status = CorrelativeResult::Status::kWeak;
  } else if (static_cast<double>(second) >= o.max_ambiguity * static_cast<double>(pb.score)) {
    res.status = CorrelativeResult::Status::kAmbiguous;
  } else {
    res.status = CorrelativeResult::Status::kFound;
  }
  return res;
}

CorrelativeResult CorrelativeMatcher::match(const Point2* target, std::uint32_t target_count, const Point2* source,
                                            std::uint32_t source_count, const Pose2& guess,
                                            const CorrelativeOptions& options) {
  if (!begin(target, target_count, source, source_count, guess, options)) return result_;
  return finish();
}

void CorrelativeMatcher::transfer_state(StateIo& io) {
  io.section("correlative");
  io.value(options_);  // the search in progress's
  io.value(result_);
  io.arena_pointer(source_, "loop search source points");
  io.value(source_count_);
  io.value(guess_);
  io.value(cx_);
  io.value(cy_);
  io.value(gcx_);
  io.value(gcy_);
  io.value(ox_);
  io.value(oy_);
  io.value(step_rad_);
  io.value(half_headings_);
  io.value(headings_);
  io.value(next_heading_);
  io.value(nq_);
  io.value(steps_);
  io.value(best_);
  io.value(nbest_);
  io.value(active_);
  io.value(w_);
  io.value(h_);
}

}  // namespace sdpslam
