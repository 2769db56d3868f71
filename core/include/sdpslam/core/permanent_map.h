#pragma once
// The global map's permanent part (SDP-SLAM, paper §III; "permanent components" of its
// future work): the submaps of the levels made permanent, each copied once into one grid
// at the place its frame had when it was copied, every cell TAGGED with the level that
// put it there.
//
// Why tags: loop closure keeps moving the frames of permanent submaps after their copy
// (frame_graph.h). A merged grid without tags can only be drawn where its cells were
// copied, so the map would lag the trajectory by the corrections made since (metres on
// ACES). With a tag per cell, the map is drawn with each cell moved by its own level's
// correction, frame_now ⊕ frame_at_copy⁻¹ (SdpSlam::for_each_permanent_cell).
//
// Layout (fixed memory from the Arena at init): a tile table, one u32 per tile of
// capacity::kDpTileSideCells² cells over the DP map's area, and up to tile_capacity
// tiles of 8-byte cells {hits, misses, tag}, taken in order on the first write into a
// tile and never released (the permanent map only grows). A cell written by two levels
// keeps the sum of their counts (accumulate(), which saturates keeping the ratio) and
// the tag of the larger contribution: it is drawn with the correction of the level that
// saw it most. Tag 0 = no data.
//
// Compared with keeping the permanent map as one more node of the DP map, it costs 8
// bytes per cell of each touched tile instead of ~32 bytes per known cell (an
// observation slot and its pool links) in the shared observation pool, so the bottom level's map no longer competes with it.
//
// Errors are results and counters: a write outside the area or into a new tile when
// every tile is taken returns false and is counted; the map stays consistent.
#include <cstddef>
#include <cstdint>

#include "sdpslam/core/arena.h"
#include "sdpslam/core/capacities.h"
#include "sdpslam/core/dp_map.h"

namespace sdpslam {

class PermanentMap {
 public:
  struct Cell {
    CellObservation value{};
    std::uint32_t tag = 0U;  // 0 = unknown; otherwise what the caller wrote (SdpSlam: level + 1)
  };

  PermanentMap() = default;
  PermanentMap(const PermanentMap&) = delete;
  PermanentMap& operator=(const PermanentMap&) = delete;

  // Arena bytes init() needs for an area of width × height cells and tile_capacity
  // tiles (at most the tiles the area holds are provisioned); 0 iff the sizes are out of
  // range (an axis of 0 or over 2^20 cells, or no tiles).
  static std::size_t required_bytes(std::int32_t width_cells, std::int32_t height_cells, std::uint32_t tile_capacity);

  // Carves its storage from `arena`. False iff the sizes are out of range or the arena is
  // too small (the map then refuses every write). tile_capacity() is the requested
  // capacity, or the tiles of the area if fewer. Call once.
  bool init(Arena& arena, std::int32_t width_cells, std::int32_t height_cells, std::uint32_t tile_capacity);

  // Adds (hits, misses) to cell (ix, iy) with `tag` (> 0). False, counted, iff the cell is
  // outside the area, the tag is 0, or the cell's tile is new and every tile is taken.
  bool add(std::int32_t ix, std::int32_t iy, std::uint16_t hits, std::uint16_t misses, std::uint32_t tag);

  // The cell (ix, iy); tag 0 when unknown or outside the area.
  Cell cell(std::int32_t ix, std::int32_t iy) const;

  // f(ix, iy, const Cell&) for every known cell, tile by tile in row-major tile order
  // (deterministic), row-major within a tile.
  template <class F>
  void for_each_cell(F&& f) const;

  std::uint32_t tile_capacity() const { return tile_capacity_; }
  std::uint32_t tiles_used() const { return tiles_used_; }
  std::uint64_t known_cells() const { return known_cells_; }
  std::uint64_t refused_out_of_area() const { return refused_out_of_area_; }
  std::uint64_t refused_no_tile() const { return refused_no_tile_; }
  bool initialised() const { return table_ != nullptr; }

 private:
  static constexpr std::uint32_t kSideLog2 = capacity::kDpTileSideLog2;
  static constexpr std::uint32_t kSide = capacity::kDpTileSideCells;
  static constexpr std::uint32_t kCells = capacity::kDpTileCells;
  static constexpr std::uint32_t kNone = 0xFFFFFFFFU;

  bool in_area(std::int32_t ix, std::int32_t iy) const {
    return table_ != nullptr && ix >= 0 && iy >= 0 && ix < width_cells_ && iy < height_cells_;
  }
  // The tile-table slot of cell (ix, iy), which must be in the area.
  std::uint32_t& tile_slot(std::int32_t ix, std::int32_t iy) const {
    return table_[(static_cast<std::uint32_t>(iy) >> kSideLog2) * tiles_x_ + (static_cast<std::uint32_t>(ix) >> kSideLog2)];
  }
  // Cell (ix, iy) inside the tile stored at `slot`.
  Cell& cell_in(std::uint32_t slot, std::int32_t ix, std::int32_t iy) const {
    const std::uint32_t in_tile = ((static_cast<std::uint32_t>(iy) & (kSide - 1U)) << kSideLog2) +
                                  (static_cast<std::uint32_t>(ix) & (kSide - 1U));
    return cells_[static_cast<std::size_t>(slot) * kCells + in_tile];
  }

  std::int32_t width_cells_ = 0;
  std::int32_t height_cells_ = 0;
  std::uint32_t tiles_x_ = 0U;
  std::uint32_t tiles_y_ = 0U;
  std::uint32_t tile_capacity_ = 0U;
  std::uint32_t tiles_used_ = 0U;
  std::uint32_t* table_ = nullptr;  // tiles_x_ × tiles_y_ slots (kNone = no tile)
  Cell* cells_ = nullptr;           // tile_capacity_ × kCells
  std::uint64_t known_cells_ = 0U;
  std::uint64_t refused_out_of_area_ = 0U;
  std::uint64_t refused_no_tile_ = 0U;
};

template <class F>
void PermanentMap::for_each_cell(F&& f) const {
  if (table_ == nullptr) return;
  for (std::uint32_t ty = 0; ty < tiles_y_; ++ty) {
    for (std::uint32_t tx = 0; tx < tiles_x_; ++tx) {
      const std::uint32_t slot = table_[ty * tiles_x_ + tx];
      if (slot == kNone) continue;
      const Cell* tile = cells_ + static_cast<std::size_t>(slot) * kCells;
      for (std::uint32_t i = 0; i < kCells; ++i) {
        if (tile[i].tag == 0U) continue;
        const auto ix = static_cast<std::int32_t>((tx << kSideLog2) + (i & (kSide - 1U)));
        const auto iy = static_cast<std::int32_t>((ty << kSideLog2) + (i >> kSideLog2));
        f(ix, iy, tile[i]);
      }
    }
  }
}

}  // namespace sdpslam
