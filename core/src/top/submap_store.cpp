#include "top/submap_store.h"

namespace sdpslam {
namespace {

// The cell of a grid (origin, cell size) whose centre is nearest to coordinate v,
// clamped to 0 .. 65535; 0 for a grid without a cell size.
std::uint16_t grid_cell(double v_m, double origin_m, double cell_m) {
  if (!(cell_m > 0.0)) return 0U;
  const double k = (v_m - origin_m) / cell_m - 0.5;
  if (!(k > 0.0)) return 0U;
  if (k >= 65535.0) return 65535U;
  return static_cast<std::uint16_t>(k + 0.5);
}

}  // namespace

bool SubmapStoreOptions::valid() const {
  return max_levels >= 1U && nodes >= 1U && skeleton_points >= 1U && max_permanent >= 1U;
}

std::size_t SubmapStore::required_bytes(const SubmapStoreOptions& o) {
  if (!o.valid()) return 0U;
  const std::size_t live = std::size_t{o.max_levels} * o.nodes;
  std::size_t total = Arena::bytes_for<Submap>(live) + Arena::bytes_for<Point2>(live * o.skeleton_points) +
                      Arena::bytes_for<SubmapLevel>(o.max_levels) + Arena::bytes_for<PermanentSubmap>(o.max_permanent) +
                      Arena::bytes_for<SkeletonCell>(std::size_t{o.max_permanent} * o.skeleton_points) +
                      Arena::bytes_for<Point2>(o.skeleton_points);
  if (o.obstacle_points > 0U) {
    total += Arena::bytes_for<CellPoint>((live + o.max_permanent) * std::size_t{o.obstacle_points});
  }
  return total;
}

bool SubmapStore::init(const SubmapStoreOptions& o, Arena& arena) {
  submaps_ = nullptr;
  if (!o.valid() || arena.available_bytes() < required_bytes(o)) return false;
  const std::size_t live = std::size_t{o.max_levels} * o.nodes;
  Submap* submaps = arena.allocate_array<Submap>(live);
  points_ = arena.allocate_array<Point2>(live * o.skeleton_points);
  levels_ = arena.allocate_array<SubmapLevel>(o.max_levels);
  perm_ = arena.allocate_array<PermanentSubmap>(o.max_permanent);
  perm_cells_ = arena.allocate_array<SkeletonCell>(std::size_t{o.max_permanent} * o.skeleton_points);
  perm_unpacked_ = arena.allocate_array<Point2>(o.skeleton_points);
  obstacles_ = nullptr;
  perm_obstacles_ = nullptr;
  if (o.obstacle_points > 0U) {
    // One block: the live submaps' points, then the permanent ones'.
    obstacles_ = arena.allocate_array<CellPoint>((live + o.max_permanent) * std::size_t{o.obstacle_points});
    if (obstacles_ == nullptr) return false;
    perm_obstacles_ = obstacles_ + live * o.obstacle_points;
  }
  if (submaps == nullptr || points_ == nullptr || levels_ == nullptr || perm_ == nullptr || perm_cells_ == nullptr ||
      perm_unpacked_ == nullptr) {
    return false;
  }
  options_ = o;
  submaps_ = submaps;
  for (std::size_t i = 0; i < live; ++i) submaps_[i] = Submap{};
  for (std::uint32_t i = 0; i < o.max_levels; ++i) levels_[i] = SubmapLevel{};
  for (std::uint32_t i = 0; i < o.max_permanent; ++i) perm_[i] = PermanentSubmap{};
  perm_head_ = 0U;
  perm_count_ = 0U;
  return true;
}

const Point2* SubmapStore::permanent_points(std::uint32_t slot) const {
  const PermanentSubmap& pm = perm_[slot];
  const SkeletonCell* cells = perm_cells_ + std::size_t{slot} * options_.skeleton_points;
  const SkeletonGrid& g = pm.skeleton_grid;
  // The expression FreeSpaceSkeleton::extract() emits its points with.
  for (std::uint32_t i = 0; i < pm.point_count; ++i) {
    perm_unpacked_[i] = Point2{g.origin_x_m + (static_cast<double>(cells[i].x) + 0.5) * g.cell_m,
                               g.origin_y_m + (static_cast<double>(cells[i].y) + 0.5) * g.cell_m};
  }
  return perm_unpacked_;
}

bool SubmapStore::find_permanent(std::uint32_t level, std::uint32_t* slot) const {
  if (perm_count_ == 0U) return false;
  const std::uint32_t oldest = perm_[perm_head_].level;
  if (level < oldest || level - oldest >= perm_count_) return false;
  const std::uint32_t k = permanent_slot_at(level - oldest);
  if (perm_[k].level != level) return false;  // levels are made permanent in order
  *slot = k;
  return true;
}

std::uint32_t SubmapStore::make_permanent(std::uint32_t level, std::uint32_t node, bool* forgot) {
  *forgot = perm_count_ == options_.max_permanent;
  if (*forgot) {
    perm_head_ = (perm_head_ + 1U) % options_.max_permanent;
    --perm_count_;
  }
  const std::uint32_t slot = permanent_slot_at(perm_count_);
  const Submap& sm = submap(level, node);
  PermanentSubmap& pm = perm_[slot];
  pm = PermanentSubmap{};
  for (int i = 0; i < 4; ++i) pm.box[i] = sm.box[i];
  pm.level = level;
  pm.start_stamp_us = this->level(level).start_stamp_us;
  pm.initial = sm.initial;
  pm.point_count = sm.point_count;
  pm.skeleton_grid = sm.skeleton_grid;
  const Point2* src = points(level, node);
  SkeletonCell* dst = perm_cells_ + std::size_t{slot} * options_.skeleton_points;
  const SkeletonGrid& g = sm.skeleton_grid;
  for (std::uint32_t i = 0; i < sm.point_count; ++i) {
    dst[i].x = grid_cell(src[i].x_m, g.origin_x_m, g.cell_m);
    dst[i].y = grid_cell(src[i].y_m, g.origin_y_m, g.cell_m);
  }
  if (obstacles_ != nullptr) {
    const CellPoint* from = obstacles(level, node);
    CellPoint* to = permanent_obstacles(slot);
    for (std::uint32_t i = 0; i < sm.obstacle_count; ++i) to[i] = from[i];
    pm.obstacle_count = sm.obstacle_count;
  }
  ++perm_count_;
  return slot;
}

}  // namespace sdpslam
