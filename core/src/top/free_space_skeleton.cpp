// Medial axis of the free space of a grid patch; see free_space_skeleton.h.
#include "top/free_space_skeleton.h"

#include <limits>

#include "sdpslam/core/det_math.h"

namespace sdpslam {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
// Cell classes kept in mark_ (low bits) and the ridge flag.
constexpr std::uint8_t kClassFree = 1U;
constexpr std::uint8_t kClassObstacle = 2U;
constexpr std::uint8_t kClassMask = 3U;
constexpr std::uint8_t kRidge = 0x10U;

// A feature (nearest obstacle cell) may lie one cell outside the patch when the border
// counts as an obstacle, so coordinates are stored shifted by one in 16 bits each.
std::uint32_t pack_feature(std::int64_t fx, std::int64_t fy) {
  return (static_cast<std::uint32_t>(fy + 1) << 16U) | static_cast<std::uint32_t>(fx + 1);
}
std::int64_t feature_x(std::uint32_t f) { return static_cast<std::int64_t>(f & 0xFFFFU) - 1; }
std::int64_t feature_y(std::uint32_t f) { return static_cast<std::int64_t>(f >> 16U) - 1; }

std::size_t aligned_block(std::size_t bytes) { return bytes + 16U; }

}  // namespace

bool SkeletonOptions::valid() const {
  return min_clearance_m >= 0.0 && min_clearance_m < kInfinity && min_ridge_angle_rad > 0.0 &&
         min_ridge_angle_rad <= det::kPi && max_points >= 1U;
}

const char* to_string(SkeletonResult::Status status) {
  switch (status) {
    case SkeletonResult::Status::kOk: return "ok";
    case SkeletonResult::Status::kNotInitialised: return "not initialised";
    case SkeletonResult::Status::kPatchTooLarge: return "patch larger than provisioned";
    case SkeletonResult::Status::kInvalidPatch: return "invalid patch";
    case SkeletonResult::Status::kInvalidOptions: return "invalid options";
  }
  return "unknown";
}

std::size_t FreeSpaceSkeleton::required_bytes(std::uint32_t max_width, std::uint32_t max_height) {
  const std::size_t cells = static_cast<std::size_t>(max_width) * max_height;
  const std::size_t line = max_width > max_height ? max_width : max_height;
  return aligned_block(cells * sizeof(std::uint32_t)) * 2U + aligned_block(cells) +
         aligned_block(line * sizeof(double)) + aligned_block((line + 1U) * sizeof(double)) +
         aligned_block(line * sizeof(std::uint32_t)) * 2U;
}

bool FreeSpaceSkeleton::init(Arena& arena, std::uint32_t max_width, std::uint32_t max_height) {
  if (initialised() || max_width == 0U || max_height == 0U || max_width > capacity::kMaxSkeletonPatchSide ||
      max_height > capacity::kMaxSkeletonPatchSide) {
    return false;
  }
  if (arena.available_bytes() < required_bytes(max_width, max_height)) return false;
  const std::size_t cells = static_cast<std::size_t>(max_width) * max_height;
  const std::size_t line = max_width > max_height ? max_width : max_height;
  std::uint32_t* sq = arena.allocate_array<std::uint32_t>(cells);
  std::uint32_t* feat = arena.allocate_array<std::uint32_t>(cells);
  std::uint8_t* mark = arena.allocate_array<std::uint8_t>(cells);
  double* lf = arena.allocate_array<double>(line);
  double* lz = arena.allocate_array<double>(line + 1U);
  std::uint32_t* lv = arena.allocate_array<std::uint32_t>(line);
  std::uint32_t* lfeat = arena.allocate_array<std::uint32_t>(line);
  if (sq == nullptr || feat == nullptr || mark == nullptr || lf == nullptr || lz == nullptr || lv == nullptr ||
      lfeat == nullptr) {
    return false;  // cannot happen after the size check above, kept as a guard
  }
  max_width_ = max_width;
  max_height_ = max_height;
  feature_ = feat;
  mark_ = mark;
  line_f_ = lf;
  line_z_ = lz;
  line_v_ = lv;
  line_feature_ = lfeat;
  sq_dist_ = sq;  // last: initialised() keys on it
  return true;
}

CellState FreeSpaceSkeleton::state_at(const GridPatchView& patch, std::uint32_t x, std::uint32_t y) const {
  if (patch.cells != nullptr) {
    const std::size_t stride = patch.row_stride != 0U ? patch.row_stride : patch.width;
    return patch.cells[static_cast<std::size_t>(y) * stride + x];
  }
  return patch.classify(patch.context, x, y);
}

double FreeSpaceSkeleton::clearance_m(std::uint32_t x, std::uint32_t y) const {
  if (!initialised() || x >= last_width_ || y >= last_height_) return -1.0;
  if (!last_has_obstacle_) return kInfinity;
  const std::uint32_t d2 = sq_dist_[static_cast<std::size_t>(y) * last_width_ + x];
  if (feature_[static_cast<std::size_t>(y) * last_width_ + x] == kNoFeature) return kInfinity;
  return det::sqrt(static_cast<double>(d2)) * last_resolution_m_;
}

SkeletonResult FreeSpaceSkeleton::extract(const GridPatchView& patch, const SkeletonOptions& options, Point2* out,
                                          std::size_t out_capacity) {
  ++extract_count_;
  SkeletonResult r;
  auto fail = [&](SkeletonResult::Status s) {
    r.status = s;
    ++failed_extract_count_;
    return r;
  };
  if (!initialised()) return fail(SkeletonResult::Status::kNotInitialised);
  if (!options.valid()) return fail(SkeletonResult::Status::kInvalidOptions);
  if (patch.width == 0U || patch.height == 0U || (patch.cells == nullptr && patch.classify == nullptr) ||
      !(patch.resolution_m > 0.0 && patch.resolution_m <= 1.0e3) ||
      !(patch.origin_x_m > -1.0e9 && patch.origin_x_m < 1.0e9) ||
      !(patch.origin_y_m > -1.0e9 && patch.origin_y_m < 1.0e9) ||
      (patch.cells != nullptr && patch.row_stride != 0U && patch.row_stride < patch.width) ||
      (out == nullptr && out_capacity > 0U)) {
    return fail(SkeletonResult::Status::kInvalidPatch);
  }
  if (patch.width > max_width_ || patch.height > max_height_) return fail(SkeletonResult::Status::kPatchTooLarge);

  const std::uint32_t w = patch.width;
  const std::uint32_t h = patch.height;
  const auto at = [w](std::uint32_t x, std::uint32_t y) { return static_cast<std::size_t>(y) * w + x; };
  last_width_ = 0U;  // clearance_m() is meaningless until this call completes
  last_height_ = 0U;

  // Classify every cell once (the view may be a costly callback).
  bool any_obstacle = options.patch_border_is_obstacle;
  for (std::uint32_t y = 0; y < h; ++y) {
    for (std::uint32_t x = 0; x < w; ++x) {
      const CellState s = state_at(patch, x, y);
      std::uint8_t cls = 0U;
      if (s == CellState::kFree) {
        cls = kClassFree;
        ++r.free_cell_count;
      } else if (s == CellState::kOccupied || options.unknown_is_obstacle) {
        cls = kClassObstacle;
        ++r.obstacle_cell_count;
        any_obstacle = true;
      }
      mark_[at(x, y)] = cls;
    }
  }

  // Pass 1, columns: nearest obstacle along each column (distance and row).
  const std::int64_t border_lo = options.patch_border_is_obstacle ? -1 : -2;  // -2: none
  for (std::uint32_t x = 0; x < w; ++x) {
    std::int64_t last = border_lo;
    for (std::uint32_t y = 0; y < h; ++y) {
      if ((mark_[at(x, y)] & kClassMask) == kClassObstacle) last = y;
      line_v_[y] = last == -2 ? kNoFeature : static_cast<std::uint32_t>(last + 1);  // row + 1
    }
    std::int64_t next = options.patch_border_is_obstacle ? static_cast<std::int64_t>(h) : -2;
    for (std::uint32_t k = h; k > 0U; --k) {
      const std::uint32_t y = k - 1U;
      if ((mark_[at(x, y)] & kClassMask) == kClassObstacle) next = y;
      std::int64_t best = -2;
      std::int64_t best_d = 0;
      if (line_v_[y] != kNoFeature) {
        best = static_cast<std::int64_t>(line_v_[y]) - 1;
        best_d = static_cast<std::int64_t>(y) - best;
      }
      if (next != -2 && (best == -2 || next - static_cast<std::int64_t>(y) < best_d)) {
        best = next;
        best_d = next - static_cast<std::int64_t>(y);
      }
      if (best == -2) {
        feature_[at(x, y)] = kNoFeature;
        sq_dist_[at(x, y)] = 0U;
      } else {
        feature_[at(x, y)] = pack_feature(x, best);
        sq_dist_[at(x, y)] = static_cast<std::uint32_t>(best_d * best_d);
      }
    }
  }

  // Pass 2, rows: lower envelope of the parabolas (x - q)² + g(q)² (Felzenszwalb &
  // Huttenlocher 2012, Algorithm 1), over the columns q that have an obstacle.
  for (std::uint32_t y = 0; y < h; ++y) {
    std::uint32_t k = 0U;
    bool any = false;
    for (std::uint32_t q = 0; q < w; ++q) {
      const std::uint32_t fq = feature_[at(q, y)];
      line_feature_[q] = fq;
      if (fq == kNoFeature) continue;
      const double fval = static_cast<double>(sq_dist_[at(q, y)]);
      line_f_[q] = fval;
      const double dq = static_cast<double>(q);
      if (!any) {
        any = true;
        k = 0U;
        line_v_[0] = q;
        line_z_[0] = -kInfinity;
        line_z_[1] = kInfinity;
        continue;
      }
      double s = 0.0;
      for (;;) {
        const std::uint32_t vk = line_v_[k];
        const double dv = static_cast<double>(vk);
        s = ((fval + dq * dq) - (line_f_[vk] + dv * dv)) / (2.0 * dq - 2.0 * dv);
        if (s > line_z_[k] || k == 0U) break;
        --k;
      }
      // z[0] is -inf, so the loop above only stops at k == 0 when s > -inf anyway.
      ++k;
      line_v_[k] = q;
      line_z_[k] = s;
      line_z_[k + 1U] = kInfinity;
    }
    if (!any) continue;  // no obstacle reaches this row through any column
    std::uint32_t j = 0U;
    for (std::uint32_t x = 0; x < w; ++x) {
      const double dx = static_cast<double>(x);
      while (line_z_[j + 1U] < dx) ++j;
      const std::uint32_t q = line_v_[j];
      const std::int64_t off = static_cast<std::int64_t>(x) - static_cast<std::int64_t>(q);
      const double fval = line_f_[q];
      sq_dist_[at(x, y)] = static_cast<std::uint32_t>(off * off) + static_cast<std::uint32_t>(fval);
      feature_[at(x, y)] = pack_feature(static_cast<std::int64_t>(q), feature_y(line_feature_[q]));
    }
  }

  // Left and right patch borders as obstacle columns x = -1 and x = w.
  if (options.patch_border_is_obstacle) {
    for (std::uint32_t y = 0; y < h; ++y) {
      for (std::uint32_t x = 0; x < w; ++x) {
        const std::uint32_t left = x + 1U;
        const std::uint32_t right = w - x;
        const std::uint32_t dmin = left < right ? left : right;
        const std::uint32_t d2 = dmin * dmin;
        if (feature_[at(x, y)] == kNoFeature || d2 < sq_dist_[at(x, y)]) {
          sq_dist_[at(x, y)] = d2;
          feature_[at(x, y)] = pack_feature(left <= right ? -1 : static_cast<std::int64_t>(w), y);
        }
      }
    }
  }

  last_width_ = w;
  last_height_ = h;
  last_resolution_m_ = patch.resolution_m;
  last_has_obstacle_ = any_obstacle;

  // Ridge cells (integer medial axis, Hesselink & Roerdink 2008, with angle pruning).
  const double res = patch.resolution_m;
  const double min_clear_cells = options.min_clearance_m / res;
  const double min_clear_sq = min_clear_cells * min_clear_cells;
  const double cos_limit = det::cos(options.min_ridge_angle_rad);
  const bool obtuse_only = cos_limit <= 0.0;
  const auto wide_enough = [&](std::uint32_t mx, std::uint32_t my, std::uint32_t fa, std::uint32_t fb) {
    if (static_cast<double>(sq_dist_[at(mx, my)]) < min_clear_sq) return false;
    const std::int64_t ax = feature_x(fa) - static_cast<std::int64_t>(mx);
    const std::int64_t ay = feature_y(fa) - static_cast<std::int64_t>(my);
    const std::int64_t bx = feature_x(fb) - static_cast<std::int64_t>(mx);
    const std::int64_t by = feature_y(fb) - static_cast<std::int64_t>(my);
    const std::int64_t dot = ax * bx + ay * by;
    // Exact integer early-out for the common case (neighbours along a wall): a limit of
    // 90° or more needs a non-positive dot product.
    if (obtuse_only && dot > 0) return false;
    const auto na = static_cast<double>(ax * ax + ay * ay);
    const auto nb = static_cast<double>(bx * bx + by * by);
    if (na == 0.0 || nb == 0.0) return false;
    return static_cast<double>(dot) <= cos_limit * det::sqrt(na * nb);
  };
  const auto consider = [&](std::uint32_t px, std::uint32_t py, std::uint32_t qx, std::uint32_t qy) {
    if ((mark_[at(px, py)] & kClassMask) != kClassFree || (mark_[at(qx, qy)] & kClassMask) != kClassFree) return;
    const std::uint32_t fp = feature_[at(px, py)];
    const std::uint32_t fq = feature_[at(qx, qy)];
    if (fp == kNoFeature || fq == kNoFeature || fp == fq) return;
    const std::int64_t vx = feature_x(fq) - feature_x(fp);
    const std::int64_t vy = feature_y(fq) - feature_y(fp);
    const std::int64_t sx = feature_x(fp) + feature_x(fq);
    const std::int64_t sy = feature_y(fp) + feature_y(fq);
    // Signed (doubled) offsets of p and q from the bisector of fp, fq along fq - fp.
    const std::int64_t sp = (2 * static_cast<std::int64_t>(px) - sx) * vx + (2 * static_cast<std::int64_t>(py) - sy) * vy;
    const std::int64_t sq = (2 * static_cast<std::int64_t>(qx) - sx) * vx + (2 * static_cast<std::int64_t>(qy) - sy) * vy;
    if (-sp <= sq && wide_enough(px, py, fp, fq)) mark_[at(px, py)] |= kRidge;
    if (sq <= -sp && wide_enough(qx, qy, fp, fq)) mark_[at(qx, qy)] |= kRidge;
  };
  for (std::uint32_t y = 0; y < h; ++y) {
    for (std::uint32_t x = 0; x < w; ++x) {
      if (x + 1U < w) consider(x, y, x + 1U, y);
      if (y + 1U < h) consider(x, y, x, y + 1U);
    }
  }

  // Emit, subsampled by a fixed stride in raster order.
  std::uint32_t ridge = 0U;
  for (std::size_t i = 0; i < static_cast<std::size_t>(w) * h; ++i) {
    if ((mark_[i] & kRidge) != 0U) ++ridge;
  }
  r.ridge_cell_count = ridge;
  r.stride = ridge > options.max_points ? (ridge + options.max_points - 1U) / options.max_points : 1U;
  std::uint32_t seen = 0U;
  for (std::uint32_t y = 0; y < h; ++y) {
    for (std::uint32_t x = 0; x < w; ++x) {
      if ((mark_[at(x, y)] & kRidge) == 0U) continue;
      const bool keep = seen % r.stride == 0U;
      ++seen;
      if (!keep) continue;
      if (r.point_count >= out_capacity) {
        ++r.truncated_count;
        ++overflow_count_;
        continue;
      }
      out[r.point_count] = Point2{patch.origin_x_m + (static_cast<double>(x) + 0.5) * res,
                                  patch.origin_y_m + (static_cast<double>(y) + 0.5) * res};
      ++r.point_count;
    }
  }
  r.status = SkeletonResult::Status::kOk;
  return r;
}

void FreeSpaceSkeleton::transfer_state(StateIo& io) {
  io.section("skeleton");
  io.value(last_width_);
  io.value(last_height_);
  io.value(last_resolution_m_);
  io.value(last_has_obstacle_);
  io.value(extract_count_);
  io.value(failed_extract_count_);
  io.value(overflow_count_);
}

}  // namespace sdpslam
