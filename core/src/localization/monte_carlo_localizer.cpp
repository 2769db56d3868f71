#include "sdpslam/core/localization/monte_carlo_localizer.h"

#include "sdpslam/core/det_math.h"

namespace sdpslam {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kInfinity = 1.0e30;

void say(char* why, std::size_t n, const char* text) {
  if (why == nullptr || n == 0U) return;
  std::size_t i = 0U;
  for (; text[i] != '\0' && i + 1U < n; ++i) why[i] = text[i];
  why[i] = '\0';
}

// floor() for |v| < 2⁶², exact (det_math has no floor).
std::int64_t floor_int(double v) {
  const auto t = static_cast<std::int64_t>(v);
  return static_cast<double>(t) > v ? t - 1 : t;
}

bool in(double v, double lo, double hi) { return v >= lo && v <= hi; }  // false for NaN

bool map_valid(const LocalizerMap& m) {
  return m.cells != nullptr && m.width >= 2U && m.height >= 2U && m.width <= 65535U && m.height <= 65535U &&
         in(m.resolution_m, 1.0e-3, 10.0) && in(m.origin_x_m, -1.0e7, 1.0e7) && in(m.origin_y_m, -1.0e7, 1.0e7);
}

std::uint32_t count_cells(const LocalizerMap& m, std::uint8_t kind) {
  std::uint32_t n = 0U;
  const std::size_t cells = static_cast<std::size_t>(m.width) * m.height;
  for (std::size_t i = 0; i < cells; ++i) n += m.cells[i] == kind ? 1U : 0U;
  return n;
}

std::uint32_t bin_capacity_for(std::uint32_t max_particles) {
  std::uint32_t c = 16U;
  while (c < 2U * max_particles) c *= 2U;
  return c;
}

// One dimension of the exact squared Euclidean distance transform (Felzenszwalb &
// Huttenlocher 2012, Algorithm 1): d[q] = min_p ((q − p)² + f[p]) over n samples, with
// scratch v (n ints) and z (n + 1 doubles).
void distance_1d(const double* f, std::uint32_t n, double* d, std::uint32_t* v, double* z) {
  std::uint32_t k = 0U;
  v[0] = 0U;
  z[0] = -kInfinity;
  z[1] = kInfinity;
  for (std::uint32_t q = 1; q < n; ++q) {
    const double fq = f[q] + static_cast<double>(q) * static_cast<double>(q);
    for (;;) {
      const std::uint32_t p = v[k];
      const double s =
          (fq - (f[p] + static_cast<double>(p) * static_cast<double>(p))) / (2.0 * static_cast<double>(q) - 2.0 * p);
      if (s <= z[k] && k > 0U) {
        --k;
        continue;
      }
      if (s <= z[k]) {  // k == 0: q replaces the only parabola
        v[0] = q;
        z[0] = -kInfinity;
        z[1] = kInfinity;
        break;
      }
      ++k;
      v[k] = q;
      z[k] = s;
      z[k + 1U] = kInfinity;
      break;
    }
  }
  k = 0U;
  for (std::uint32_t q = 0; q < n; ++q) {
    while (z[k + 1U] < static_cast<double>(q)) ++k;
    const double dq = static_cast<double>(q) - static_cast<double>(v[k]);
    d[q] = dq * dq + f[v[k]];
  }
}

}  // namespace

bool LocalizerOptions::check(char* why, std::size_t n) const {
  const char* bad = nullptr;
  if (min_particles < 10U) bad = "min_particles: below 10";
  else if (max_particles < min_particles || max_particles > 1000000U) bad = "max_particles: not in [min_particles, 1000000]";
  else if (!(kld_error > 0.0 && kld_error < 1.0)) bad = "kld_error: not in (0, 1)";
  else if (!(kld_quantile_z > 0.0 && kld_quantile_z <= 10.0)) bad = "kld_quantile_z: not in (0, 10]";
  else if (!(kld_bin_xy_m > 0.0 && kld_bin_xy_m <= 10.0)) bad = "kld_bin_xy_m: not in (0, 10]";
  else if (!(kld_bin_theta_rad > 0.0 && kld_bin_theta_rad <= kPi)) bad = "kld_bin_theta_rad: not in (0, pi]";
  else if (!(sigma_hit_m > 0.0 && sigma_hit_m <= 5.0)) bad = "sigma_hit_m: not in (0, 5]";
  else if (!(z_hit > 0.0 && z_hit < 1.0)) bad = "z_hit: not in (0, 1)";
  else if (!(max_distance_m > 0.0 && max_distance_m <= 20.0)) bad = "max_distance_m: not in (0, 20]";
  else if (beams < 1U || beams > capacity::kMaxBeams) bad = "beams: not in [1, the beam capacity]";
  else if (independent_beams < 1U || independent_beams > beams) bad = "independent_beams: not in [1, beams]";
  else if (!in(update_min_travel_m, 0.0, 10.0)) bad = "update_min_travel_m: not in [0, 10]";
  else if (!in(update_min_turn_rad, 0.0, 10.0)) bad = "update_min_turn_rad: not in [0, 10]";
  else if (!in(recovery_alpha_slow, 0.0, 1.0) || !in(recovery_alpha_fast, 0.0, 1.0) ||
           (recovery_alpha_fast > 0.0 && !(recovery_alpha_slow < recovery_alpha_fast)))
    bad = "recovery_alpha_slow/fast: need 0 <= slow < fast <= 1 (or both 0)";
  if (bad == nullptr) {
    say(why, n, "");
    return true;
  }
  say(why, n, bad);
  return false;
}

std::size_t MonteCarloLocalizer::required_arena_bytes(const LocalizerOptions& o, const LocalizerMap& m) {
  if (!o.check(nullptr, 0U) || !map_valid(m)) return 0U;
  const std::size_t cells = static_cast<std::size_t>(m.width) * m.height;
  const std::size_t line = m.width > m.height ? m.width : m.height;
  const std::size_t p = o.max_particles;
  return Arena::bytes_for<std::uint8_t>(cells) + 2U * Arena::bytes_for<Pose2>(p) + 2U * Arena::bytes_for<double>(p) +
         Arena::bytes_for<std::uint64_t>(bin_capacity_for(o.max_particles)) + 3U * Arena::bytes_for<double>(line + 1U) +
         Arena::bytes_for<std::uint32_t>(line);
}

bool MonteCarloLocalizer::init(const LocalizerOptions& o, const LocalizerMap& m, Arena& arena, std::uint64_t seed,
                               char* why, std::size_t n) {
  initialised_ = false;
  if (!o.check(why, n)) return false;
  if (!map_valid(m)) {
    say(why, n, "map: no cells, a side outside [2, 65535] cells, or a resolution/origin out of range");
    return false;
  }
  options_ = o;
  motion_ = MotionModel(o.motion);
  rng_.reseed(seed);
  width_ = m.width;
  height_ = m.height;
  res_m_ = m.resolution_m;
  origin_x_m_ = m.origin_x_m;
  origin_y_m_ = m.origin_y_m;
  stats_ = LocalizerStats{};
  stats_.free_cells = count_cells(m, LocalizerMap::kFree);
  stats_.occupied_cells = count_cells(m, LocalizerMap::kOccupied);
  if (stats_.free_cells == 0U || stats_.occupied_cells == 0U) {
    say(why, n, "map: no free or no occupied cell to localize in");
    return false;
  }
  const std::size_t cells = static_cast<std::size_t>(width_) * height_;
  const std::uint32_t line = width_ > height_ ? width_ : height_;
  bin_capacity_ = bin_capacity_for(o.max_particles);
  field_ = arena.allocate_array<std::uint8_t>(cells);
  pose_ = arena.allocate_array<Pose2>(o.max_particles);
  next_ = arena.allocate_array<Pose2>(o.max_particles);
  log_w_ = arena.allocate_array<double>(o.max_particles);
  cumulative_ = arena.allocate_array<double>(o.max_particles);
  bins_ = arena.allocate_array<std::uint64_t>(bin_capacity_);
  double* f = arena.allocate_array<double>(line + 1U);
  double* d = arena.allocate_array<double>(line + 1U);
  double* z = arena.allocate_array<double>(line + 1U);
  std::uint32_t* v = arena.allocate_array<std::uint32_t>(line);
  if (field_ == nullptr || pose_ == nullptr || next_ == nullptr || log_w_ == nullptr ||
      cumulative_ == nullptr || bins_ == nullptr || f == nullptr || d == nullptr || z == nullptr || v == nullptr) {
    say(why, n, "arena: too small for this map and max_particles (required_arena_bytes)");
    return false;
  }
  // Distance to the nearest occupied cell, columns then rows (distance_1d), in field_
  // itself: after the columns a cell holds its distance in cells along its column (an
  // integer), clamped at the field's reach (at most kReachCells: beyond 5 σ the model is
  // flat anyway); a clamped term is still at least the reach, so the rows' minimum is
  // exact wherever it is below it.
  const std::int64_t want = floor_int(o.max_distance_m / res_m_) + 2;
  const double reach = static_cast<double>(want < kReachCells ? want : kReachCells);
  const double reach_sq = reach * reach;
  constexpr double kFar = 1.0e20;  // "no occupied cell": finite, so the parabolas stay defined
  for (std::uint32_t c = 0; c < width_; ++c) {
    for (std::uint32_t r = 0; r < height_; ++r) {
      f[r] = m.cells[static_cast<std::size_t>(r) * width_ + c] == LocalizerMap::kOccupied ? 0.0 : kFar;
    }
    distance_1d(f, height_, d, v, z);
    for (std::uint32_t r = 0; r < height_; ++r) {
      const double g = d[r] < reach_sq ? det::sqrt(d[r]) : reach;  // d is a square of an integer here
      field_[static_cast<std::size_t>(r) * width_ + c] = static_cast<std::uint8_t>(g);
    }
  }
  // log p(beam ends here) = log(z_hit · N(d; 0, σ) + (1 − z_hit) / (2 · reach)) with d
  // clamped at max_distance_m (Table 6.3; the uniform part spread over the field's reach,
  // so that both terms are densities in 1/m), kept as one of kLevels steps between its
  // floor (at max_distance_m) and its peak (on a wall), plus the free-cell bit.
  const double sigma = o.sigma_hit_m;
  const double norm = 1.0 / (det::sqrt(2.0 * kPi) * sigma);
  const double rand_density = (1.0 - o.z_hit) / (2.0 * o.max_distance_m);
  auto log_p = [&](double dist_m) {
    if (dist_m > o.max_distance_m) dist_m = o.max_distance_m;
    return det::log(o.z_hit * norm * det::exp(-0.5 * dist_m * dist_m / (sigma * sigma)) + rand_density);
  };
  log_floor_ = log_p(o.max_distance_m);
  log_step_ = (log_p(0.0) - log_floor_) / static_cast<double>(kLevels - 1U);
  for (std::uint32_t r = 0; r < height_; ++r) {
    std::uint8_t* row = field_ + static_cast<std::size_t>(r) * width_;
    for (std::uint32_t c = 0; c < width_; ++c) f[c] = static_cast<double>(row[c]) * static_cast<double>(row[c]);
    distance_1d(f, width_, d, v, z);
    for (std::uint32_t c = 0; c < width_; ++c) {
      const double dist_m = det::sqrt(d[c] < reach_sq ? d[c] : reach_sq) * res_m_;
      const auto level = static_cast<double>(floor_int((log_p(dist_m) - log_floor_) / log_step_ + 0.5));
      const auto q = static_cast<std::uint8_t>(level < 0.0 ? 0.0 : (level > kLevels - 1.0 ? kLevels - 1.0 : level));
      const bool free = m.cells[static_cast<std::size_t>(r) * width_ + c] == LocalizerMap::kFree;
      row[c] = static_cast<std::uint8_t>(q | (free ? kFreeBit : 0U));
    }
  }
  count_ = 0U;
  have_update_ = false;
  w_slow_ = w_fast_ = 0.0;
  initialised_ = true;
  say(why, n, "");
  return true;
}

double MonteCarloLocalizer::log_field(double x_m, double y_m) const {
  const double cx = (x_m - origin_x_m_) / res_m_;
  const double cy = (y_m - origin_y_m_) / res_m_;
  if (!(cx >= 0.0 && cy >= 0.0 && cx < static_cast<double>(width_) && cy < static_cast<double>(height_))) {
    return log_floor_;
  }
  const std::uint8_t v =
      field_[static_cast<std::size_t>(static_cast<std::uint32_t>(cy)) * width_ + static_cast<std::uint32_t>(cx)];
  return log_floor_ + static_cast<double>(v & static_cast<std::uint8_t>(~kFreeBit)) * log_step_;
}

// A uniform free cell: rejection sampling over the map (free cells are a good share of
// any building's map), then, after kTries misses, the first free cell from the last one
// drawn (init made sure there is one).
Pose2 MonteCarloLocalizer::random_free_pose() {
  constexpr std::uint32_t kTries = 64U;
  const std::size_t cells = static_cast<std::size_t>(width_) * height_;
  auto cell = static_cast<std::size_t>(rng_.below(static_cast<std::uint32_t>(cells)));
  for (std::uint32_t t = 1; t < kTries && (field_[cell] & kFreeBit) == 0U; ++t) {
    cell = static_cast<std::size_t>(rng_.below(static_cast<std::uint32_t>(cells)));
  }
  while ((field_[cell] & kFreeBit) == 0U) cell = cell + 1U < cells ? cell + 1U : 0U;
  const double cx = static_cast<double>(cell % width_) + rng_.uniform();
  const double cy = static_cast<double>(cell / width_) + rng_.uniform();
  ++stats_.random_particles;
  return Pose2{origin_x_m_ + cx * res_m_, origin_y_m_ + cy * res_m_, normalize_angle_rad((2.0 * rng_.uniform() - 1.0) * kPi)};
}

void MonteCarloLocalizer::start_at(const Pose2& pose, double sigma_xy_m, double sigma_theta_rad) {
  if (!initialised_) return;
  count_ = options_.min_particles;
  for (std::uint32_t i = 0; i < count_; ++i) {
    pose_[i] = Pose2{pose.x_m + rng_.gaussian(sigma_xy_m), pose.y_m + rng_.gaussian(sigma_xy_m),
                     normalize_angle_rad(pose.heading_rad + rng_.gaussian(sigma_theta_rad))};
  }
  have_update_ = false;
  estimate_ = pose;
  spread_m_ = det::sqrt(2.0) * sigma_xy_m;
  w_slow_ = w_fast_ = 0.0;
}

void MonteCarloLocalizer::start_global() {
  if (!initialised_) return;
  count_ = options_.max_particles;
  for (std::uint32_t i = 0; i < count_; ++i) pose_[i] = random_free_pose();
  have_update_ = false;
  summarise();
  w_slow_ = w_fast_ = 0.0;
}

// log p(z | x, m) of `beams` beams evenly spread over the scan (Table 6.3), per particle;
// the average per-beam likelihood feeds augmented MCL's averages.
void MonteCarloLocalizer::weigh(const RangeScan& scan) {
  const std::uint32_t n = scan.beam_count;
  const std::uint32_t want = options_.beams < n ? options_.beams : n;
  // Beam end points in the robot frame, then per particle one field lookup each.
  double end_x[capacity::kMaxBeams];
  double end_y[capacity::kMaxBeams];
  std::uint32_t used = 0U;
  for (std::uint32_t j = 0; j < want; ++j) {
    const std::uint32_t b = static_cast<std::uint32_t>((static_cast<std::uint64_t>(j) * n) / want);
    if (scan.classify(b) != RangeScan::Beam::kReturn) continue;  // no return, invalid: not weighed (as AMCL)
    const double r = static_cast<double>(scan.ranges_m[b]);
    const double a = static_cast<double>(scan.beam_angle_rad(b));
    const Pose2 end = scan.geometry.laser_in_base.compose(Pose2{r * det::cos(a), r * det::sin(a), 0.0});
    end_x[used] = end.x_m;
    end_y[used] = end.y_m;
    ++used;
  }
  stats_.beams_weighed += static_cast<std::uint64_t>(used) * count_;
  for (std::uint32_t i = 0; i < count_; ++i) {
    const Pose2& p = pose_[i];
    const double c = det::cos(p.heading_rad), s = det::sin(p.heading_rad);
    double ll = 0.0;
    for (std::uint32_t k = 0; k < used; ++k) {
      ll += log_field(p.x_m + c * end_x[k] - s * end_y[k], p.y_m + s * end_x[k] + c * end_y[k]);
    }
    log_w_[i] = ll;
  }
  const double scale = used > options_.independent_beams
                           ? static_cast<double>(options_.independent_beams) / static_cast<double>(used)
                           : 1.0;
  for (std::uint32_t i = 0; i < count_; ++i) log_w_[i] *= scale;
  // Augmented MCL's measure of how well the belief explains the scan: the per-beam
  // (geometric mean) likelihood of each particle, averaged with the particles' weights.
  // Thrun's plain average over the set would count the random particles of a recovery
  // as the belief and drop further because of them, asking for more.
  if (used > 0U) {
    double max = -kInfinity;
    for (std::uint32_t i = 0; i < count_; ++i) max = log_w_[i] > max ? log_w_[i] : max;
    double sw = 0.0, fit = 0.0;
    for (std::uint32_t i = 0; i < count_; ++i) {
      const double w = det::exp(log_w_[i] - max);
      sw += w;
      fit += w * det::exp(log_w_[i] / (scale * static_cast<double>(used)));
    }
    fit /= sw;
    if (w_slow_ == 0.0) w_slow_ = w_fast_ = fit;
    w_slow_ += options_.recovery_alpha_slow * (fit - w_slow_);
    w_fast_ += options_.recovery_alpha_fast * (fit - w_fast_);
  }
}

// The estimate: the weighed set's heaviest mode — of the neighbourhoods (kModeRadiusM,
// kModeTurnRad) of the kModeCandidates heaviest particles, the one holding the most
// weight, and the weighted mean of its particles (a distant cluster, such as random
// particles of a recovery that found a similar place, neither drags the pose between the
// two nor wins by one lucky particle) — and the spread of the whole weighed set about it
// (a multimodal set shows as a large spread). Before any scan, all particles count alike.
void MonteCarloLocalizer::summarise() {
  if (count_ == 0U) return;
  constexpr double kModeRadiusM = 1.0;
  constexpr double kModeTurnRad = 0.5;
  constexpr std::uint32_t kModeCandidates = 8U;
  double max = -kInfinity;
  for (std::uint32_t i = 0; i < count_; ++i) max = log_w_[i] > max ? log_w_[i] : max;
  const auto near = [&](const Pose2& p, const Pose2& q) {
    const double dx = p.x_m - q.x_m, dy = p.y_m - q.y_m;
    const double dt = normalize_angle_rad(p.heading_rad - q.heading_rad);
    return dx * dx + dy * dy <= kModeRadiusM * kModeRadiusM && dt <= kModeTurnRad && dt >= -kModeTurnRad;
  };
  // The candidates: the heaviest particles, each outside the others' neighbourhoods.
  std::uint32_t candidate[kModeCandidates] = {};
  std::uint32_t candidates = 0U;
  double floor = kInfinity;  // weight of the lightest candidate while the list is full
  for (std::uint32_t i = 0; i < count_; ++i) {
    if (candidates == kModeCandidates && !(log_w_[i] > floor)) continue;
    bool merged = false;
    for (std::uint32_t c = 0; c < candidates && !merged; ++c) {
      if (near(pose_[i], pose_[candidate[c]])) {
        if (log_w_[i] > log_w_[candidate[c]]) candidate[c] = i;
        merged = true;
      }
    }
    if (!merged) {
      if (candidates < kModeCandidates) {
        candidate[candidates++] = i;
      } else {
        std::uint32_t lightest = 0U;
        for (std::uint32_t c = 1; c < candidates; ++c) lightest = log_w_[candidate[c]] < log_w_[candidate[lightest]] ? c : lightest;
        candidate[lightest] = i;
      }
    }
    if (candidates == kModeCandidates) {
      floor = kInfinity;
      for (std::uint32_t c = 0; c < candidates; ++c) floor = log_w_[candidate[c]] < floor ? log_w_[candidate[c]] : floor;
    }
  }
  std::uint32_t best = candidate[0];
  double best_mass = -1.0;
  for (std::uint32_t c = 0; c < candidates; ++c) {
    double mass = 0.0;
    for (std::uint32_t i = 0; i < count_; ++i) {
      if (near(pose_[i], pose_[candidate[c]])) mass += det::exp(log_w_[i] - max);
    }
    if (mass > best_mass) {
      best_mass = mass;
      best = candidate[c];
    }
  }
  const bool weighed = have_update_ && max > -kInfinity;
  auto weight = [&](std::uint32_t i) { return weighed ? det::exp(log_w_[i] - max) : 1.0; };
  const Pose2 peak = pose_[best];
  double sw = 0.0, sx = 0.0, sy = 0.0, sc = 0.0, ss = 0.0;
  for (std::uint32_t i = 0; i < count_; ++i) {
    const Pose2& p = pose_[i];
    if (weighed && !near(p, peak)) continue;
    const double w = weight(i);
    sw += w;
    sx += w * p.x_m;
    sy += w * p.y_m;
    sc += w * det::cos(p.heading_rad);
    ss += w * det::sin(p.heading_rad);
  }
  const double mx = sx / sw, my = sy / sw;
  double var = 0.0, total = 0.0;
  for (std::uint32_t i = 0; i < count_; ++i) {
    const double w = weight(i);
    const double dx = pose_[i].x_m - mx, dy = pose_[i].y_m - my;
    total += w;
    var += w * (dx * dx + dy * dy);
  }
  estimate_ = Pose2{mx, my, det::atan2(ss, sc)};
  spread_m_ = det::sqrt(var / total);
}

// KLD-sampling (Fox 2003, Table 8.4) from the weighed set, with augmented MCL's random
// particles (Table 8.3): each new particle is, with probability max(0, 1 − w_fast/w_slow),
// a random free pose, otherwise a draw from the weights; drawing stops once the set is
// large enough for the number k of histogram bins it occupies:
//   n ≥ (k − 1)/(2ε) · (1 − 2/(9(k − 1)) + √(2/(9(k − 1))) z)³.
void MonteCarloLocalizer::resample() {
  double max = -kInfinity;
  for (std::uint32_t i = 0; i < count_; ++i) max = log_w_[i] > max ? log_w_[i] : max;
  double total = 0.0;
  for (std::uint32_t i = 0; i < count_; ++i) {
    total += det::exp(log_w_[i] - max);
    cumulative_[i] = total;
  }
  if (!(total > 0.0) || !(max > -kInfinity)) {
    ++stats_.degenerate_weights;
    for (std::uint32_t i = 0; i < count_; ++i) cumulative_[i] = static_cast<double>(i + 1U);
    total = static_cast<double>(count_);
  }
  // Random particles only once the belief explains the scans at most half as well as it
  // has over the long run (a per-beam likelihood halved: about 0.7 nats per beam, far
  // beyond the fit's swing from a clean corridor to a cluttered room), in proportion to
  // how far below that it fell: 1 − 2 w_fast / w_slow.
  const double inject =
      (options_.recovery_alpha_fast > 0.0 && w_slow_ > 0.0) ? 1.0 - 2.0 * w_fast_ / w_slow_ : 0.0;
  for (std::uint32_t b = 0; b < bin_capacity_; ++b) bins_[b] = 0U;
  // The bin table has room for 2 × max_particles keys and each draw adds at most one.
  std::uint32_t bins = 0U;
  std::uint32_t drawn = 0U;
  const auto cell = [](double v, double size) {
    return static_cast<std::uint64_t>(floor_int(v / size) + (1LL << 20)) & 0x1FFFFFU;
  };
  for (;;) {
    Pose2 p;
    if (inject > 0.0 && rng_.uniform() < inject) {
      p = random_free_pose();
    } else {
      const double u = rng_.uniform() * total;
      std::uint32_t lo = 0U, hi = count_ - 1U;  // the first i with cumulative_[i] > u
      while (lo < hi) {
        const std::uint32_t mid = lo + (hi - lo) / 2U;
        if (cumulative_[mid] > u) hi = mid;
        else lo = mid + 1U;
      }
      p = pose_[lo];
    }
    next_[drawn++] = p;
    const std::uint64_t key = ((cell(p.x_m, options_.kld_bin_xy_m) << 42) | (cell(p.y_m, options_.kld_bin_xy_m) << 21) |
                               cell(p.heading_rad + kPi, options_.kld_bin_theta_rad)) + 1U;
    std::uint32_t slot = static_cast<std::uint32_t>((key * 0x9E3779B97F4A7C15ULL) >> 40) & (bin_capacity_ - 1U);
    while (bins_[slot] != 0U && bins_[slot] != key) slot = (slot + 1U) & (bin_capacity_ - 1U);
    if (bins_[slot] == 0U) {
      bins_[slot] = key;
      ++bins;
    }
    if (drawn >= options_.max_particles) {
      ++stats_.kld_capped;
      break;
    }
    if (drawn < options_.min_particles || bins <= 1U) {
      if (drawn >= options_.min_particles) break;  // one bin: the floor is enough
      continue;
    }
    const double k1 = static_cast<double>(bins - 1U);
    const double a = 2.0 / (9.0 * k1);
    const double b = 1.0 - a + det::sqrt(a) * options_.kld_quantile_z;
    if (static_cast<double>(drawn) >= k1 / (2.0 * options_.kld_error) * b * b * b) break;
  }
  Pose2* t = pose_;
  pose_ = next_;
  next_ = t;
  count_ = drawn;
}

MonteCarloLocalizer::Step MonteCarloLocalizer::update(const OdometrySample& odom, const RangeScan& scan) {
  Step step;
  ++stats_.scans;
  if (!initialised_ || count_ == 0U) {
    step.pose = estimate_;
    return step;
  }
  const Pose2 delta = between(odom_at_update_, odom.pose);
  const double travel = det::sqrt(delta.x_m * delta.x_m + delta.y_m * delta.y_m);
  const double turn = delta.heading_rad < 0.0 ? -delta.heading_rad : delta.heading_rad;
  if (have_update_ && travel < options_.update_min_travel_m && turn < options_.update_min_turn_rad) {
    step.pose = estimate_.compose(delta);
    step.spread_m = spread_m_;
    return step;
  }
  if (have_update_) {
    for (std::uint32_t i = 0; i < count_; ++i) pose_[i] = motion_.sample(pose_[i], delta, rng_);
  }
  odom_at_update_ = odom.pose;
  weigh(scan);
  have_update_ = true;
  summarise();
  resample();
  ++stats_.filter_updates;
  step.updated = true;
  step.pose = estimate_;
  step.spread_m = spread_m_;
  return step;
}

}  // namespace sdpslam
