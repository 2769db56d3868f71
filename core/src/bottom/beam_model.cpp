#include "sdpslam/core/bottom/beam_model.h"

#include <cstring>

#include "sdpslam/core/det_math.h"

namespace sdpslam {
namespace {

// floor() to a cell index, clamped far outside any map so that int32 never overflows.
std::int32_t floor_cell(double v) {
  if (!(v > -1.0e9)) return -1000000000;
  if (!(v < 1.0e9)) return 1000000000;
  auto i = static_cast<std::int64_t>(v);
  if (static_cast<double>(i) > v) --i;
  return static_cast<std::int32_t>(i);
}

// f(ix, iy, last) for every cell from (x0, y0) to (x1, y1), as Bresenham steps; f returns
// false to stop early.
template <class F>
void trace_cells(std::int32_t x0, std::int32_t y0, std::int32_t x1, std::int32_t y1, F&& f) {
  const std::int64_t dx = x1 >= x0 ? static_cast<std::int64_t>(x1) - x0 : static_cast<std::int64_t>(x0) - x1;
  const std::int64_t dy = y1 >= y0 ? static_cast<std::int64_t>(y1) - y0 : static_cast<std::int64_t>(y0) - y1;
  const std::int32_t sx = x0 < x1 ? 1 : -1;
  const std::int32_t sy = y0 < y1 ? 1 : -1;
  std::int64_t err = dx - dy;
  std::int32_t x = x0;
  std::int32_t y = y0;
  // A beam is at most a few thousand cells long; the bound guards against garbage input.
  for (std::int64_t guard = 0; guard <= dx + dy + 1; ++guard) {
    const bool last = (x == x1 && y == y1);
    if (!f(x, y, last) || last) return;
    const std::int64_t e2 = 2 * err;
    if (e2 > -dy) {
      err -= dy;
      x += sx;
    }
    if (e2 < dx) {
      err += dx;
      y += sy;
    }
  }
}

inline double mantissa_and_exponent(double v, std::int64_t* exponent) {
  // v > 0 and normal: returns v scaled into [1, 2) and adds the removed power of two.
  std::uint64_t u;
  std::memcpy(&u, &v, sizeof u);
  const auto e = static_cast<std::int64_t>((u >> 52) & 0x7FFU);
  if (e == 0 || e == 0x7FF) return v;  // subnormal/inf: leave (cannot happen with floor > 0)
  *exponent += e - 1023;
  u = (u & 0x000FFFFFFFFFFFFFULL) | 0x3FF0000000000000ULL;
  std::memcpy(&v, &u, sizeof v);
  return v;
}

struct LaserFrame {
  double x_m, y_m, c, s;
};
LaserFrame laser_frame(const ScanRays& rays, const Pose2& robot) {
  const Pose2 laser = robot.compose(rays.laser_in_base);
  return LaserFrame{laser.x_m, laser.y_m, det::cos(laser.heading_rad), det::sin(laser.heading_rad)};
}

}  // namespace

void prepare_rays(const RangeScan& scan, ScanRays* out) {
  const std::uint32_t n = scan.beam_count <= capacity::kMaxBeams ? scan.beam_count : capacity::kMaxBeams;
  out->count = n;
  out->laser_in_base = scan.geometry.laser_in_base;
  for (std::uint32_t i = 0; i < n; ++i) {
    const double a = static_cast<double>(scan.beam_angle_rad(i));
    out->cos_a[i] = det::cos(a);
    out->sin_a[i] = det::sin(a);
    out->range_m[i] = scan.ranges_m[i];
    out->kind[i] = static_cast<std::uint8_t>(scan.classify(i));
  }
}

bool BeamModel::init(const BeamModelOptions& options, double resolution_m) {
  if (!(resolution_m > 0.0) || !(options.sigma_hit_m > 0.0) || !(options.window_m > 0.0) ||
      !(options.prior_hits > 0.0) || !(options.prior_misses > 0.0) ||
      !(options.unknown_stop_probability > 0.0 && options.unknown_stop_probability < 1.0) ||
      !(options.floor_likelihood > 0.0) || options.weight_beam_stride == 0U ||
      !(options.likelihood_temperature >= 1.0)) {
    return false;
  }
  options_ = options;
  resolution_m_ = resolution_m;
  for (std::uint32_t h = 0; h < kStopLutSide; ++h) {
    for (std::uint32_t m = 0; m < kStopLutSide; ++m) {
      stop_lut_[h * kStopLutSide + m] = (static_cast<double>(h) + options.prior_hits) /
                                        (static_cast<double>(h + m) + options.prior_hits + options.prior_misses);
    }
  }
  const double step = resolution_m / static_cast<double>(kGaussSubsteps);
  inv_gauss_step_ = 1.0 / step;
  const double span = options.window_m + 2.0 * resolution_m;
  double n = span / step + 2.0;
  if (n > static_cast<double>(kMaxGaussEntries)) n = static_cast<double>(kMaxGaussEntries);
  gauss_entries_ = static_cast<std::uint32_t>(n);
  const double norm = resolution_m / (options.sigma_hit_m * det::sqrt(2.0 * det::kPi));
  for (std::uint32_t i = 0; i < gauss_entries_; ++i) {
    const double e = static_cast<double>(i) * step / options.sigma_hit_m;
    gauss_lut_[i] = norm * det::exp(-0.5 * e * e);
  }
  return true;
}

double BeamModel::stop_probability(const CellObservation& c) const {
  std::uint32_t h = c.hits;
  std::uint32_t m = c.misses;
  if (h >= kStopLutSide || m >= kStopLutSide) {
    const std::uint32_t big = h > m ? h : m;
    h = h * (kStopLutSide - 1U) / big;
    m = m * (kStopLutSide - 1U) / big;
  }
  return stop_lut_[h * kStopLutSide + m];
}

double BeamModel::gauss_mass(double abs_error_m) const {
  const double idx = abs_error_m * inv_gauss_step_ + 0.5;
  if (!(idx < static_cast<double>(gauss_entries_))) return 0.0;
  return gauss_lut_[static_cast<std::uint32_t>(idx)];
}

double BeamModel::log_likelihood(const DpMap& map, NodeId particle, const ScanRays& rays, const Pose2& robot) const {
  return log_likelihood_strided(map, particle, rays, robot, options_.weight_beam_stride, nullptr);
}

double BeamModel::log_likelihood_strided(const DpMap& map, NodeId particle, const ScanRays& rays,
                                         const Pose2& robot, std::uint32_t stride, BeamScore* score) const {
  return likelihood(map, rays, robot, stride, score,
                    [&](std::int32_t ix, std::int32_t iy, CellObservation* obs) {
                      return map.lookup(particle, ix, iy, obs);
                    });
}

double BeamModel::log_likelihood_strided(ViewCache& view, const DpMap& map, const ScanRays& rays,
                                         const Pose2& robot, std::uint32_t stride, BeamScore* score) const {
  return likelihood(map, rays, robot, stride, score,
                    [&](std::int32_t ix, std::int32_t iy, CellObservation* obs) { return view.lookup(ix, iy, obs); });
}

template <class Lookup>
double BeamModel::likelihood(const DpMap& map, const ScanRays& rays, const Pose2& robot, std::uint32_t stride,
                             BeamScore* score, Lookup&& lookup) const {
  if (stride == 0U) stride = 1U;
  std::uint32_t beams = 0U;
  std::uint32_t known_beams = 0U;
  const LaserFrame lf = laser_frame(rays, robot);
  const double res = resolution_m_;
  const double inv_res = 1.0 / res;
  const double ox = map.options().origin_x_m;
  const double oy = map.options().origin_y_m;
  const double w = options_.window_m;
  const double unknown = options_.unknown_stop_probability;
  double prod = 1.0;
  std::int64_t exponent = 0;
  // On a torus map (DpMap::Options::wrap) a lookup is exact closer than half a window to
  // the square that holds the lineage's updates, so within half a window of the robot
  // (which is in that square). A longer reading would be judged against cells a window
  // away: it is left out, like a beam without return.
  const std::int32_t side = map.width_cells() < map.height_cells() ? map.width_cells() : map.height_cells();
  const double reach_m = map.wraps() ? 0.5 * res * static_cast<double>(side) : 1.0e300;
  for (std::uint32_t b = 0; b < rays.count; b += stride) {
    if (rays.kind[b] != static_cast<std::uint8_t>(RangeScan::Beam::kReturn)) continue;
    const double r = static_cast<double>(rays.range_m[b]);
    if (r + w > reach_m) continue;
    ++beams;
    bool known = false;
    const double dx = lf.c * rays.cos_a[b] - lf.s * rays.sin_a[b];
    const double dy = lf.s * rays.cos_a[b] + lf.c * rays.sin_a[b];
    const double d0 = r > w ? r - w : 0.0;
    const double d1 = r + w;
    const std::int32_t x0 = floor_cell((lf.x_m + d0 * dx - ox) * inv_res);
    const std::int32_t y0 = floor_cell((lf.y_m + d0 * dy - oy) * inv_res);
    const std::int32_t x1 = floor_cell((lf.x_m + d1 * dx - ox) * inv_res);
    const std::int32_t y1 = floor_cell((lf.y_m + d1 * dy - oy) * inv_res);
    double reach = 1.0;
    double like = 0.0;
    trace_cells(x0, y0, x1, y1, [&](std::int32_t ix, std::int32_t iy, bool) {
      CellObservation obs;
      const bool seen = lookup(ix, iy, &obs);
      known = known || seen;
      const double p = seen ? stop_probability(obs) : unknown;
      // Distance along the beam of the cell centre's projection.
      const double cx = ox + (static_cast<double>(ix) + 0.5) * res - lf.x_m;
      const double cy = oy + (static_cast<double>(iy) + 0.5) * res - lf.y_m;
      const double d = cx * dx + cy * dy;
      const double e = r > d ? r - d : d - r;
      like += reach * p * gauss_mass(e);
      reach *= 1.0 - p;
      return reach > 1e-6;
    });
    prod = mantissa_and_exponent(prod * (like + options_.floor_likelihood), &exponent);
    if (known) ++known_beams;
  }
  if (score != nullptr) {
    score->beams = beams;
    score->known_beams = known_beams;
  }
  const double ll = det::log(prod) + static_cast<double>(exponent) * det::kLn2;
  return ll / options_.likelihood_temperature;
}

// The cells update_map() traces: from the laser's cell to each beam's end cell.
struct BeamModel::Tracer {
  LaserFrame lf;
  double inv_res, ox, oy;
  double reach_m;
  std::int32_t lx, ly;
  Tracer(const BeamModel& m, const DpMap& map, const ScanRays& rays, const Pose2& robot, double reach)
      : lf(laser_frame(rays, robot)),
        inv_res(1.0 / m.resolution_m_),
        ox(map.options().origin_x_m),
        oy(map.options().origin_y_m),
        reach_m(reach < 0.0 ? 0.0 : (reach < m.options_.max_update_range_m ? reach : m.options_.max_update_range_m)),
        lx(floor_cell((lf.x_m - ox) * inv_res)),
        ly(floor_cell((lf.y_m - oy) * inv_res)) {}
  // Beam b's end cell and whether it is a hit; false iff the beam traces nothing.
  bool end_cell(const BeamModel& m, const ScanRays& rays, std::uint32_t b, std::int32_t* ex, std::int32_t* ey,
                bool* hit) const {
    double end_m;
    if (!m.traced_m(static_cast<RangeScan::Beam>(rays.kind[b]), static_cast<double>(rays.range_m[b]), reach_m, &end_m,
                    hit)) {
      return false;
    }
    const double dx = lf.c * rays.cos_a[b] - lf.s * rays.sin_a[b];
    const double dy = lf.s * rays.cos_a[b] + lf.c * rays.sin_a[b];
    *ex = floor_cell((lf.x_m + end_m * dx - ox) * inv_res);
    *ey = floor_cell((lf.y_m + end_m * dy - oy) * inv_res);
    return true;
  }
  // f(ix, iy, hit) for the cells of every traced beam, each beam from the laser's cell to
  // its end cell (hit: the end cell of a beam that ends in a hit); f returns false to
  // stop tracing that beam. beam_done() follows each traced beam's cells.
  template <class F, class Done>
  void each_cell(const BeamModel& m, const ScanRays& rays, F&& f, Done&& beam_done) const {
    for (std::uint32_t b = 0; b < rays.count; ++b) {
      std::int32_t ex;
      std::int32_t ey;
      bool hit;
      if (!end_cell(m, rays, b, &ex, &ey, &hit)) continue;
      trace_cells(lx, ly, ex, ey, [&](std::int32_t ix, std::int32_t iy, bool last) { return f(ix, iy, last && hit); });
      beam_done();
    }
  }
  template <class F>
  void each_cell(const BeamModel& m, const ScanRays& rays, F&& f) const {
    each_cell(m, rays, f, [] {});
  }
};

std::uint32_t BeamModel::update_map(DpMap& map, NodeId particle, const ScanRays& rays, const Pose2& robot,
                                    double reach_m, std::uint64_t* scratch) const {
  const Tracer t(*this, map, rays, robot, reach_m);
  std::uint32_t dropped = 0U;
  const DpMap::ViewScope view(map, particle);  // only this particle's add()s meanwhile
  const auto write = [&](std::int32_t ix, std::int32_t iy, std::uint16_t hits, std::uint16_t misses) {
    if (!map.add(particle, ix, iy, hits, misses)) dropped += static_cast<std::uint32_t>(hits) + misses;
  };
  // The near square: the largest odd square of cells around the laser's cell whose sums
  // (hits in the low, misses in the high 32 bits of a word) the scratch holds; none
  // without scratch. Bresenham moves each coordinate one way only, so a beam's cells in
  // the square are its first ones: pass 1 stops a beam where it leaves the square.
  static_assert(capacity::kMaxBeams <= 0xFFFFU, "a scan's writes to one cell must fit a DpMap::add()");
  const std::size_t words = scratch != nullptr ? marks_words(options_.max_update_range_m, resolution_m_) : 0U;
  std::int32_t side = 1;
  while (static_cast<std::size_t>(side + 2) * static_cast<std::size_t>(side + 2) <= words) side += 2;
  const std::int32_t half = words > 0U ? (side - 1) / 2 : -1;
  const auto in_near = [&](std::int32_t ix, std::int32_t iy) {
    const std::int64_t dx = static_cast<std::int64_t>(ix) - t.lx;
    const std::int64_t dy = static_cast<std::int64_t>(iy) - t.ly;
    return dx >= -half && dx <= half && dy >= -half && dy <= half;
  };
  // Both passes write in runs of distinct cells (DpMap::add_run(): their cell lists are
  // walked side by side), in the order one add() per cell would take.
  DpMap::CellAdd run[DpMap::kMaxRun];
  std::uint32_t queued = 0U;
  const auto flush = [&] {
    dropped += map.add_run(particle, run, queued);
    queued = 0U;
  };
  const auto queue = [&](std::int32_t ix, std::int32_t iy, std::uint16_t hits, std::uint16_t misses) {
    run[queued++] = DpMap::CellAdd{ix, iy, hits, misses};
    if (queued == DpMap::kMaxRun) flush();
  };
  // Pass 1: sum the near square's writes (a cell outside the map goes to add(), which
  // counts each such write), then write each cell once, row by row.
  if (half >= 0) {
    t.each_cell(*this, rays, [&](std::int32_t ix, std::int32_t iy, bool hit) {
      if (!in_near(ix, iy)) return false;
      if (!map.in_bounds(ix, iy)) {
        write(ix, iy, hit ? 1U : 0U, hit ? 0U : 1U);
      } else {
        const std::int64_t i = (static_cast<std::int64_t>(iy) - t.ly + half) * side + (ix - t.lx + half);
        scratch[i] += hit ? std::uint64_t{1} : std::uint64_t{1} << 32U;
      }
      return true;
    });
    for (std::int32_t y = 0; y < side; ++y) {
      for (std::int32_t x = 0; x < side; ++x) {
        std::uint64_t& sum = scratch[static_cast<std::int64_t>(y) * side + x];
        if (sum == 0U) continue;
        queue(t.lx - half + x, t.ly - half + y, static_cast<std::uint16_t>(sum & 0xFFFFFFFFU),
              static_cast<std::uint16_t>(sum >> 32U));
        sum = 0U;
      }
    }
    flush();
  }
  // Pass 2: every beam's cells beyond the square, one add() per cell, in runs of the
  // beam's cells (distinct: Bresenham never visits a cell twice).
  t.each_cell(
      *this, rays,
      [&](std::int32_t ix, std::int32_t iy, bool hit) {
        if (!in_near(ix, iy)) queue(ix, iy, hit ? 1U : 0U, hit ? 0U : 1U);
        return true;
      },
      flush);
  return dropped;
}

namespace {
// Cells from the laser's cell to the far edge of the square marks cover: a traced end
// cell lies within floor(end / cell) + 1 of it (floor_cell of both ends), +1 for
// floating-point rounding.
std::int32_t marks_half(double max_update_range_m, double resolution_m) {
  return static_cast<std::int32_t>(max_update_range_m / resolution_m) + 2;
}
}  // namespace

std::size_t BeamModel::marks_words(double max_update_range_m, double resolution_m) {
  if (!(max_update_range_m >= 0.0) || !(resolution_m > 0.0) || !(max_update_range_m / resolution_m < 1.0e5)) {
    return 0U;
  }
  const auto side = static_cast<std::size_t>(2 * marks_half(max_update_range_m, resolution_m) + 1);
  return (side * side + 63U) / 64U;
}

std::uint64_t BeamModel::cells_written(const DpMap& map, const ScanRays& rays, const Pose2& robot, double reach_m,
                                       NodeId into, std::uint64_t* marks) const {
  const Tracer t(*this, map, rays, robot, reach_m);
  const std::int32_t half = marks_half(options_.max_update_range_m, resolution_m_);
  const std::int64_t side = 2 * static_cast<std::int64_t>(half) + 1;
  std::uint64_t cells = 0U;
  t.each_cell(*this, rays, [&](std::int32_t ix, std::int32_t iy, bool) {
    const std::int64_t mx = static_cast<std::int64_t>(ix) - t.lx + half;
    const std::int64_t my = static_cast<std::int64_t>(iy) - t.ly + half;
    if (mx < 0 || my < 0 || mx >= side || my >= side) {
      ++cells;  // cannot happen (the square holds every traced cell); counted anyway
      return true;
    }
    const auto bit = static_cast<std::uint64_t>(my * side + mx);
    const std::uint64_t mask = std::uint64_t{1} << (bit & 63U);
    if ((marks[bit >> 6U] & mask) == 0U) {
      marks[bit >> 6U] |= mask;
      if (into == kNoNode || !map.owns(into, ix, iy)) ++cells;
    }
    return true;
  });
  std::memset(marks, 0, marks_words(options_.max_update_range_m, resolution_m_) * sizeof(std::uint64_t));
  return cells;
}

bool BeamModel::traced_m(RangeScan::Beam kind, double range_m, double reach_m, double* end_m, bool* hit) const {
  if (kind == RangeScan::Beam::kReturn) {
    *hit = range_m <= reach_m;
    *end_m = *hit ? range_m : reach_m;
    return true;
  }
  if (kind == RangeScan::Beam::kNoReturn && options_.no_return_free_m > 0.0) {
    *hit = false;
    *end_m = options_.no_return_free_m < reach_m ? options_.no_return_free_m : reach_m;
    return true;
  }
  return false;
}

std::uint64_t BeamModel::cells_bound(const ScanRays& rays, double reach_m) const {
  // Past k = beams / 8 the square grows faster than the beams' tails shrink ((2k + 1)^2
  // grows by 8k + 8, the tails by at most the number of beams), so the least is below.
  constexpr std::uint32_t kMaxK = capacity::kMaxBeams / 8U + 1U;
  // at_least[j]: beams tracing at least j cells (j = kMaxK + 1 counts all longer ones).
  std::uint32_t at_least[kMaxK + 2U] = {};
  std::uint64_t tail = 0U;  // sum over beams of cells - 1 (k = 0)
  for (std::uint32_t b = 0; b < rays.count; ++b) {
    double end_m;
    bool hit;
    if (!traced_m(static_cast<RangeScan::Beam>(rays.kind[b]), static_cast<double>(rays.range_m[b]), reach_m, &end_m,
                  &hit)) {
      continue;
    }
    const auto cells = static_cast<std::uint64_t>(end_m / resolution_m_) + 3U;
    tail += cells - 1U;
    ++at_least[cells < kMaxK + 1U ? cells : kMaxK + 1U];
  }
  for (std::uint32_t j = kMaxK + 1U; j > 0U; --j) at_least[j - 1U] += at_least[j];
  std::uint64_t best = 1U + tail;
  for (std::uint32_t k = 1U; k <= kMaxK; ++k) {
    tail -= at_least[k + 1U];  // each beam of at least k + 1 cells leaves one more inside
    const std::uint64_t side = 2U * std::uint64_t{k} + 1U;
    const std::uint64_t bound = side * side + tail;
    if (bound < best) best = bound;
  }
  return best;
}

}  // namespace sdpslam
