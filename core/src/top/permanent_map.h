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
// Layout (fixed memory from the Arena at init): up to tile_capacity tiles of
// capacity::kDpTileSideCells² 8-byte cells {hits, misses, tag}, taken in order on the
// first write into a tile and never released (the permanent map only grows), and an
// open-addressing table (linear probing, twice the tiles rounded up to a power of two,
// so at most half full) from a tile's coordinates to its slot. Cell coordinates are any
// int32 in the DP map's cell frame (same origin and resolution): the area has no bound,
// only the number of tiles does, so a building of any size keeps its map as long as
// the tiles last. A cell written by two levels keeps the sum of their counts
// (accumulate(), which saturates keeping the ratio) and the tag of the larger
// contribution: it is drawn with the correction of the level that saw it most. Tag 0 =
// no data.
//
// Compared with keeping the permanent map as one more node of the DP map, it costs 8
// bytes per cell of each touched tile instead of 24 bytes per known cell (an
// observation slot) in the shared observation pool, so the bottom level's map no longer
// competes with it.
//
// Full store: compacted, not lost (issue: memory is fixed, the world is not). When a
// write needs a new tile and every tile is taken, the whole map is coarsened once:
// every 2×2 block of cells becomes one cell (counts summed with accumulate(), the tag
// chosen by add()'s rule as if the four cells were written into it in turn), so every
// 2×2 block of tiles becomes one tile and about three tiles in four are freed where the
// map is dense. Cells are then kept at twice the side (scale_log2() counts the halvings)
// and every later write lands in the cell covering it. SdpSlam::for_each_permanent_cell
// gives each coarse cell as the block of fine cells it covers, and the global map image
// is drawn at the coarse cell's size. Each compaction is counted and reported
// (compactions(), stats.json), as is the cell side it left. Cost: one pass over the
// stored cells (tile_capacity × 256), with a sort of the tile slots, only when the store
// is full. Up to kMaxScaleLog2 halvings (a 5 cm grid becomes 12.8 m cells): beyond that
// a write into a new tile is refused and counted (refused_no_tile), the only refusal.
//
// Errors are results and counters: a write with tag 0, or into a new tile when every
// tile is taken and the map is as coarse as it may become, returns false and is counted;
// the map stays consistent.
#include <cstddef>
#include <cstdint>

#include "sdpslam/core/arena.h"
#include "sdpslam/core/capacities.h"
#include "sdpslam/core/bottom/dp_map.h"
#include "sdpslam/core/state_io.h"

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

  // Arena bytes init() needs for tile_capacity tiles; 0 iff tile_capacity is 0 or above
  // capacity::kDpMaxTiles.
  static std::size_t required_bytes(std::uint32_t tile_capacity);

  // Carves its storage from `arena`. False iff tile_capacity is out of range or the arena
  // is too small (the map then refuses every write). Call once.
  bool init(Arena& arena, std::uint32_t tile_capacity);

  // Halvings of the cell side the store may make when full (see the header comment).
  static constexpr std::uint32_t kMaxScaleLog2 = 8U;

  // Adds (hits, misses) to the cell covering fine cell (ix, iy) with `tag` (> 0). False,
  // counted, iff the tag is 0 or the map is not initialised (refused_untagged), or the
  // cell's tile is new, every tile is taken and the map is already kMaxScaleLog2 times
  // coarsened (refused_no_tile). O(1) expected; a compaction when the store is full.
  bool add(std::int32_t ix, std::int32_t iy, std::uint16_t hits, std::uint16_t misses, std::uint32_t tag);

  // The cell covering fine cell (ix, iy); tag 0 when unknown. O(1) expected.
  Cell cell(std::int32_t ix, std::int32_t iy) const;

  // f(ix, iy, const Cell&) for every known cell, in the coordinates of the current scale
  // (a cell covers fine cells [ix·2^s, (ix+1)·2^s) × [iy·2^s, (iy+1)·2^s), s =
  // scale_log2()), tile by tile in row-major order of the tiles' coordinates
  // (deterministic, whatever order they were written in), row-major within a tile.
  // O(tiles in the bounding box of the used ones).
  template <class F>
  void for_each_cell(F&& f) const;

  std::uint32_t tile_capacity() const { return tile_capacity_; }
  std::uint32_t tiles_used() const { return tiles_used_; }
  std::uint64_t known_cells() const { return known_cells_; }
  std::uint64_t refused_untagged() const { return refused_untagged_; }
  std::uint64_t refused_no_tile() const { return refused_no_tile_; }
  // Halvings of the cell side so far (0: the DP map's resolution), and how many times the
  // store was full and compacted (equal: one halving per compaction).
  std::uint32_t scale_log2() const { return scale_log2_; }
  std::uint64_t compactions() const { return compactions_; }
  bool initialised() const { return table_ != nullptr; }

  // The mutable state, for snapshots (core/state_io.h): what init() did not fix.
  void transfer_state(StateIo& io);

 private:
  static constexpr std::uint32_t kSideLog2 = capacity::kDpTileSideLog2;
  static constexpr std::uint32_t kSide = capacity::kDpTileSideCells;
  static constexpr std::uint32_t kCells = capacity::kDpTileCells;
  static constexpr std::uint32_t kNone = 0xFFFFFFFFU;

  // A tile's key: its coordinates floor(i / kSide) as the high bits of the cell
  // coordinates' two's complement (one key per tile over all of int32).
  static std::uint64_t tile_key(std::int32_t ix, std::int32_t iy) {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(iy) >> kSideLog2) << 32U) |
           (static_cast<std::uint32_t>(ix) >> kSideLog2);
  }
  // Table position of `key`: its slot's entry if the tile exists, else the empty entry
  // where it would go.
  std::uint32_t probe(std::uint64_t key) const {
    std::uint32_t i = static_cast<std::uint32_t>((key * 0x9E3779B97F4A7C15ULL) >> table_shift_);
    while (table_[i] != kNone && keys_[table_[i]] != key) i = (i + 1U) & table_mask_;
    return i;
  }
  // The slot of the tile holding (ix, iy), kNone if it has none.
  std::uint32_t find_slot(std::int32_t ix, std::int32_t iy) const {
    return table_ == nullptr ? kNone : table_[probe(tile_key(ix, iy))];
  }
  // The fine cell (ix, iy) in the coordinates of the current scale.
  std::int32_t coarse(std::int32_t v) const;
  // Inserts a fresh tile for the scaled cell (ix, iy) at table position `at`; false iff
  // every tile is taken.
  bool new_tile(std::uint32_t at, std::uint64_t key, std::int32_t ix, std::int32_t iy);
  // Grows the used tiles' bounding box by tile (tx, ty), stored at `slot` (slot 0 starts it).
  void include_tile(std::uint32_t slot, std::int32_t tx, std::int32_t ty);
  // Coarsens the whole store once (header comment); false iff it is already at
  // kMaxScaleLog2.
  bool compact();
  // Rebuilds the table, the bounding box and the known-cell count from slots
  // [0, tiles_used_).
  void reindex();
  // Cell (ix, iy) inside the tile stored at `slot`.
  Cell& cell_in(std::uint32_t slot, std::int32_t ix, std::int32_t iy) const {
    const std::uint32_t in_tile = ((static_cast<std::uint32_t>(iy) & (kSide - 1U)) << kSideLog2) +
                                  (static_cast<std::uint32_t>(ix) & (kSide - 1U));
    return cells_[static_cast<std::size_t>(slot) * kCells + in_tile];
  }

  std::uint32_t tile_capacity_ = 0U;
  std::uint32_t tiles_used_ = 0U;
  std::uint32_t* table_ = nullptr;  // table_mask_ + 1 entries: a tile slot, or kNone
  std::uint32_t table_mask_ = 0U;
  std::uint32_t table_shift_ = 63U;  // 64 − log2(table entries)
  std::uint64_t* keys_ = nullptr;    // tile_capacity_: each slot's tile key
  Cell* cells_ = nullptr;            // tile_capacity_ × kCells
  std::uint32_t* order_ = nullptr;   // tile_capacity_: compact()'s slots sorted by new key
  std::uint64_t* new_keys_ = nullptr;  // tile_capacity_: each slot's key after the halving
  Cell* scratch_ = nullptr;          // kCells: the tile being merged
  std::uint32_t* scratch_weight_ = nullptr;  // kCells: its cells' counts merged so far
  std::uint32_t scale_log2_ = 0U;
  std::uint64_t compactions_ = 0U;
  // Bounding box of the used tiles, in tile coordinates (for_each_cell's order).
  std::int32_t tx0_ = 0, ty0_ = 0, tx1_ = -1, ty1_ = -1;
  std::uint64_t known_cells_ = 0U;
  std::uint64_t refused_untagged_ = 0U;
  std::uint64_t refused_no_tile_ = 0U;
};

template <class F>
void PermanentMap::for_each_cell(F&& f) const {
  if (table_ == nullptr) return;
  for (std::int64_t ty = ty0_; ty <= ty1_; ++ty) {
    for (std::int64_t tx = tx0_; tx <= tx1_; ++tx) {
      const auto ox = static_cast<std::int32_t>(tx * kSide);
      const auto oy = static_cast<std::int32_t>(ty * kSide);
      const std::uint32_t slot = find_slot(ox, oy);
      if (slot == kNone) continue;
      const Cell* tile = cells_ + static_cast<std::size_t>(slot) * kCells;
      for (std::uint32_t i = 0; i < kCells; ++i) {
        if (tile[i].tag == 0U) continue;
        f(ox + static_cast<std::int32_t>(i & (kSide - 1U)), oy + static_cast<std::int32_t>(i >> kSideLog2), tile[i]);
      }
    }
  }
}

}  // namespace sdpslam
