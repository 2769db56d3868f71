#include "sdpslam/core/permanent_map.h"

namespace sdpslam {

namespace {

constexpr std::int32_t kMaxAxisCells = 1 << 20;

std::uint32_t tiles_along(std::int32_t cells, std::uint32_t side_log2) {
  return (static_cast<std::uint32_t>(cells) + (1U << side_log2) - 1U) >> side_log2;
}

}  // namespace

std::size_t PermanentMap::required_bytes(std::int32_t width_cells, std::int32_t height_cells,
                                         std::uint32_t tile_capacity) {
  if (width_cells <= 0 || height_cells <= 0 || width_cells > kMaxAxisCells || height_cells > kMaxAxisCells) return 0U;
  const std::size_t tiles = static_cast<std::size_t>(tiles_along(width_cells, kSideLog2)) *
                            tiles_along(height_cells, kSideLog2);
  if (tile_capacity == 0U) return 0U;
  if (tile_capacity > tiles) tile_capacity = static_cast<std::uint32_t>(tiles);
  return Arena::bytes_for<std::uint32_t>(tiles) + Arena::bytes_for<Cell>(static_cast<std::size_t>(tile_capacity) * kCells);
}

bool PermanentMap::init(Arena& arena, std::int32_t width_cells, std::int32_t height_cells, std::uint32_t tile_capacity) {
  table_ = nullptr;
  const std::size_t need = required_bytes(width_cells, height_cells, tile_capacity);
  if (need == 0U || arena.available_bytes() < need) return false;
  width_cells_ = width_cells;
  height_cells_ = height_cells;
  tiles_x_ = tiles_along(width_cells, kSideLog2);
  tiles_y_ = tiles_along(height_cells, kSideLog2);
  const std::size_t tiles = static_cast<std::size_t>(tiles_x_) * tiles_y_;
  tile_capacity_ = tile_capacity < tiles ? tile_capacity : static_cast<std::uint32_t>(tiles);
  tiles_used_ = 0U;
  known_cells_ = 0U;
  refused_out_of_area_ = 0U;
  refused_no_tile_ = 0U;
  std::uint32_t* table = arena.allocate_array<std::uint32_t>(tiles);
  Cell* cells = arena.allocate_array<Cell>(static_cast<std::size_t>(tile_capacity_) * kCells);
  if (table == nullptr || cells == nullptr) return false;
  for (std::size_t i = 0; i < tiles; ++i) table[i] = kNone;
  cells_ = cells;
  table_ = table;
  return true;
}

bool PermanentMap::add(std::int32_t ix, std::int32_t iy, std::uint16_t hits, std::uint16_t misses, std::uint32_t tag) {
  if (tag == 0U || !in_area(ix, iy)) {
    ++refused_out_of_area_;
    return false;
  }
  std::uint32_t& slot = tile_slot(ix, iy);
  if (slot == kNone) {
    if (tiles_used_ == tile_capacity_) {
      ++refused_no_tile_;
      return false;
    }
    slot = tiles_used_++;
    Cell* tile = cells_ + static_cast<std::size_t>(slot) * kCells;
    for (std::uint32_t i = 0; i < kCells; ++i) tile[i] = Cell{};
  }
  Cell& c = cell_in(slot, ix, iy);
  const std::uint32_t before = static_cast<std::uint32_t>(c.value.hits) + c.value.misses;
  const std::uint32_t added = static_cast<std::uint32_t>(hits) + misses;
  if (c.tag == 0U) ++known_cells_;
  if (c.tag == 0U || added >= before) c.tag = tag;
  c.value = accumulate(c.value, hits, misses);
  return true;
}

PermanentMap::Cell PermanentMap::cell(std::int32_t ix, std::int32_t iy) const {
  if (!in_area(ix, iy)) return Cell{};
  const std::uint32_t slot = tile_slot(ix, iy);
  return slot == kNone ? Cell{} : cell_in(slot, ix, iy);
}

}  // namespace sdpslam
