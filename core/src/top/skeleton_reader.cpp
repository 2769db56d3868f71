#include "top/skeleton_reader.h"

#include "sdpslam/core/box2.h"

namespace sdpslam {

bool SkeletonReaderOptions::valid() const {
  return patch_side >= 3U && downsample >= 1U && skeleton_points >= 1U && free_threshold <= occupied_threshold;
}

std::size_t SkeletonReader::required_bytes(const SkeletonReaderOptions& o) {
  if (!o.valid()) return 0U;
  return FreeSpaceSkeleton::required_bytes(o.patch_side, o.patch_side) +
         Arena::bytes_for<CellState>(std::size_t{o.patch_side} * o.patch_side);
}

bool SkeletonReader::init(const SkeletonReaderOptions& o, Arena& arena) {
  coarse_ = nullptr;
  job_ = Job{};
  if (!o.valid() || arena.available_bytes() < required_bytes(o)) return false;
  if (!skeleton_.init(arena, o.patch_side, o.patch_side)) return false;
  coarse_ = arena.allocate_array<CellState>(std::size_t{o.patch_side} * o.patch_side);
  if (coarse_ == nullptr) return false;
  options_ = o;
  return true;
}

void SkeletonReader::transfer_state(StateIo& io) {
  skeleton_.transfer_state(io);
  io.value(job_);
}

void SkeletonReader::start(SubmapStore& store, std::uint32_t level, std::uint32_t node) {
  Submap& sm = store.submap(level, node);
  sm.skeleton_done = false;
  sm.point_count = 0U;
  sm.obstacle_count = 0U;
  box_init(sm.box);
  CellRect r = sm.path_rect;
  const std::uint32_t d = options_.downsample;
  const std::uint32_t max_fine = (options_.patch_side - 2U) * d;
  // Bounded patch: centred crop of the padded path bounds.
  if (r.width > max_fine) {
    r.ix0 += static_cast<std::int32_t>((r.width - max_fine) / 2U);
    r.width = max_fine;
  }
  if (r.height > max_fine) {
    r.iy0 += static_cast<std::int32_t>((r.height - max_fine) / 2U);
    r.height = max_fine;
  }
  job_ = Job{};
  job_.level = level;
  job_.node = node;
  job_.rect = r;
  job_.coarse_width = (r.width + d - 1U) / d;
  job_.coarse_height = (r.height + d - 1U) / d;
  job_.active = true;
}

SkeletonStep SkeletonReader::work(std::uint32_t budget_cells, const DpSlamFilter& filter, SubmapStore& store,
                                  const FineBuffer& fine) {
  SkeletonStep step;
  Job& job = job_;
  if (!job.active) return step;
  Submap& sm = store.submap(job.level, job.node);
  const CellRect& r = job.rect;
  const std::uint32_t d = options_.downsample;
  const std::uint32_t cw = job.coarse_width;
  const std::uint32_t ch = job.coarse_height;
  const DpMap& map = filter.map();
  std::uint32_t used = 0U;
  if (r.width == 0U || r.height == 0U) {
    job.next_coarse_row = ch;
    used = 1U;
  }
  while (job.next_coarse_row < ch && used < budget_cells) {
    // Whole coarse rows, as many as the budget and the fine buffer afford (at least one).
    const std::uint32_t row_cells = r.width * d;
    std::uint32_t rows = static_cast<std::uint32_t>(fine.cells / row_cells);
    const std::uint32_t afford = (budget_cells - used) / row_cells;
    if (rows > afford) rows = afford;
    if (rows == 0U) rows = 1U;
    if (rows > ch - job.next_coarse_row) rows = ch - job.next_coarse_row;
    CellRect strip = r;
    const std::uint32_t fy0 = job.next_coarse_row * d;
    std::uint32_t fh = rows * d;
    if (fy0 + fh > r.height) fh = r.height - fy0;
    strip.iy0 = r.iy0 + static_cast<std::int32_t>(fy0);
    strip.height = fh;
    map.fill_rect(sm.node, strip, fine.values, fine.known);
    for (std::uint32_t cy = job.next_coarse_row; cy < job.next_coarse_row + rows; ++cy) {
      for (std::uint32_t cx = 0; cx < cw; ++cx) {
        bool occ = false;
        bool fre = false;
        for (std::uint32_t dy = 0; dy < d; ++dy) {
          const std::uint32_t y = cy * d + dy;
          if (y >= r.height) break;
          for (std::uint32_t dx = 0; dx < d; ++dx) {
            const std::uint32_t x = cx * d + dx;
            if (x >= r.width) break;
            const std::size_t i = static_cast<std::size_t>(y - fy0) * r.width + x;
            if (fine.known[i] == 0U) continue;
            const double p = filter.occupancy(fine.values[i]);
            if (p >= options_.occupied_threshold) occ = true;
            else if (p <= options_.free_threshold) fre = true;
          }
        }
        coarse_[static_cast<std::size_t>(cy) * cw + cx] =
            occ ? CellState::kOccupied : (fre ? CellState::kFree : CellState::kUnknown);
      }
    }
    job.next_coarse_row += rows;
    used += r.width * fh;
  }
  step.cells_read = used;
  if (job.next_coarse_row < ch) return step;
  // The whole patch is classified: the skeleton (and the obstacle points).
  job.active = false;
  sm.skeleton_done = true;
  if (r.width == 0U || r.height == 0U) return step;
  GridPatchView patch;
  patch.width = cw;
  patch.height = ch;
  patch.resolution_m = map.resolution_m() * static_cast<double>(d);
  patch.origin_x_m = map.options().origin_x_m + static_cast<double>(r.ix0) * map.resolution_m();
  patch.origin_y_m = map.options().origin_y_m + static_cast<double>(r.iy0) * map.resolution_m();
  patch.cells = coarse_;
  SkeletonOptions so;
  so.min_clearance_m = options_.min_clearance_m;
  so.max_points = options_.skeleton_points;
  Point2* out = store.points(job.level, job.node);
  sm.skeleton_grid = SkeletonGrid{patch.origin_x_m, patch.origin_y_m, patch.resolution_m};
  if (options_.obstacle_points > 0U) extract_obstacles(sm, store.obstacles(job.level, job.node), r, cw, ch);
  const SkeletonResult res = skeleton_.extract(patch, so, out, options_.skeleton_points);
  step.extracted = true;
  if (res.status == SkeletonResult::Status::kOk) {
    sm.point_count = res.point_count;
    step.truncated_points = res.truncated_count;
    for (std::uint32_t i = 0; i < sm.point_count; ++i) box_add(sm.box, out[i].x_m, out[i].y_m);
  }
  return step;
}

// Occupied coarse cells with a free 4-neighbour (wall surfaces seen from free space),
// thinned by a fixed stride to at most obstacle_points, stored as the fine cell at the
// coarse cell's centre. Reads coarse_ as work() just filled it.
void SkeletonReader::extract_obstacles(Submap& sm, CellPoint* out, const CellRect& r, std::uint32_t cw,
                                       std::uint32_t ch) const {
  auto state = [&](std::uint32_t x, std::uint32_t y) { return coarse_[static_cast<std::size_t>(y) * cw + x]; };
  auto surface = [&](std::uint32_t x, std::uint32_t y) {
    if (state(x, y) != CellState::kOccupied) return false;
    return (x > 0U && state(x - 1U, y) == CellState::kFree) || (x + 1U < cw && state(x + 1U, y) == CellState::kFree) ||
           (y > 0U && state(x, y - 1U) == CellState::kFree) || (y + 1U < ch && state(x, y + 1U) == CellState::kFree);
  };
  std::uint32_t total = 0U;
  for (std::uint32_t y = 0; y < ch; ++y) {
    for (std::uint32_t x = 0; x < cw; ++x) total += surface(x, y) ? 1U : 0U;
  }
  const std::uint32_t k = options_.obstacle_points;
  const std::uint32_t stride = total > k ? (total + k - 1U) / k : 1U;
  const std::uint32_t d = options_.downsample;
  std::uint32_t seen = 0U;
  std::uint32_t n = 0U;
  for (std::uint32_t y = 0; y < ch && n < k; ++y) {
    for (std::uint32_t x = 0; x < cw && n < k; ++x) {
      if (!surface(x, y)) continue;
      if (seen++ % stride != 0U) continue;
      // Centre of the coarse cell in half fine cells from the map's origin.
      const std::int64_t ix = 2 * (static_cast<std::int64_t>(r.ix0) + static_cast<std::int64_t>(x * d)) + d;
      const std::int64_t iy = 2 * (static_cast<std::int64_t>(r.iy0) + static_cast<std::int64_t>(y * d)) + d;
      if (ix < 0 || iy < 0 || ix > 65535 || iy > 65535) continue;
      out[n].ix = static_cast<std::uint16_t>(ix);
      out[n].iy = static_cast<std::uint16_t>(iy);
      ++n;
    }
  }
  sm.obstacle_count = n;
}

}  // namespace sdpslam
