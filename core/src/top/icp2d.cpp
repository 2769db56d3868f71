// 2D point-to-point ICP; see icp2d.h for the contract.
#include "sdpslam/core/top/icp2d.h"

#include <cmath>  // std::floor only (exact in IEEE-754)
#include <limits>

#include "sdpslam/core/det_math.h"

namespace sdpslam {
namespace {

constexpr double kMaxAbsCoordinate_m = 1.0e6;
constexpr double kInfinity = std::numeric_limits<double>::infinity();

bool coordinates_ok(const Point2* points, std::size_t count) {
  for (std::size_t i = 0; i < count; ++i) {
    const double x = points[i].x_m;
    const double y = points[i].y_m;
    // Written so that NaN fails too.
    if (!(x > -kMaxAbsCoordinate_m && x < kMaxAbsCoordinate_m && y > -kMaxAbsCoordinate_m &&
          y < kMaxAbsCoordinate_m)) {
      return false;
    }
  }
  return true;
}

// Cell index along one axis, or false when it would not fit 32 bits (a query point that
// wandered far away; it has no neighbours anyway).
bool cell_of(double v_m, double cell_m, std::int64_t& out) {
  const double c = std::floor(v_m / cell_m);
  if (!(c > -2.0e9 && c < 2.0e9)) return false;
  out = static_cast<std::int64_t>(c);
  return true;
}

}  // namespace

bool Icp2dOptions::valid() const {
  const bool finite_eps = translation_epsilon_m >= 0.0 && translation_epsilon_m < kInfinity &&
                          rotation_epsilon_rad >= 0.0 && rotation_epsilon_rad < kInfinity;
  return max_iterations >= 1U && max_correspondence_m <= 1.0e3 && min_correspondence_m > 0.0 &&
         min_correspondence_m <= max_correspondence_m && nn_cell_m >= 1.0e-3 && nn_cell_m <= 1.0e3 &&
         max_correspondence_m <= 1000.0 * nn_cell_m && shrink_factor > 0.0 && shrink_factor <= 1.0 && finite_eps &&
         min_pairs >= 2U;
}

const char* to_string(Icp2dResult::Status status) {
  switch (status) {
    case Icp2dResult::Status::kConverged: return "converged";
    case Icp2dResult::Status::kMaxIterations: return "max iterations reached";
    case Icp2dResult::Status::kInsufficientOverlap: return "insufficient overlap";
    case Icp2dResult::Status::kTooFewPoints: return "too few points";
    case Icp2dResult::Status::kTooManyPoints: return "too many points";
    case Icp2dResult::Status::kInvalidInput: return "invalid input";
    case Icp2dResult::Status::kInvalidOptions: return "invalid options";
  }
  return "unknown";
}

std::uint32_t Icp2d::bucket_of(std::int64_t cx, std::int64_t cy) const {
  // Multiplicative mixing of the two 32-bit cell indices (any fixed mix will do; the
  // chain walk checks the exact cell).
  std::uint32_t h = static_cast<std::uint32_t>(cx) * 0x9E3779B1U;
  h ^= static_cast<std::uint32_t>(cy) * 0x85EBCA77U;
  h ^= h >> 15U;
  h *= 0xC2B2AE3DU;
  h ^= h >> 13U;
  return h & (capacity::kIcpHashBuckets - 1U);
}

void Icp2d::build_index(const Point2* target, std::uint32_t count, double cell_m) {
  cell_m_ = cell_m;
  for (std::uint32_t& head : heads_) head = kNone;
  // Inserted from the highest index down so that every chain lists indices ascending.
  for (std::uint32_t k = count; k > 0U; --k) {
    const std::uint32_t i = k - 1U;
    std::int64_t cx = 0;
    std::int64_t cy = 0;
    // Cannot fail: |coordinate| < 1e6 and nn_cell_m >= 1e-3 (checked before).
    (void)cell_of(target[i].x_m, cell_m, cx);
    (void)cell_of(target[i].y_m, cell_m, cy);
    cell_x_[i] = static_cast<std::int32_t>(cx);
    cell_y_[i] = static_cast<std::int32_t>(cy);
    const std::uint32_t b = bucket_of(cx, cy);
    next_[i] = heads_[b];
    heads_[b] = i;
  }
}

void Icp2d::scan_cell(const Point2* target, std::int64_t qx, std::int64_t qy, double x_m, double y_m,
                      std::uint32_t& best, double& best_d2) const {
  for (std::uint32_t i = heads_[bucket_of(qx, qy)]; i != kNone; i = next_[i]) {
    if (cell_x_[i] != qx || cell_y_[i] != qy) continue;  // hash collision
    const double ex = target[i].x_m - x_m;
    const double ey = target[i].y_m - y_m;
    const double d2 = ex * ex + ey * ey;
    // Ties go to the lowest index, whatever order the cells are visited in.
    if (d2 < best_d2 || (d2 == best_d2 && (best == kNone || i < best))) {
      best = i;
      best_d2 = d2;
    }
  }
}

std::uint32_t Icp2d::nearest(const Point2* target, double x_m, double y_m, double max_d, double& out_d2) const {
  std::int64_t cx = 0;
  std::int64_t cy = 0;
  if (!cell_of(x_m, cell_m_, cx) || !cell_of(y_m, cell_m_, cy)) return kNone;
  std::uint32_t best = kNone;
  double best_d2 = max_d * max_d;
  // Ring k holds the cells at Chebyshev distance k from the query's cell; every point in
  // it is at least (k - 1) cells away, so ring rings + 1 is beyond max_d.
  const auto rings = static_cast<std::int64_t>(max_d / cell_m_) + 1;
  scan_cell(target, cx, cy, x_m, y_m, best, best_d2);
  for (std::int64_t k = 1; k <= rings; ++k) {
    const double reach = static_cast<double>(k - 1) * cell_m_;
    if (best != kNone && best_d2 < reach * reach) break;  // strict: keeps tie-breaking exact
    for (std::int64_t d = -k; d <= k; ++d) {
      scan_cell(target, cx + d, cy - k, x_m, y_m, best, best_d2);
      scan_cell(target, cx + d, cy + k, x_m, y_m, best, best_d2);
    }
    for (std::int64_t d = -k + 1; d <= k - 1; ++d) {
      scan_cell(target, cx - k, cy + d, x_m, y_m, best, best_d2);
      scan_cell(target, cx + k, cy + d, x_m, y_m, best, best_d2);
    }
  }
  out_d2 = best_d2;
  return best;
}

Icp2dResult Icp2d::match(const Point2* target, std::size_t target_count, const Point2* source,
                         std::size_t source_count, const Pose2& initial_guess, const Icp2dOptions& options) {
  ++match_count_;
  Icp2dResult r;
  r.transform = initial_guess;
  r.mean_nn_error_m = kInfinity;
  r.rms_nn_error_m = kInfinity;
  auto fail = [&](Icp2dResult::Status s) {
    r.status = s;
    r.converged = false;
    ++failed_match_count_;
    return r;
  };
  if (!options.valid()) return fail(Icp2dResult::Status::kInvalidOptions);
  if ((target == nullptr && target_count > 0U) || (source == nullptr && source_count > 0U)) {
    return fail(Icp2dResult::Status::kInvalidInput);
  }
  if (target_count > capacity::kMaxIcpPoints || source_count > capacity::kMaxIcpPoints) {
    return fail(Icp2dResult::Status::kTooManyPoints);
  }
  if (target_count < options.min_pairs || source_count < options.min_pairs) {
    return fail(Icp2dResult::Status::kTooFewPoints);
  }
  if (!coordinates_ok(target, target_count) || !coordinates_ok(source, source_count)) {
    return fail(Icp2dResult::Status::kInvalidInput);
  }
  if (!(initial_guess.x_m > -kMaxAbsCoordinate_m && initial_guess.x_m < kMaxAbsCoordinate_m &&
        initial_guess.y_m > -kMaxAbsCoordinate_m && initial_guess.y_m < kMaxAbsCoordinate_m &&
        initial_guess.heading_rad > -1.0e3 && initial_guess.heading_rad < 1.0e3)) {
    return fail(Icp2dResult::Status::kInvalidInput);
  }
  r.transform.heading_rad = normalize_angle_rad(initial_guess.heading_rad);

  const auto n_target = static_cast<std::uint32_t>(target_count);
  const auto n_source = static_cast<std::uint32_t>(source_count);
  build_index(target, n_target, options.nn_cell_m);

  Pose2 t = r.transform;
  double reject_m = options.max_correspondence_m;
  for (std::uint32_t iter = 1U; iter <= options.max_iterations; ++iter) {
    const double c = det::cos(t.heading_rad);
    const double s = det::sin(t.heading_rad);
    // Pairing pass, accumulating the centroids on the way.
    std::uint32_t n_pairs = 0U;
    double sum_px = 0.0, sum_py = 0.0, sum_qx = 0.0, sum_qy = 0.0;
    for (std::uint32_t i = 0; i < n_source; ++i) {
      const double px = t.x_m + c * source[i].x_m - s * source[i].y_m;
      const double py = t.y_m + s * source[i].x_m + c * source[i].y_m;
      double d2 = 0.0;
      const std::uint32_t j = nearest(target, px, py, reject_m, d2);
      if (j == kNone) continue;
      pairs_[n_pairs] = Pair{i, j};
      ++n_pairs;
      sum_px += px;
      sum_py += py;
      sum_qx += target[j].x_m;
      sum_qy += target[j].y_m;
    }
    if (n_pairs < options.min_pairs) {
      r.transform = t;
      r.iterations = iter;
      r.matched_pairs = n_pairs;
      r.overlap_fraction = static_cast<double>(n_pairs) / static_cast<double>(n_source);
      return fail(Icp2dResult::Status::kInsufficientOverlap);
    }
    const double inv_n = 1.0 / static_cast<double>(n_pairs);
    const double mpx = sum_px * inv_n, mpy = sum_py * inv_n;
    const double mqx = sum_qx * inv_n, mqy = sum_qy * inv_n;
    // Centred cross-covariance; the optimal rotation is atan2(Σ p×q, Σ p·q).
    double sum_dot = 0.0;
    double sum_cross = 0.0;
    for (std::uint32_t k = 0; k < n_pairs; ++k) {
      const Point2& sp = source[pairs_[k].source];
      const Point2& tq = target[pairs_[k].target];
      const double px = (t.x_m + c * sp.x_m - s * sp.y_m) - mpx;
      const double py = (t.y_m + s * sp.x_m + c * sp.y_m) - mpy;
      const double qx = tq.x_m - mqx;
      const double qy = tq.y_m - mqy;
      sum_dot += px * qx + py * qy;
      sum_cross += px * qy - py * qx;
    }
    const double dtheta = det::atan2(sum_cross, sum_dot);
    const double dc = det::cos(dtheta);
    const double ds = det::sin(dtheta);
    const Pose2 delta{mqx - (dc * mpx - ds * mpy), mqy - (ds * mpx + dc * mpy), dtheta};
    t = delta.compose(t);
    r.iterations = iter;
    const double step2 = delta.x_m * delta.x_m + delta.y_m * delta.y_m;
    const double abs_dtheta = dtheta < 0.0 ? -dtheta : dtheta;
    if (step2 <= options.translation_epsilon_m * options.translation_epsilon_m &&
        abs_dtheta <= options.rotation_epsilon_rad) {
      r.converged = true;
      break;
    }
    const double shrunk = reject_m * options.shrink_factor;
    reject_m = shrunk > options.min_correspondence_m ? shrunk : options.min_correspondence_m;
  }

  // Final pass: the nearest-neighbour error of the final transform.
  r.transform = t;
  const double c = det::cos(t.heading_rad);
  const double s = det::sin(t.heading_rad);
  std::uint32_t matched = 0U;
  double sum_d = 0.0;
  double sum_d2 = 0.0;
  for (std::uint32_t i = 0; i < n_source; ++i) {
    const double px = t.x_m + c * source[i].x_m - s * source[i].y_m;
    const double py = t.y_m + s * source[i].x_m + c * source[i].y_m;
    double d2 = 0.0;
    if (nearest(target, px, py, reject_m, d2) == kNone) continue;
    ++matched;
    sum_d += det::sqrt(d2);
    sum_d2 += d2;
  }
  r.matched_pairs = matched;
  r.overlap_fraction = static_cast<double>(matched) / static_cast<double>(n_source);
  if (matched < options.min_pairs) {
    r.converged = false;
    return fail(Icp2dResult::Status::kInsufficientOverlap);
  }
  r.mean_nn_error_m = sum_d / static_cast<double>(matched);
  r.rms_nn_error_m = det::sqrt(sum_d2 / static_cast<double>(matched));
  r.status = r.converged ? Icp2dResult::Status::kConverged : Icp2dResult::Status::kMaxIterations;
  return r;
}

// Principal axes of the target points within radius_m of target[i] (itself included):
// covariance C = [a b; b c], eigenvalues λ± = (a+c)/2 ± sqrt(((a−c)/2)² + b²). Line-like
// when there are at least 3 points and λ− <= kLineRatio λ+; the normal is then
// perpendicular to the eigenvector of λ+ (det::symmetric2_eigen).
bool Icp2d::line_normal(const Point2* target, std::uint32_t i, double radius_m, double& nx, double& ny) {
  constexpr double kLineRatio = 0.1;
  if (normal_state_[i] != 0U) {
    nx = normal_x_[i];
    ny = normal_y_[i];
    return normal_state_[i] == 1U;
  }
  normal_state_[i] = 2U;
  const double px = target[i].x_m;
  const double py = target[i].y_m;
  const double r2 = radius_m * radius_m;
  const auto reach = static_cast<std::int64_t>(radius_m / cell_m_) + 1;
  // Two passes over the same cells in a fixed order (mean, then centred moments).
  auto visit = [&](auto&& f) {
    for (std::int64_t dy = -reach; dy <= reach; ++dy) {
      for (std::int64_t dx = -reach; dx <= reach; ++dx) {
        const std::int64_t qx = cell_x_[i] + dx;
        const std::int64_t qy = cell_y_[i] + dy;
        for (std::uint32_t k = heads_[bucket_of(qx, qy)]; k != kNone; k = next_[k]) {
          if (cell_x_[k] != qx || cell_y_[k] != qy) continue;  // hash collision
          const double ex = target[k].x_m - px;
          const double ey = target[k].y_m - py;
          if (ex * ex + ey * ey <= r2) f(ex, ey);
        }
      }
    }
  };
  std::uint32_t count = 0U;
  double sx = 0.0, sy = 0.0;
  visit([&](double ex, double ey) {
    ++count;
    sx += ex;
    sy += ey;
  });
  if (count < 3U) return false;
  const double mx = sx / static_cast<double>(count);
  const double my = sy / static_cast<double>(count);
  double a = 0.0, b = 0.0, c = 0.0;
  visit([&](double ex, double ey) {
    const double u = ex - mx;
    const double v = ey - my;
    a += u * u;
    b += u * v;
    c += v * v;
  });
  double major = 0.0, minor = 0.0, ux = 1.0, uy = 0.0;
  det::symmetric2_eigen(a, b, c, &major, &minor, &ux, &uy);
  if (!(major > 0.0) || minor > kLineRatio * major) return false;
  nx = -uy;
  ny = ux;
  normal_x_[i] = nx;
  normal_y_[i] = ny;
  normal_state_[i] = 1U;
  return true;
}

bool Icp2d::direction_information(const Point2* target, std::size_t target_count, const Point2* source,
                                  std::size_t source_count, const Pose2& transform, const Icp2dOptions& options,
                                  double normal_radius_m, Icp2dInformation* out) {
  if (out == nullptr || !options.valid() || !(normal_radius_m > 0.0) || normal_radius_m > 100.0 * options.nn_cell_m) {
    return false;
  }
  if ((target == nullptr && target_count > 0U) || (source == nullptr && source_count > 0U)) return false;
  if (target_count == 0U || target_count > capacity::kMaxIcpPoints || source_count > capacity::kMaxIcpPoints) {
    return false;
  }
  if (!coordinates_ok(target, target_count) || !coordinates_ok(source, source_count)) return false;
  if (!(transform.x_m > -kMaxAbsCoordinate_m && transform.x_m < kMaxAbsCoordinate_m &&
        transform.y_m > -kMaxAbsCoordinate_m && transform.y_m < kMaxAbsCoordinate_m &&
        transform.heading_rad > -1.0e3 && transform.heading_rad < 1.0e3)) {
    return false;
  }
  const auto n_target = static_cast<std::uint32_t>(target_count);
  const auto n_source = static_cast<std::uint32_t>(source_count);
  build_index(target, n_target, options.nn_cell_m);
  for (std::uint32_t i = 0; i < n_target; ++i) normal_state_[i] = 0U;
  const double c = det::cos(transform.heading_rad);
  const double s = det::sin(transform.heading_rad);
  Icp2dInformation info;
  double xx = 0.0, xy = 0.0, yy = 0.0;
  for (std::uint32_t i = 0; i < n_source; ++i) {
    const double px = transform.x_m + c * source[i].x_m - s * source[i].y_m;
    const double py = transform.y_m + s * source[i].x_m + c * source[i].y_m;
    double d2 = 0.0;
    const std::uint32_t j = nearest(target, px, py, options.max_correspondence_m, d2);
    if (j == kNone) continue;
    ++info.pairs;
    double nx = 0.0, ny = 0.0;
    if (line_normal(target, j, normal_radius_m, nx, ny)) {
      xx += nx * nx;
      xy += nx * ny;
      yy += ny * ny;
      ++info.line_pairs;
    } else {
      xx += 0.5;
      yy += 0.5;
    }
  }
  if (info.pairs == 0U) return false;
  const double inv = 1.0 / static_cast<double>(info.pairs);
  info.xx = xx * inv;
  info.xy = xy * inv;
  info.yy = yy * inv;
  *out = info;
  return true;
}

// The index and pair buffers are rebuilt by every match: only the counters persist.
void Icp2d::transfer_state(StateIo& io) {
  io.section("icp");
  io.value(cell_m_);
  io.value(match_count_);
  io.value(failed_match_count_);
}

}  // namespace sdpslam
