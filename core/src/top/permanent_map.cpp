#include "sdpslam/core/top/permanent_map.h"

namespace sdpslam {

namespace {

// Table entries: twice the tiles, rounded up to a power of two (load at most 1/2).
std::size_t table_entries_for(std::uint32_t tile_capacity) {
  std::size_t n = 2U;
  while (n < 2U * static_cast<std::size_t>(tile_capacity)) n <<= 1U;
  return n;
}

// floor(v / 2^k) for any int32 (an arithmetic shift without relying on it).
std::int32_t floor_shift(std::int32_t v, std::uint32_t k) {
  const std::int64_t d = std::int64_t{1} << k;
  const std::int64_t q = static_cast<std::int64_t>(v) / d;
  return static_cast<std::int32_t>((static_cast<std::int64_t>(v) % d) < 0 ? q - 1 : q);
}

}  // namespace

std::size_t PermanentMap::required_bytes(std::uint32_t tile_capacity) {
  if (tile_capacity == 0U || tile_capacity > capacity::kDpMaxTiles) return 0U;
  return Arena::bytes_for<std::uint32_t>(table_entries_for(tile_capacity)) +
         Arena::bytes_for<std::uint64_t>(tile_capacity) +
         Arena::bytes_for<Cell>(static_cast<std::size_t>(tile_capacity) * kCells);
}

bool PermanentMap::init(Arena& arena, std::uint32_t tile_capacity) {
  table_ = nullptr;
  const std::size_t need = required_bytes(tile_capacity);
  if (need == 0U || arena.available_bytes() < need) return false;
  const std::size_t entries = table_entries_for(tile_capacity);
  std::uint32_t* table = arena.allocate_array<std::uint32_t>(entries);
  std::uint64_t* keys = arena.allocate_array<std::uint64_t>(tile_capacity);
  Cell* cells = arena.allocate_array<Cell>(static_cast<std::size_t>(tile_capacity) * kCells);
  if (table == nullptr || keys == nullptr || cells == nullptr) return false;
  for (std::size_t i = 0; i < entries; ++i) table[i] = kNone;
  std::uint32_t bits = 0U;
  while ((std::size_t{1} << bits) < entries) ++bits;
  table_mask_ = static_cast<std::uint32_t>(entries - 1U);
  table_shift_ = 64U - bits;
  tile_capacity_ = tile_capacity;
  tiles_used_ = 0U;
  known_cells_ = 0U;
  refused_untagged_ = 0U;
  refused_no_tile_ = 0U;
  tx0_ = ty0_ = 0;
  tx1_ = ty1_ = -1;
  keys_ = keys;
  cells_ = cells;
  table_ = table;
  return true;
}

bool PermanentMap::add(std::int32_t ix, std::int32_t iy, std::uint16_t hits, std::uint16_t misses, std::uint32_t tag) {
  if (tag == 0U || table_ == nullptr) {
    ++refused_untagged_;
    return false;
  }
  const std::uint64_t key = tile_key(ix, iy);
  const std::uint32_t at = probe(key);
  if (table_[at] == kNone) {
    if (tiles_used_ == tile_capacity_) {
      ++refused_no_tile_;
      return false;
    }
    const std::uint32_t slot = tiles_used_++;
    table_[at] = slot;
    keys_[slot] = key;
    Cell* tile = cells_ + static_cast<std::size_t>(slot) * kCells;
    for (std::uint32_t i = 0; i < kCells; ++i) tile[i] = Cell{};
    const std::int32_t tx = floor_shift(ix, kSideLog2);
    const std::int32_t ty = floor_shift(iy, kSideLog2);
    if (slot == 0U) {
      tx0_ = tx1_ = tx;
      ty0_ = ty1_ = ty;
    } else {
      if (tx < tx0_) tx0_ = tx;
      if (tx > tx1_) tx1_ = tx;
      if (ty < ty0_) ty0_ = ty;
      if (ty > ty1_) ty1_ = ty;
    }
  }
  Cell& c = cell_in(table_[at], ix, iy);
  const std::uint32_t before = static_cast<std::uint32_t>(c.value.hits) + c.value.misses;
  const std::uint32_t added = static_cast<std::uint32_t>(hits) + misses;
  if (c.tag == 0U) ++known_cells_;
  if (c.tag == 0U || added >= before) c.tag = tag;
  c.value = accumulate(c.value, hits, misses);
  return true;
}

PermanentMap::Cell PermanentMap::cell(std::int32_t ix, std::int32_t iy) const {
  const std::uint32_t slot = find_slot(ix, iy);
  return slot == kNone ? Cell{} : cell_in(slot, ix, iy);
}

}  // namespace sdpslam
