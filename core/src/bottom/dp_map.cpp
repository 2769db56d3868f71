// Distributed particle map: tiled grid of per-cell observation lists (paper §II-A).
#include "sdpslam/core/bottom/dp_map.h"

#include <cmath>
#include <cstdint>
#include <new>

namespace sdpslam {

namespace {
// A hint that `p` is read soon (no effect on results); nothing where the compiler has none.
inline void prefetch(const void* p) {
#if defined(__GNUC__) || defined(__clang__)
  __builtin_prefetch(p);
#else
  (void)p;
#endif
}

// Largest torus side (cells): far below 2^31, so that coordinates a window apart stay in
// int32 wherever a lineage may draw.
constexpr std::int64_t kMaxWrapCells = std::int64_t{1} << 20;

struct GridDims {
  std::int32_t width_cells = 0;
  std::int32_t height_cells = 0;
  std::uint32_t tiles_x = 0U;
  std::uint32_t tiles_y = 0U;
};

// Whole cells covering `extent_m`; a relative tolerance keeps 10 m / 0.05 m at 200 cells
// despite the quotient's rounding error. 0 iff out of range.
std::int32_t cells_for(double extent_m, double resolution_m) {
  const double q = extent_m / resolution_m;
  if (!(q > 0.0) || !std::isfinite(q) || q >= 2147483000.0) return 0;
  return static_cast<std::int32_t>(std::ceil(q - 1e-9 * q));
}

bool grid_dims(const DpMap::Options& o, GridDims* d) {
  if (!std::isfinite(o.origin_x_m) || !std::isfinite(o.origin_y_m)) return false;
  if (!(o.resolution_m > 0.0) || !(o.width_m > 0.0) || !(o.height_m > 0.0)) return false;
  if (o.tile_capacity == 0U || o.tile_capacity > capacity::kDpMaxTiles || o.observation_capacity == 0U) return false;
  if (o.observation_capacity > capacity::kDpMaxObservations) return false;  // index_slots_for() < 2^31
  // The observation slots' bytes fit a size_t with room for the rest (32-bit targets).
  if (std::uint64_t{o.observation_capacity} * DpMap::kObservationBytes > SIZE_MAX / 2U) return false;
  d->width_cells = cells_for(o.width_m, o.resolution_m);
  d->height_cells = cells_for(o.height_m, o.resolution_m);
  if (d->width_cells <= 0 || d->height_cells <= 0) return false;
  if (o.wrap) {
    // A torus: whole tiles per axis, a power of two of them, so that a cell's place is
    // its coordinates' low bits (also for negative ones, in two's complement).
    std::int64_t w = capacity::kDpTileSideCells;
    std::int64_t h = capacity::kDpTileSideCells;
    while (w < d->width_cells) w <<= 1;
    while (h < d->height_cells) h <<= 1;
    if (w > kMaxWrapCells || h > kMaxWrapCells) return false;
    d->width_cells = static_cast<std::int32_t>(w);
    d->height_cells = static_cast<std::int32_t>(h);
  }
  const std::uint32_t side = capacity::kDpTileSideCells;
  d->tiles_x = (static_cast<std::uint32_t>(d->width_cells) + side - 1U) / side;
  d->tiles_y = (static_cast<std::uint32_t>(d->height_cells) + side - 1U) / side;
  return static_cast<std::uint64_t>(d->tiles_x) * d->tiles_y < 0xFFFFFFFFULL;
}

// owner → node, node → owner, owner list head, owner count, free-owner stack, owner →
// tree sequence, owner → view mark.
constexpr std::size_t kOwnerTables = 7U;

template <typename T>
std::size_t pool_bytes(std::uint32_t capacity) {
  return PoolOf<T>::kSlotSize * capacity + 2U * sizeof(std::uint32_t) * capacity + alignof(T) +
         2U * alignof(std::uint32_t);
}

}  // namespace

std::int32_t DpMap::cells_along(double extent_m, double resolution_m) { return cells_for(extent_m, resolution_m); }

std::size_t DpMap::index_slots_for(std::uint32_t observation_capacity) {
  const std::size_t want = static_cast<std::size_t>(observation_capacity) + observation_capacity / 2U + 1U;
  std::size_t slots = 2U;
  while (slots < want) slots <<= 1U;
  return slots;
}

bool DpMap::options_valid(const Options& options) {
  GridDims d;
  return grid_dims(options, &d);
}

std::size_t DpMap::required_arena_bytes(const Options& options, std::uint32_t node_capacity) {
  GridDims d;
  if (!grid_dims(options, &d)) return 0U;
  return sizeof(std::uint32_t) * (static_cast<std::size_t>(d.tiles_x) * d.tiles_y + kOwnerTables * node_capacity) +
         3U * alignof(std::uint32_t) +
         (options.owner_cell_index ? sizeof(std::uint32_t) * index_slots_for(options.observation_capacity) : 0U) +
         pool_bytes<Tile>(options.tile_capacity) + sizeof(Observation) * options.observation_capacity +
         alignof(Observation);
}

bool DpMap::init(Arena& arena, const Options& options, const AncestryTree& tree) {
  tree_ = nullptr;
  GridDims d;
  if (!grid_dims(options, &d) || tree.capacity() == 0U) return false;
  const std::size_t table_entries = static_cast<std::size_t>(d.tiles_x) * d.tiles_y;
  tile_table_ = arena.allocate_array<std::uint32_t>(table_entries);
  const std::size_t cap = tree.capacity();
  std::uint32_t* owners = arena.allocate_array<std::uint32_t>(kOwnerTables * cap);
  if (tile_table_ == nullptr || owners == nullptr) return false;
  index_ = nullptr;
  index_mask_ = 0U;
  if (options.owner_cell_index) {
    const std::size_t slots = index_slots_for(options.observation_capacity);
    index_ = arena.allocate_array<std::uint32_t>(slots);
    if (index_ == nullptr) return false;
    for (std::size_t i = 0; i < slots; ++i) index_[i] = kNone;
    index_mask_ = static_cast<std::uint32_t>(slots - 1U);
    std::uint32_t bits = 0U;
    while ((std::size_t{1} << bits) < slots) ++bits;
    index_shift_ = 64U - bits;
  }
  owner_node_ = owners;
  node_owner_ = owners + cap;
  owner_head_ = owners + 2U * cap;
  owner_count_ = owners + 3U * cap;
  owner_free_ = owners + 4U * cap;
  owner_tree_ = owners + 5U * cap;
  owner_mark_ = owners + 6U * cap;
  // Raw slots, not value-initialised: a slot's memory is first touched when it is handed
  // out, so slots the map never needs are never paged in.
  obs_ = static_cast<Observation*>(
      arena.allocate(sizeof(Observation) * std::size_t{options.observation_capacity}, alignof(Observation)));
  if (obs_ == nullptr || !tiles_pool_.init(arena, options.tile_capacity)) return false;
  obs_capacity_ = options.observation_capacity;
  obs_fresh_ = 0U;
  obs_used_ = 0U;
  obs_peak_ = 0U;
  obs_free_ = kNone;
  for (std::size_t i = 0; i < table_entries; ++i) tile_table_[i] = kNone;
  // Free stack popped from the top: owner 0 is handed out first.
  for (std::uint32_t i = 0; i < tree.capacity(); ++i) {
    owner_node_[i] = kNoNode;
    node_owner_[i] = kNone;
    owner_head_[i] = kNone;
    owner_count_[i] = 0U;
    owner_free_[i] = tree.capacity() - 1U - i;
    owner_tree_[i] = 0U;
    owner_mark_[i] = 0U;
  }
  view_particle_ = kNoNode;
  view_tree_ = 0U;
  view_mark_ = 0U;
  owner_free_count_ = tree.capacity();
  options_ = options;
  width_cells_ = d.width_cells;
  height_cells_ = d.height_cells;
  tiles_x_ = d.tiles_x;
  tiles_y_ = d.tiles_y;
  wrap_ = options.wrap;
  tile_mask_x_ = wrap_ ? tiles_x_ - 1U : 0xFFFFFFFFU;
  tile_mask_y_ = wrap_ ? tiles_y_ - 1U : 0xFFFFFFFFU;
  node_capacity_ = tree.capacity();
  tiles_ = nullptr;
  tree_ = &tree;
  return true;
}

bool DpMap::world_to_cell(double x_m, double y_m, std::int32_t* ix, std::int32_t* iy) const {
  if (tree_ == nullptr) return false;
  const double fx = std::floor((x_m - options_.origin_x_m) / options_.resolution_m);
  const double fy = std::floor((y_m - options_.origin_y_m) / options_.resolution_m);
  if (wrap_) {
    // Any place has a cell; the bound only keeps the coordinates in int32 (and rejects NaN).
    constexpr double kLimit = 1073741824.0;  // 2^30 cells
    if (!(fx > -kLimit && fx < kLimit && fy > -kLimit && fy < kLimit)) return false;
    *ix = static_cast<std::int32_t>(fx);
    *iy = static_cast<std::int32_t>(fy);
    return true;
  }
  // The negated comparisons also reject NaN.
  if (!(fx >= 0.0 && fx < static_cast<double>(width_cells_) && fy >= 0.0 && fy < static_cast<double>(height_cells_))) {
    return false;
  }
  *ix = static_cast<std::int32_t>(fx);
  *iy = static_cast<std::int32_t>(fy);
  return true;
}

void DpMap::cell_center(std::int32_t ix, std::int32_t iy, double* x_m, double* y_m) const {
  *x_m = options_.origin_x_m + (static_cast<double>(ix) + 0.5) * options_.resolution_m;
  *y_m = options_.origin_y_m + (static_cast<double>(iy) + 0.5) * options_.resolution_m;
}

CellRect DpMap::rect_around(double x0, double y0, double x1, double y1, double pad_m) const {
  CellRect r{};
  if (!(x0 <= x1 && y0 <= y1)) return r;
  const double res = options_.resolution_m;
  const double ox = options_.origin_x_m;
  const double oy = options_.origin_y_m;
  auto cell = [res](double v, double o) {
    const double c = (v - o) / res;
    return c < -1.0e9 ? -1000000000 : (c > 1.0e9 ? 1000000000 : static_cast<std::int32_t>(c >= 0.0 ? c : c - 1.0));
  };
  std::int32_t ix0 = cell(x0 - pad_m, ox);
  std::int32_t iy0 = cell(y0 - pad_m, oy);
  std::int32_t ix1 = cell(x1 + pad_m, ox) + 1;
  std::int32_t iy1 = cell(y1 + pad_m, oy) + 1;
  if (wrap_) {
    // No edge; reading more than half the window would meet the other copies of its
    // cells: a centred crop.
    const auto crop = [](std::int32_t* lo, std::int32_t* hi, std::int32_t side) {
      const std::int64_t extra = static_cast<std::int64_t>(*hi) - *lo - side / 2;
      if (extra <= 0) return;
      *lo = static_cast<std::int32_t>(*lo + extra / 2);
      *hi = *lo + side / 2;
    };
    crop(&ix0, &ix1, width_cells_);
    crop(&iy0, &iy1, height_cells_);
  } else {
    if (ix0 < 0) ix0 = 0;
    if (iy0 < 0) iy0 = 0;
    if (ix1 > width_cells_) ix1 = width_cells_;
    if (iy1 > height_cells_) iy1 = height_cells_;
  }
  if (ix1 <= ix0 || iy1 <= iy0) return r;
  r.ix0 = ix0;
  r.iy0 = iy0;
  r.width = static_cast<std::uint32_t>(ix1 - ix0);
  r.height = static_cast<std::uint32_t>(iy1 - iy0);
  return r;
}

std::uint32_t DpMap::find_view(NodeId particle, std::uint32_t slot, std::uint32_t c) const {
  if (particle == view_particle_) return find_marked_view(slot, c);
  std::uint32_t e = tiles_[slot].head[c];
  if (e == kNone) return kNone;
  const std::uint32_t location = (slot << (2U * kSideLog2)) | c;
  // Entries of live nodes only (invariant), so the unchecked query is safe.
  const AncestryTree::DescendantQuery query(*tree_, particle);
  // Cell lists hold newer trees' entries before older trees' (invariants_hold), and only
  // the particle's own tree can hold its ancestors: newer trees' entries are skipped, and
  // the first older tree's entry ends the search. In SDP-SLAM every segment is a tree, so
  // a revisited cell's entries of earlier segments are not walked by the current one.
  const std::uint32_t own_tree = tree_->tree_sequence_unchecked(particle);
  NodeId up = particle;  // next ancestor-or-self whose index entry is probed
  for (;;) {
    const Observation& o = obs_[e];
    const NodeId node = owner_node_[o.owner];
    const std::uint32_t entry_tree = tree_->tree_sequence_unchecked(node);
    if (entry_tree == own_tree) {
      if (node == particle || query.has_ancestor_or_self(node)) return e;
    } else if (entry_tree < own_tree) {
      return kNone;
    }
    e = o.next_in_cell;
    if (e == kNone) return kNone;  // the list is exhausted: no ancestor-or-self here
    if (index_ == nullptr) continue;  // no index: the scan alone decides
    if (up == kNoNode) return kNone;  // every ancestor was probed: none has an entry
    const std::uint32_t owner = node_owner_[up];
    if (owner != kNone) {
      const std::uint32_t f = index_find(owner, location);
      if (f != kNone) return f;
    }
    up = tree_->parent(up);
  }
}

// Marks the owners of `particle`'s ancestors-or-self with a new view mark (a new mark
// leaves every earlier one stale, so nothing is cleared; a wrapped counter clears all).
// With the (owner, cell) index the lockstep of find_view() stays: at hundreds of
// particles, probing the ancestors beats any walk of the list.
void DpMap::begin_view(NodeId particle) {
  view_particle_ = kNoNode;
  if (tree_ == nullptr || index_ != nullptr || !tree_->contains(particle)) return;
  if (++view_mark_ == 0U) {
    for (std::uint32_t o = 0U; o < node_capacity_; ++o) owner_mark_[o] = 0U;
    view_mark_ = 1U;
  }
  for (NodeId n = particle; n != kNoNode; n = tree_->parent(n)) {
    const std::uint32_t o = node_owner_[n];
    if (o != kNone) owner_mark_[o] = view_mark_;
  }
  view_particle_ = particle;
  view_tree_ = tree_->tree_sequence_unchecked(particle);
}

// find_view() for the particle of begin_view(): the same walk (the first ancestor-or-self
// entry is the deepest; the first older tree's entry ends it), with both tests on
// per-owner tables instead of the node's tree labels.
std::uint32_t DpMap::find_marked_view(std::uint32_t slot, std::uint32_t c) const {
  for (std::uint32_t e = tiles_[slot].head[c]; e != kNone;) {
    const Observation& o = obs_[e];
    if (owner_mark_[o.owner] == view_mark_) return e;
    if (owner_tree_[o.owner] < view_tree_) return kNone;
    e = o.next_in_cell;
  }
  return kNone;
}

void DpMap::index_insert(std::uint32_t e) {
  if (index_ == nullptr) return;
  std::uint32_t i = index_home(obs_[e].owner, obs_[e].location);
  while (index_[i] != kNone) i = (i + 1U) & index_mask_;
  index_[i] = e;
}

// Backward-shift deletion (linear probing without tombstones): later members of the
// probe run move into the hole unless their home lies cyclically in (hole, position].
void DpMap::index_erase(std::uint32_t e) {
  if (index_ == nullptr) return;
  std::uint32_t i = index_home(obs_[e].owner, obs_[e].location);
  while (index_[i] != e) i = (i + 1U) & index_mask_;
  std::uint32_t j = i;
  for (;;) {
    j = (j + 1U) & index_mask_;
    const std::uint32_t f = index_[j];
    if (f == kNone) break;
    const std::uint32_t k = index_home(obs_[f].owner, obs_[f].location);
    const bool stays = i <= j ? (i < k && k <= j) : (i < k || k <= j);
    if (stays) continue;
    index_[i] = f;
    i = j;
  }
  index_[i] = kNone;
}

void DpMap::release_owner(std::uint32_t owner) {
  node_owner_[owner_node_[owner]] = kNone;
  owner_node_[owner] = kNoNode;
  owner_head_[owner] = kNone;
  owner_count_[owner] = 0U;
  owner_free_[owner_free_count_++] = owner;
}

bool DpMap::update(NodeId particle, std::int32_t ix, std::int32_t iy, CellObservation value) {
  if (tree_ == nullptr || !tree_->contains(particle)) {
    ++misuse_count_;
    return false;
  }
  if (!in_bounds(ix, iy)) {
    ++out_of_bounds_count_;
    return false;
  }
  const std::uint32_t ti = tile_index(ix, iy);
  const std::uint32_t c = cell_in_tile(ix, iy);
  const std::uint32_t slot = tile_table_[ti];
  const std::uint32_t owner = node_owner_[particle];
  if (slot != kNone && owner != kNone) {
    const std::uint32_t e = index_find(owner, (slot << (2U * kSideLog2)) | c);
    if (e != kNone) {
      obs_[e].value = value;
      return true;
    }
  }
  return insert(particle, ti, c, value);
}

bool DpMap::insert(NodeId particle, std::uint32_t ti, std::uint32_t c, CellObservation value) {
  std::uint32_t slot = tile_table_[ti];
  std::uint32_t owner = node_owner_[particle];
  // A new entry is needed. Check the observation pool first so that a refused update
  // never allocates (and then has to release) a tile.
  if (obs_free_ == kNone && obs_fresh_ == obs_capacity_) {
    ++observation_oom_count_;
    return false;
  }
  if (slot == kNone) {
    Tile* t = static_cast<Tile*>(tiles_pool_.allocate());
    if (t == nullptr) {
      ++tile_oom_count_;
      return false;
    }
    slot = tiles_pool_.index_of(t);
    tiles_ = t - slot;  // pool slots are contiguous: slot 0 is the base used by lookups
    for (std::uint32_t i = 0; i < capacity::kDpTileCells; ++i) t->head[i] = kNone;
    t->count = 0U;
    t->table_index = ti;
    tile_table_[ti] = slot;
    const std::uint32_t tx = ti % tiles_x_;
    const std::uint32_t ty = ti / tiles_x_;
    if (touched_tx0_ == kNone) {
      touched_tx0_ = touched_tx1_ = tx;
      touched_ty0_ = touched_ty1_ = ty;
    } else {
      if (tx < touched_tx0_) touched_tx0_ = tx;
      if (tx > touched_tx1_) touched_tx1_ = tx;
      if (ty < touched_ty0_) touched_ty0_ = ty;
      if (ty > touched_ty1_) touched_ty1_ = ty;
    }
  }
  if (owner == kNone) {
    // Cannot be empty: owners in use belong to distinct live nodes, `particle` has none.
    owner = owner_free_[--owner_free_count_];
    owner_node_[owner] = particle;
    node_owner_[particle] = owner;
    owner_tree_[owner] = tree_->tree_sequence_unchecked(particle);
    if (particle == view_particle_) owner_mark_[owner] = view_mark_;  // the view's own records
  }
  // The last slot freed, else the first never used (checked above: one of them exists).
  const std::uint32_t e = obs_free_ != kNone ? obs_free_ : obs_fresh_++;
  if (e == obs_free_) obs_free_ = obs_[e].next_in_node;
  Observation* o = new (&obs_[e]) Observation();
  if (++obs_used_ > obs_peak_) obs_peak_ = obs_used_;
  ++observations_made_;
  Tile& tile = tiles_[slot];
  o->owner = owner;
  o->value = value;
  o->location = (slot << (2U * kSideLog2)) | c;
  // Keep newer trees' entries before older trees' and, within a tree, descendants before
  // ancestors: a leaf goes after the entries of newer trees (first, unless it belongs to
  // an older tree, as SdpSlam's global-map root does); an inner node goes after the last
  // entry of any of its descendants. A tree's entries are contiguous, so the walk ends at
  // the first entry of an older tree.
  std::uint32_t prev = kNone;
  const std::uint32_t own_tree = owner_tree_[owner];
  const bool inner = tree_->child_count(particle) > 0U;
  for (std::uint32_t f = tile.head[c]; f != kNone; f = obs_[f].next_in_cell) {
    const std::uint32_t entry_tree = owner_tree_[obs_[f].owner];
    if (entry_tree > own_tree) {
      prev = f;
      continue;
    }
    if (entry_tree < own_tree || !inner) break;
    if (tree_->is_ancestor_or_self(particle, owner_node_[obs_[f].owner])) prev = f;
  }
  const std::uint32_t next = prev == kNone ? tile.head[c] : obs_[prev].next_in_cell;
  o->prev_in_cell = prev;
  o->next_in_cell = next;
  if (prev == kNone) {
    tile.head[c] = e;
  } else {
    obs_[prev].next_in_cell = e;
  }
  if (next != kNone) obs_[next].prev_in_cell = e;
  index_insert(e);
  o->next_in_node = owner_head_[owner];
  owner_head_[owner] = e;
  ++owner_count_[owner];
  ++tile.count;
  return true;
}

// One find_view() instead of lookup() + update(): the deepest entry of `particle` or of
// an ancestor is its view; if it is the particle's own, it is updated in place,
// otherwise the particle has none in this cell (its own would be the deepest) and a new
// one is made.
bool DpMap::add(NodeId particle, std::int32_t ix, std::int32_t iy, std::uint16_t hits, std::uint16_t misses) {
  if (tree_ == nullptr || !tree_->contains(particle)) {
    ++misuse_count_;
    return false;
  }
  if (!in_bounds(ix, iy)) {
    ++out_of_bounds_count_;
    return false;
  }
  const std::uint32_t ti = tile_index(ix, iy);
  const std::uint32_t c = cell_in_tile(ix, iy);
  const std::uint32_t slot = tile_table_[ti];
  CellObservation view{};
  if (slot != kNone) {
    const std::uint32_t e = find_view(particle, slot, c);
    if (e != kNone) {
      Observation& o = obs_[e];
      if (o.owner == node_owner_[particle]) {
        o.value = accumulate(o.value, hits, misses);
        return true;
      }
      view = o.value;
    }
  }
  return insert(particle, ti, c, accumulate(view, hits, misses));
}

std::uint32_t DpMap::add_run(NodeId particle, const CellAdd* adds, std::uint32_t count) {
  std::uint32_t dropped = 0U;
  const auto refused = [&](const CellAdd& a) { dropped += static_cast<std::uint32_t>(a.hits) + a.misses; };
  if (particle != view_particle_ || tree_ == nullptr || !tree_->contains(particle)) {
    for (std::uint32_t i = 0; i < count; ++i) {
      if (!add(particle, adds[i].ix, adds[i].iy, adds[i].hits, adds[i].misses)) refused(adds[i]);
    }
    return dropped;
  }
  for (std::uint32_t first = 0; first < count; first += kMaxRun) {
    const std::uint32_t n = count - first < kMaxRun ? count - first : kMaxRun;
    const CellAdd* run = adds + first;
    bool inside[kMaxRun];
    std::uint32_t ti[kMaxRun];
    std::uint32_t c[kMaxRun];
    std::uint32_t slot[kMaxRun];     // kNone: no tile yet (or outside)
    std::uint32_t e[kMaxRun];        // the entry each walk is at, then its answer (find_marked_view())
    std::uint32_t walking[kMaxRun];  // runs whose walk goes on
    std::uint32_t active = 0U;
    for (std::uint32_t i = 0; i < n; ++i) {
      e[i] = kNone;
      slot[i] = kNone;
      inside[i] = in_bounds(run[i].ix, run[i].iy);
      if (!inside[i]) continue;
      ti[i] = tile_index(run[i].ix, run[i].iy);
      c[i] = cell_in_tile(run[i].ix, run[i].iy);
      slot[i] = tile_table_[ti[i]];
      if (slot[i] != kNone) prefetch(&tiles_[slot[i]].head[c[i]]);
    }
    for (std::uint32_t i = 0; i < n; ++i) {
      if (slot[i] == kNone) continue;
      e[i] = tiles_[slot[i]].head[c[i]];
      if (e[i] != kNone) {
        prefetch(&obs_[e[i]]);
        walking[active++] = i;
      }
    }
    // find_marked_view() for every walk at once: a round takes one step of each.
    while (active > 0U) {
      std::uint32_t still = 0U;
      for (std::uint32_t k = 0; k < active; ++k) {
        const std::uint32_t i = walking[k];
        const Observation& o = obs_[e[i]];
        if (owner_mark_[o.owner] == view_mark_) continue;  // found: e[i] is the view
        if (owner_tree_[o.owner] < view_tree_ || o.next_in_cell == kNone) {
          e[i] = kNone;
          continue;
        }
        e[i] = o.next_in_cell;
        prefetch(&obs_[e[i]]);
        walking[still++] = i;
      }
      active = still;
    }
    // add()'s tail, in order: the particle's own entry in place, else a new one.
    for (std::uint32_t i = 0; i < n; ++i) {
      const CellAdd& a = run[i];
      if (!inside[i]) {
        ++out_of_bounds_count_;
        refused(a);
        continue;
      }
      CellObservation view{};
      if (e[i] != kNone) {
        Observation& o = obs_[e[i]];
        if (o.owner == node_owner_[particle]) {
          o.value = accumulate(o.value, a.hits, a.misses);
          continue;
        }
        view = o.value;
      }
      if (!insert(particle, ti[i], c[i], accumulate(view, a.hits, a.misses))) refused(a);
    }
  }
  return dropped;
}

void DpMap::unlink_from_cell(std::uint32_t e) {
  const Observation& o = obs_[e];
  if (o.prev_in_cell == kNone) {
    tiles_[o.location >> (2U * kSideLog2)].head[o.location & (capacity::kDpTileCells - 1U)] = o.next_in_cell;
  } else {
    obs_[o.prev_in_cell].next_in_cell = o.next_in_cell;
  }
  if (o.next_in_cell != kNone) obs_[o.next_in_cell].prev_in_cell = o.prev_in_cell;
}

void DpMap::release_observation(std::uint32_t e) {
  index_erase(e);
  unlink_from_cell(e);
  const std::uint32_t slot = obs_[e].location >> (2U * kSideLog2);
  Tile& tile = tiles_[slot];
  if (--tile.count == 0U) {  // last observation gone: the tile returns to the pool
    tile_table_[tile.table_index] = kNone;
    tiles_pool_.release(&tile);
  }
  obs_[e].owner = kNone;
  obs_[e].next_in_node = obs_free_;
  obs_free_ = e;
  --obs_used_;
}

bool DpMap::pop_observation(NodeId node, std::int32_t* ix, std::int32_t* iy, CellObservation* value) {
  if (tree_ == nullptr || !tree_->contains(node)) {
    ++misuse_count_;
    return false;
  }
  const std::uint32_t owner = node_owner_[node];
  if (owner == kNone) return false;
  const std::uint32_t e = owner_head_[owner];
  const Observation& o = obs_[e];
  const std::uint32_t table = tiles_[o.location >> (2U * kSideLog2)].table_index;
  const std::uint32_t c = o.location & (capacity::kDpTileCells - 1U);
  *ix = static_cast<std::int32_t>(((table % tiles_x_) << kSideLog2) | (c & kSideMask));
  *iy = static_cast<std::int32_t>(((table / tiles_x_) << kSideLog2) | (c >> kSideLog2));
  *value = o.value;
  const std::uint32_t next = o.next_in_node;
  release_observation(e);
  if (next == kNone) {
    release_owner(owner);
  } else {
    owner_head_[owner] = next;
    --owner_count_[owner];
  }
  return true;
}

void DpMap::remove_node(NodeId node) {
  if (tree_ == nullptr || node >= node_capacity_) {
    ++misuse_count_;
    return;
  }
  const std::uint32_t owner = node_owner_[node];
  if (owner == kNone) return;
  std::uint32_t e = owner_head_[owner];
  while (e != kNone) {
    const std::uint32_t next = obs_[e].next_in_node;
    release_observation(e);
    e = next;
  }
  release_owner(owner);
}

// Parent P merges into its only child C (§II-A). C's entries are newer than P's and, in
// every cell list, ahead of them (a node's entries precede its ancestors'). Whichever
// side owns fewer observations is moved into the other's owner, which then belongs to C.
// The cell order invariant holds afterwards: an entry keeps its place in its cell list,
// and both P's and C's places lie after every entry of C's descendants (P's descendants
// are C and C's descendants) and before every entry of P's ancestors (C's ancestors now).
void DpMap::merge_node(NodeId parent, NodeId child) {
  if (tree_ == nullptr || parent >= node_capacity_ || child >= node_capacity_ || parent == child) {
    ++misuse_count_;
    return;
  }
  const std::uint32_t op = node_owner_[parent];
  const std::uint32_t oc = node_owner_[child];
  if (op == kNone) return;  // nothing to hand down
  if (oc == kNone || owner_count_[op] > owner_count_[oc]) {
    // The child's side is smaller: fold it into the parent's owner, then hand that owner
    // to the child. A fresh particle (no observations) makes this O(1).
    if (oc != kNone) fold_owner(oc, op, true);  // C's records are newer
    node_owner_[parent] = kNone;
    owner_node_[op] = child;
    node_owner_[child] = op;
    return;
  }
  // The parent's side is not larger: move it into the child's owner.
  fold_owner(op, oc, false);  // the child's own records are newer and shadow P's
}

void DpMap::fold_owner(std::uint32_t from, std::uint32_t into, bool from_is_newer) {
  std::uint32_t e = owner_head_[from];
  while (e != kNone) {
    Observation& o = obs_[e];
    const std::uint32_t next = o.next_in_node;
    const std::uint32_t f = index_find(into, o.location);  // `into`'s entry in this cell
    if (f != kNone) {
      if (from_is_newer) obs_[f].value = o.value;  // the newer record survives in f's slot
      release_observation(e);                      // the tile keeps f, so it stays
    } else {
      index_erase(e);
      o.owner = into;
      index_insert(e);
      o.next_in_node = owner_head_[into];
      owner_head_[into] = e;
      ++owner_count_[into];
    }
    e = next;
  }
  owner_head_[from] = kNone;
  release_owner(from);
}

void DpMap::location_to_cell(std::uint32_t location, std::int32_t* ix, std::int32_t* iy) const {
  const Tile& tile = tiles_[location >> (2U * kSideLog2)];
  const std::uint32_t c = location & (capacity::kDpTileCells - 1U);
  *ix = static_cast<std::int32_t>(((tile.table_index % tiles_x_) << kSideLog2) | (c & kSideMask));
  *iy = static_cast<std::int32_t>(((tile.table_index / tiles_x_) << kSideLog2) | (c >> kSideLog2));
}

std::uint32_t DpMap::fill_rect(NodeId particle, const CellRect& rect, CellObservation* values,
                               std::uint8_t* known) const {
  std::uint32_t known_count = 0U;
  std::size_t i = 0U;
  for (std::uint32_t r = 0U; r < rect.height; ++r) {
    const std::int64_t iy64 = static_cast<std::int64_t>(rect.iy0) + r;
    for (std::uint32_t col = 0U; col < rect.width; ++col, ++i) {
      const std::int64_t ix64 = static_cast<std::int64_t>(rect.ix0) + col;
      bool ok = false;
      const bool inside = wrap_ ? (ix64 > INT32_MIN && ix64 < INT32_MAX && iy64 > INT32_MIN && iy64 < INT32_MAX)
                                : (ix64 >= 0 && iy64 >= 0 && ix64 < width_cells_ && iy64 < height_cells_);
      if (tree_ != nullptr && inside) {
        ok = lookup(particle, static_cast<std::int32_t>(ix64), static_cast<std::int32_t>(iy64), &values[i]);
      }
      known[i] = ok ? 1U : 0U;
      if (ok) ++known_count;
    }
  }
  return known_count;
}

void DpMap::unwrap_near(std::int32_t* ix, std::int32_t* iy, std::int32_t near_ix, std::int32_t near_iy) const {
  if (!wrap_) return;
  // The representative of ix modulo the width that lies in [near - width/2, near + width/2).
  const auto nearest = [](std::int32_t v, std::int32_t near, std::int32_t side) {
    const std::int64_t half = side / 2;
    const std::int64_t d = static_cast<std::int64_t>(v) - near + half;
    const std::int64_t m = ((d % side) + side) % side;
    return static_cast<std::int32_t>(static_cast<std::int64_t>(near) - half + m);
  };
  *ix = nearest(*ix, near_ix, width_cells_);
  *iy = nearest(*iy, near_iy, height_cells_);
}

bool DpMap::touched_bounds(CellRect* out) const {
  if (touched_tx0_ == kNone) return false;
  const std::uint32_t x0 = touched_tx0_ << kSideLog2;
  const std::uint32_t y0 = touched_ty0_ << kSideLog2;
  std::uint32_t x1 = (touched_tx1_ + 1U) << kSideLog2;
  std::uint32_t y1 = (touched_ty1_ + 1U) << kSideLog2;
  if (x1 > static_cast<std::uint32_t>(width_cells_)) x1 = static_cast<std::uint32_t>(width_cells_);
  if (y1 > static_cast<std::uint32_t>(height_cells_)) y1 = static_cast<std::uint32_t>(height_cells_);
  out->ix0 = static_cast<std::int32_t>(x0);
  out->iy0 = static_cast<std::int32_t>(y0);
  out->width = x1 - x0;
  out->height = y1 - y0;
  return true;
}

std::uint32_t DpMap::entries_in_cell(std::int32_t ix, std::int32_t iy) const {
  if (tree_ == nullptr || !in_bounds(ix, iy)) return 0U;
  const std::uint32_t slot = tile_table_[tile_index(ix, iy)];
  if (slot == kNone) return 0U;
  std::uint32_t n = 0U;
  for (std::uint32_t e = tiles_[slot].head[cell_in_tile(ix, iy)]; e != kNone; e = obs_[e].next_in_cell) ++n;
  return n;
}

std::uint32_t DpMap::observation_count(NodeId node) const {
  if (tree_ == nullptr || node >= node_capacity_) return 0U;
  const std::uint32_t owner = node_owner_[node];
  return owner == kNone ? 0U : owner_count_[owner];
}

bool DpMap::owns(NodeId node, std::int32_t ix, std::int32_t iy) const {
  if (tree_ == nullptr || !tree_->contains(node) || !in_bounds(ix, iy)) return false;
  const std::uint32_t slot = tile_table_[tile_index(ix, iy)];
  if (slot == kNone) return false;
  const std::uint32_t e = find_view(node, slot, cell_in_tile(ix, iy));
  return e != kNone && owner_node_[obs_[e].owner] == node;
}

std::size_t DpMap::footprint_bytes() const {
  return sizeof(std::uint32_t) * (static_cast<std::size_t>(tiles_x_) * tiles_y_ + kOwnerTables * node_capacity_ +
                                  static_cast<std::size_t>(index_mask_) + 1U) +
         tiles_pool_.footprint_bytes() + sizeof(Observation) * obs_capacity_;
}

bool DpMap::invariants_hold() const {
  if (tree_ == nullptr) return true;
  if (!tiles_pool_.invariants_hold() || obs_ == nullptr) return false;
  // Observation slots: the free stack holds exactly the slots handed out and not in use
  // (owner kNone); those never handed out are the rest.
  const std::uint32_t obs_total = obs_used_;
  if (obs_fresh_ > obs_capacity_ || obs_used_ > obs_fresh_ || obs_peak_ < obs_used_ || obs_peak_ > obs_fresh_) {
    return false;
  }
  std::uint32_t obs_free_seen = 0U;
  for (std::uint32_t e = obs_free_; e != kNone; e = obs_[e].next_in_node) {
    if (e >= obs_fresh_ || obs_[e].owner != kNone || ++obs_free_seen > obs_fresh_ - obs_used_) return false;
  }
  if (obs_free_seen != obs_fresh_ - obs_used_) return false;
  // Cells: each tile in use is referenced once, knows its table entry, counts its
  // entries, is not empty; each entry is live, addresses this cell, belongs to a live
  // tree node, and no node appears twice in one cell.
  std::uint32_t tiles_seen = 0U;
  std::uint32_t in_cells = 0U;
  for (std::uint32_t t = 0U; t < tiles_x_ * tiles_y_; ++t) {
    const std::uint32_t slot = tile_table_[t];
    if (slot == kNone) continue;
    if (!tiles_pool_.slot_in_use(slot) || tiles_ == nullptr) return false;
    ++tiles_seen;
    const Tile& tile = tiles_[slot];
    if (tile.table_index != t || tile.count == 0U) return false;
    std::uint32_t in_tile = 0U;
    for (std::uint32_t c = 0U; c < capacity::kDpTileCells; ++c) {
      std::uint32_t prev = kNone;
      for (std::uint32_t e = tile.head[c]; e != kNone; prev = e, e = obs_[e].next_in_cell) {
        if (!obs_in_use(e) || ++in_cells > obs_total) return false;
        ++in_tile;
        const Observation& o = obs_[e];
        if (o.prev_in_cell != prev) return false;
        if (index_find(o.owner, o.location) != e) return false;
        if (o.location != ((slot << (2U * kSideLog2)) | c) || o.owner >= node_capacity_) return false;
        const NodeId node = owner_node_[o.owner];
        if (!tree_->contains(node)) return false;
        for (std::uint32_t f = o.next_in_cell; f != kNone; f = obs_[f].next_in_cell) {
          if (obs_[f].owner == o.owner) return false;
          if (tree_->is_ancestor_or_self(node, owner_node_[obs_[f].owner])) return false;  // order
          // newer trees first (find_view stops at the first older tree's entry)
          if (tree_->tree_sequence(owner_node_[obs_[f].owner]) > tree_->tree_sequence(node)) return false;
        }
      }
    }
    if (in_tile != tile.count) return false;
  }
  if (tiles_seen != tiles_pool_.size() || in_cells != obs_total) return false;
  // Index: exactly one slot per observation (each findable, checked above).
  std::uint32_t indexed = index_ == nullptr ? obs_total : 0U;
  for (std::size_t i = 0U; index_ != nullptr && i <= index_mask_; ++i) {
    const std::uint32_t e = index_[i];
    if (e == kNone) continue;
    if (!obs_in_use(e) || ++indexed > obs_total) return false;
  }
  if (indexed != obs_total) return false;
  // Owners: the free stack holds distinct owners not in use; an owner in use (not on
  // the stack) belongs to a live node that points back at it, has a non-empty list of
  // its own entries whose length is its count; lists add up to the pool count.
  if (owner_free_count_ > node_capacity_) return false;
  for (std::uint32_t o = 0U; o < node_capacity_; ++o) {
    if (owner_head_[o] == kNone && owner_node_[o] != kNoNode) return false;
  }
  std::uint32_t free_seen = 0U;
  for (std::uint32_t i = 0U; i < owner_free_count_; ++i) {
    const std::uint32_t o = owner_free_[i];
    if (o >= node_capacity_ || owner_node_[o] != kNoNode || owner_head_[o] != kNone || owner_count_[o] != 0U) {
      return false;
    }
    ++free_seen;
  }
  std::uint32_t in_nodes = 0U;
  std::uint32_t owners_in_use = 0U;
  for (std::uint32_t o = 0U; o < node_capacity_; ++o) {
    if (owner_node_[o] == kNoNode) continue;
    ++owners_in_use;
    const NodeId n = owner_node_[o];
    if (n >= node_capacity_ || !tree_->contains(n) || node_owner_[n] != o) return false;
    if (owner_tree_[o] != tree_->tree_sequence(n)) return false;
    std::uint32_t len = 0U;
    for (std::uint32_t e = owner_head_[o]; e != kNone; e = obs_[e].next_in_node) {
      if (!obs_in_use(e) || ++in_nodes > obs_total || obs_[e].owner != o) return false;
      ++len;
    }
    if (len == 0U || len != owner_count_[o]) return false;
  }
  if (owners_in_use + free_seen != node_capacity_) return false;
  for (NodeId n = 0U; n < node_capacity_; ++n) {
    const std::uint32_t o = node_owner_[n];
    if (o != kNone && (o >= node_capacity_ || owner_node_[o] != n)) return false;
  }
  return in_nodes == obs_total;
}


void DpMap::transfer_state(StateIo& io) {
  io.section("dp_map");
  tiles_pool_.transfer_state(io);
  io.fixed(obs_capacity_, "dp map observation capacity");
  io.value(obs_fresh_);
  io.value(obs_used_);
  io.value(obs_peak_);
  io.value(obs_free_);
  // Slot 0 of each pool, set by the first allocation.
  io.arena_pointer(tiles_, "dp map tiles");
  io.arena_pointer(obs_, "dp map observations");
  io.value(owner_free_count_);
  io.value(touched_tx0_);
  io.value(touched_ty0_);
  io.value(touched_tx1_);
  io.value(touched_ty1_);
  io.value(tile_oom_count_);
  io.value(observation_oom_count_);
  io.value(observations_made_);
  io.value(out_of_bounds_count_);
  io.value(misuse_count_);
  io.value(view_particle_);
  io.value(view_tree_);
  io.value(view_mark_);
}

}  // namespace sdpslam
