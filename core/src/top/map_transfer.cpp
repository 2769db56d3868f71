#include "top/map_transfer.h"

#include <cmath>

namespace sdpslam {

void MapTransfer::start(NodeId node, const Pose2& frame, std::uint32_t tag, const CellRect& rect) {
  job_ = Job{};
  job_.active = true;
  job_.node = node;
  job_.frame = frame;
  job_.tag = tag;
  job_.rect = rect;
  job_.next_row = 0U;
}

bool MapTransfer::pending(NodeId* node, CellRect* rest) const {
  if (!job_.active) return false;
  *node = job_.node;
  *rest = job_.rect;
  rest->iy0 += static_cast<std::int32_t>(job_.next_row);
  rest->height -= job_.next_row;
  return true;
}

void MapTransfer::copy_cell(std::int32_t ix, std::int32_t iy, const CellObservation& v, const DpMap& dp,
                            PermanentMap& map, TransferStep* step) const {
  double cx = 0.0;
  double cy = 0.0;
  dp.cell_center(ix, iy, &cx, &cy);
  double gx = 0.0;
  double gy = 0.0;
  job_.frame.transform_point(cx, cy, gx, gy);
  ++step->cells_copied;
  const double fx = std::floor((gx - dp.options().origin_x_m) / dp.resolution_m());
  const double fy = std::floor((gy - dp.options().origin_y_m) / dp.resolution_m());
  constexpr double kLimit = 1073741824.0;  // 2^30 cells
  if (!(fx > -kLimit && fx < kLimit && fy > -kLimit && fy < kLimit) ||
      !map.add(static_cast<std::int32_t>(fx), static_cast<std::int32_t>(fy), v.hits, v.misses, job_.tag)) {
    ++step->cells_dropped;
  }
}

TransferStep MapTransfer::work(std::uint32_t budget_cells, DpSlamFilter& filter, PermanentMap& map,
                               const FineBuffer& fine) {
  TransferStep step;
  if (!job_.active) return step;
  const DpMap& dp = filter.map();
  const std::uint32_t held = dp.observations_used();
  const CellRect& r = job_.rect;
  std::uint32_t used = 0U;
  if (r.width == 0U || !map.initialised()) job_.next_row = r.height;
  if (job_.mode == Mode::kUndecided) {
    const bool root = filter.tree().parent(job_.node) == kNoNode;
    job_.mode = root ? Mode::kPop : Mode::kRows;
    (root ? step.popped : step.by_rows) = true;
  }
  if (job_.mode == Mode::kPop && job_.next_row < r.height) {
    std::int32_t ix = 0;
    std::int32_t iy = 0;
    CellObservation v{};
    bool more = true;
    // Popped cells come in window coordinates; the submap's are those near its rectangle.
    const std::int32_t mid_x = r.ix0 + static_cast<std::int32_t>(r.width / 2U);
    const std::int32_t mid_y = r.iy0 + static_cast<std::int32_t>(r.height / 2U);
    while (used < budget_cells && (more = filter.pop_anchored_observation(job_.node, &ix, &iy, &v))) {
      used += kPopCostCells;
      dp.unwrap_near(&ix, &iy, mid_x, mid_y);
      copy_cell(ix, iy, v, dp, map, &step);
    }
    if (!more) job_.next_row = r.height;
  }
  while (job_.mode == Mode::kRows && job_.next_row < r.height && used < budget_cells) {
    // A strip fits the buffer and what is left of the budget (at least one row).
    std::uint32_t rows = static_cast<std::uint32_t>(fine.cells / r.width);
    const std::uint32_t budget_rows = (budget_cells - used) / r.width;
    if (budget_rows < rows) rows = budget_rows;
    if (rows == 0U) rows = 1U;
    if (rows > r.height - job_.next_row) rows = r.height - job_.next_row;
    CellRect strip = r;
    strip.iy0 = r.iy0 + static_cast<std::int32_t>(job_.next_row);
    strip.height = rows;
    if (static_cast<std::size_t>(strip.width) * rows > fine.cells) strip.width = static_cast<std::uint32_t>(fine.cells);
    dp.fill_rect(job_.node, strip, fine.values, fine.known);
    for (std::uint32_t y = 0; y < rows; ++y) {
      for (std::uint32_t x = 0; x < strip.width; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * strip.width + x;
        if (fine.known[i] == 0U) continue;
        copy_cell(strip.ix0 + static_cast<std::int32_t>(x), strip.iy0 + static_cast<std::int32_t>(y), fine.values[i], dp,
                  map, &step);
      }
    }
    job_.next_row += rows;
    used += strip.width * rows;
  }
  if (job_.next_row >= r.height) {
    step.released = filter.release_anchored(job_.node);
    job_ = Job{};
  }
  const std::uint32_t left = dp.observations_used();
  if (left < held) step.observations_freed = held - left;
  step.work_cells = used > 0U ? used : 1U;
  return step;
}

}  // namespace sdpslam
