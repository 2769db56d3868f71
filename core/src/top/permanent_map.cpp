#include "top/permanent_map.h"

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

// The tile origin (fine cells of the current scale) a key stands for: tile_key()'s
// unsigned high bits back to signed coordinates.
std::int32_t origin_of(std::uint64_t key_half, std::uint32_t side_log2) {
  const std::int64_t u = static_cast<std::int64_t>((key_half & 0xFFFFFFFFULL) << side_log2) & 0xFFFFFFFFLL;
  return static_cast<std::int32_t>(u >= 0x80000000LL ? u - 0x100000000LL : u);
}

}  // namespace

std::size_t PermanentMap::required_bytes(std::uint32_t tile_capacity) {
  if (tile_capacity == 0U || tile_capacity > capacity::kDpMaxTiles) return 0U;
  return Arena::bytes_for<std::uint32_t>(table_entries_for(tile_capacity)) +
         Arena::bytes_for<std::uint64_t>(tile_capacity) +
         Arena::bytes_for<Cell>(static_cast<std::size_t>(tile_capacity) * kCells) +
         Arena::bytes_for<std::uint32_t>(tile_capacity) + Arena::bytes_for<std::uint64_t>(tile_capacity) +
         Arena::bytes_for<Cell>(kCells) + Arena::bytes_for<std::uint32_t>(kCells);
}

bool PermanentMap::init(Arena& arena, std::uint32_t tile_capacity) {
  table_ = nullptr;
  const std::size_t need = required_bytes(tile_capacity);
  if (need == 0U || arena.available_bytes() < need) return false;
  const std::size_t entries = table_entries_for(tile_capacity);
  std::uint32_t* table = arena.allocate_array<std::uint32_t>(entries);
  std::uint64_t* keys = arena.allocate_array<std::uint64_t>(tile_capacity);
  Cell* cells = arena.allocate_array<Cell>(static_cast<std::size_t>(tile_capacity) * kCells);
  std::uint32_t* order = arena.allocate_array<std::uint32_t>(tile_capacity);
  std::uint64_t* new_keys = arena.allocate_array<std::uint64_t>(tile_capacity);
  Cell* scratch = arena.allocate_array<Cell>(kCells);
  std::uint32_t* weight = arena.allocate_array<std::uint32_t>(kCells);
  if (table == nullptr || keys == nullptr || cells == nullptr || order == nullptr || new_keys == nullptr ||
      scratch == nullptr || weight == nullptr) {
    return false;
  }
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
  scale_log2_ = 0U;
  compactions_ = 0U;
  tx0_ = ty0_ = 0;
  tx1_ = ty1_ = -1;
  keys_ = keys;
  cells_ = cells;
  order_ = order;
  new_keys_ = new_keys;
  scratch_ = scratch;
  scratch_weight_ = weight;
  table_ = table;
  return true;
}

std::int32_t PermanentMap::coarse(std::int32_t v) const { return floor_shift(v, scale_log2_); }

bool PermanentMap::new_tile(std::uint32_t at, std::uint64_t key, std::int32_t ix, std::int32_t iy) {
  if (tiles_used_ == tile_capacity_) return false;
  const std::uint32_t slot = tiles_used_++;
  table_[at] = slot;
  keys_[slot] = key;
  Cell* tile = cells_ + static_cast<std::size_t>(slot) * kCells;
  for (std::uint32_t i = 0; i < kCells; ++i) tile[i] = Cell{};
  include_tile(slot, floor_shift(ix, kSideLog2), floor_shift(iy, kSideLog2));
  return true;
}

void PermanentMap::include_tile(std::uint32_t slot, std::int32_t tx, std::int32_t ty) {
  if (slot == 0U) {
    tx0_ = tx1_ = tx;
    ty0_ = ty1_ = ty;
    return;
  }
  if (tx < tx0_) tx0_ = tx;
  if (tx > tx1_) tx1_ = tx;
  if (ty < ty0_) ty0_ = ty;
  if (ty > ty1_) ty1_ = ty;
}

void PermanentMap::reindex() {
  for (std::uint32_t i = 0; i <= table_mask_; ++i) table_[i] = kNone;
  known_cells_ = 0U;
  tx0_ = ty0_ = 0;
  tx1_ = ty1_ = -1;
  for (std::uint32_t slot = 0; slot < tiles_used_; ++slot) {
    table_[probe(keys_[slot])] = slot;
    include_tile(slot, floor_shift(origin_of(keys_[slot], kSideLog2), kSideLog2),
                 floor_shift(origin_of(keys_[slot] >> 32U, kSideLog2), kSideLog2));
    const Cell* tile = cells_ + static_cast<std::size_t>(slot) * kCells;
    for (std::uint32_t i = 0; i < kCells; ++i) known_cells_ += tile[i].tag != 0U ? 1U : 0U;
  }
}

bool PermanentMap::compact() {
  if (scale_log2_ >= kMaxScaleLog2 || table_ == nullptr) return false;
  const std::uint32_t n = tiles_used_;
  // Each tile's key once its cells are halved: its origin halved, floored to a tile.
  for (std::uint32_t slot = 0; slot < n; ++slot) {
    const std::int32_t ox = floor_shift(origin_of(keys_[slot], kSideLog2), 1U);
    const std::int32_t oy = floor_shift(origin_of(keys_[slot] >> 32U, kSideLog2), 1U);
    new_keys_[slot] = tile_key(ox, oy);
    order_[slot] = slot;
  }
  // Slots grouped by new key: binary insertion sort on (key, slot), deterministic and in
  // place (at most n²/2 index moves, once per compaction).
  for (std::uint32_t i = 1; i < n; ++i) {
    const std::uint32_t v = order_[i];
    std::uint32_t lo = 0U;
    std::uint32_t hi = i;
    while (lo < hi) {
      const std::uint32_t mid = lo + (hi - lo) / 2U;
      const std::uint32_t o = order_[mid];
      if (new_keys_[o] < new_keys_[v] || (new_keys_[o] == new_keys_[v] && o < v)) lo = mid + 1U;
      else hi = mid;
    }
    for (std::uint32_t k = i; k > lo; --k) order_[k] = order_[k - 1U];
    order_[lo] = v;
  }
  // Merge each group into the scratch tile, then into the group's lowest slot (all of
  // the group is read by then); the other slots of the group are freed (key marked).
  constexpr std::uint64_t kFreed = ~0ULL;
  std::uint32_t g = 0U;
  while (g < n) {
    std::uint32_t e = g + 1U;
    while (e < n && new_keys_[order_[e]] == new_keys_[order_[g]]) ++e;
    for (std::uint32_t i = 0; i < kCells; ++i) {
      scratch_[i] = Cell{};
      scratch_weight_[i] = 0U;
    }
    std::uint32_t target = order_[g];
    const std::uint64_t nk = new_keys_[order_[g]];
    const std::int32_t nox = origin_of(nk, kSideLog2);
    const std::int32_t noy = origin_of(nk >> 32U, kSideLog2);
    for (std::uint32_t k = g; k < e; ++k) {
      const std::uint32_t slot = order_[k];
      if (slot < target) target = slot;
      const std::int32_t ox = origin_of(keys_[slot], kSideLog2);
      const std::int32_t oy = origin_of(keys_[slot] >> 32U, kSideLog2);
      const Cell* tile = cells_ + static_cast<std::size_t>(slot) * kCells;
      for (std::uint32_t i = 0; i < kCells; ++i) {
        const Cell& c = tile[i];
        if (c.tag == 0U) continue;
        const std::int32_t cx = floor_shift(ox + static_cast<std::int32_t>(i & (kSide - 1U)), 1U) - nox;
        const std::int32_t cy = floor_shift(oy + static_cast<std::int32_t>(i >> kSideLog2), 1U) - noy;
        const std::uint32_t j = (static_cast<std::uint32_t>(cy) << kSideLog2) + static_cast<std::uint32_t>(cx);
        // The rule of add(): a contribution at least as large as all before it takes the
        // tag (cells merged in slot, then row-major order: deterministic).
        const std::uint32_t w = static_cast<std::uint32_t>(c.value.hits) + c.value.misses;
        Cell& m = scratch_[j];
        if (m.tag == 0U || w >= scratch_weight_[j]) m.tag = c.tag;
        scratch_weight_[j] += w;
        m.value = accumulate(m.value, c.value.hits, c.value.misses);
      }
    }
    for (std::uint32_t k = g; k < e; ++k) keys_[order_[k]] = kFreed;
    keys_[target] = nk;
    Cell* dst = cells_ + static_cast<std::size_t>(target) * kCells;
    for (std::uint32_t i = 0; i < kCells; ++i) dst[i] = scratch_[i];
    g = e;
  }
  // Close the gaps, keeping the slots' order.
  std::uint32_t used = 0U;
  for (std::uint32_t slot = 0; slot < n; ++slot) {
    if (keys_[slot] == kFreed) continue;
    if (slot != used) {
      keys_[used] = keys_[slot];
      const Cell* src = cells_ + static_cast<std::size_t>(slot) * kCells;
      Cell* dst = cells_ + static_cast<std::size_t>(used) * kCells;
      for (std::uint32_t i = 0; i < kCells; ++i) dst[i] = src[i];
    }
    ++used;
  }
  tiles_used_ = used;
  ++scale_log2_;
  ++compactions_;
  reindex();
  return true;
}

bool PermanentMap::add(std::int32_t ix, std::int32_t iy, std::uint16_t hits, std::uint16_t misses, std::uint32_t tag) {
  if (tag == 0U || table_ == nullptr) {
    ++refused_untagged_;
    return false;
  }
  std::int32_t cx = coarse(ix);
  std::int32_t cy = coarse(iy);
  std::uint64_t key = tile_key(cx, cy);
  std::uint32_t at = probe(key);
  while (table_[at] == kNone && !new_tile(at, key, cx, cy)) {
    // Full: coarsen once and look again (the cell may now fall in a stored tile).
    if (!compact()) {
      ++refused_no_tile_;
      return false;
    }
    cx = coarse(ix);
    cy = coarse(iy);
    key = tile_key(cx, cy);
    at = probe(key);
  }
  Cell& c = cell_in(table_[at], cx, cy);
  const std::uint32_t before = static_cast<std::uint32_t>(c.value.hits) + c.value.misses;
  const std::uint32_t added = static_cast<std::uint32_t>(hits) + misses;
  if (c.tag == 0U) ++known_cells_;
  if (c.tag == 0U || added >= before) c.tag = tag;
  c.value = accumulate(c.value, hits, misses);
  return true;
}

PermanentMap::Cell PermanentMap::cell(std::int32_t ix, std::int32_t iy) const {
  if (table_ == nullptr) return Cell{};
  const std::int32_t cx = coarse(ix);
  const std::int32_t cy = coarse(iy);
  const std::uint32_t slot = find_slot(cx, cy);
  return slot == kNone ? Cell{} : cell_in(slot, cx, cy);
}

void PermanentMap::transfer_state(StateIo& io) {
  io.section("permanent_map");
  io.fixed(tile_capacity_, "permanent map capacity");
  io.value(tiles_used_);
  io.value(table_mask_);
  io.value(table_shift_);
  io.value(scale_log2_);
  io.value(compactions_);
  io.value(tx0_);
  io.value(ty0_);
  io.value(tx1_);
  io.value(ty1_);
  io.value(known_cells_);
  io.value(refused_untagged_);
  io.value(refused_no_tile_);
}

}  // namespace sdpslam
