#pragma once
// Distributed particle map (DP-Mapping, paper §II-A; Eliazar & Parr, DP-SLAM 2003 §3.2).
//
// One grid shared by all particles. Each cell holds a short list of observations, each
// made by one ancestry-tree node; a particle sees, in every cell, the observation of its
// nearest ancestor-or-self that has one ("to obtain the full map associated to a
// particle it is necessary to consult the observations made by the particle and by its
// ancestrals"). A copy of a particle's map at resampling is thus free: the child simply
// inherits.
//
// Layout (fixed memory, all from the Arena at init):
//  - a tile index table, one u32 per tile of kDpTileSideCells² cells, covering the area;
//  - tiles (cell list heads) from a pool, allocated on the first write into the tile and
//    released when their last observation goes, so unexplored space costs 4 bytes/tile;
//  - observations (24 bytes: owner, cell links both ways, owner link, cell address,
//    value) in one array with its own free list: the last slot freed is handed out
//    first, else the first never used; a freed slot (owner kNone) links to the one
//    freed before it through its owner link. So a slot costs its 24 bytes and nothing
//    beside them (a general pool's free links and generations would add a third, and a
//    cache miss to every allocation and release), and a slot the map never needs is
//    never touched. The cell list is doubly linked so that a release is O(1). An
//    observation names an *owner* slot, not a node: owner → node and
//    node → owner tables (one owner per node that has observations, sized by the tree's
//    capacity) add one indirection to lookups and make a merge cost O(smaller side).
//    Each owner keeps an intrusive list of its observations and their count;
//  - owner tables: owner → node, node → owner, list head, count, free-owner stack, the
//    owner's tree sequence and a view mark (begin_view());
//  - an (owner, cell) → observation index: open addressing with linear probing and
//    backward-shift deletion, 4 bytes per slot, the smallest power of two ≥ 1.5 ×
//    observation_capacity slots (load ≤ 2/3 even with the pool full).
//
// Finding a particle's view in a cell (the hot path of every map update and beam
// evaluation) runs two exact searches in lockstep and stops with whichever ends first:
// the scan of the cell list (the first ancestor-or-self entry is the deepest, see
// update()) and the walk up the particle's ancestors probing the index for each one's
// entry in this cell (the first found is the deepest by construction). With N
// particles a busy cell holds an entry per live lineage, so the scan alone costs O(N)
// cache misses per cell, while the nearest ancestor with an entry is usually the
// particle itself or its parent: cost O(min(list position, ancestor distance)).
// Without the index (SDP-SLAM's few particles per segment) a scan's match and map update
// for one particle run in a view (begin_view()): its ancestors' owners are marked once, and the
// scan of each cell list tests per-owner tables (mark, tree sequence) instead of each
// entry's node labels: one cache miss per entry walked instead of three. A map update
// writes its cells in runs (add_run()): the lists of a run's cells are walked side by
// side, so that those misses overlap.
//
// Merge cost (TreeListener::on_node_merged, parent P into its only child C): if P owns
// more observations than C, C's are moved into P's owner (where both have one in a
// cell, C's newer value is copied into P's entry and C's is freed) and P's owner is
// re-pointed to C; otherwise P's are moved into C's owner. Either way
// O(min(|P|, |C|) × cell list length): a fresh particle (C empty) costs O(1) however
// long the history it inherits; each moved or dropped entry costs O(1) expected (index).
// Removal costs O(observations of the node) expected.
//
// Ownership: the map keeps a reference to the AncestryTree given to init() (it must
// outlive the map) and reads it for ancestor queries; the tree tells the map about
// removals and merges through prune(&map). Lookups must not run concurrently with
// prune or updates (single-threaded filter; concurrent lookups alone are fine).
//
// Errors are results and counters: out-of-area coordinates, exhausted pools and dead
// node ids make update() return false with a counter bumped; the map stays consistent.
#include <cstddef>
#include <cstdint>

#include "sdpslam/core/bottom/ancestry_tree.h"
#include "sdpslam/core/arena.h"
#include "sdpslam/core/capacities.h"
#include "sdpslam/core/pool.h"
#include "sdpslam/core/state_io.h"

namespace sdpslam {

// The value one ancestry node recorded for one cell. How the filter turns it into an
// occupancy probability is its business (e.g. hits / (hits + misses)).
struct CellObservation {
  std::uint16_t hits = 0U;
  std::uint16_t misses = 0U;
};
inline bool operator==(const CellObservation& a, const CellObservation& b) {
  return a.hits == b.hits && a.misses == b.misses;
}
inline bool operator!=(const CellObservation& a, const CellObservation& b) { return !(a == b); }

// base + (add_hits, add_misses) with saturation that keeps the ratio: while either count
// would reach 65535, both are halved (rounding down). Pure, O(1).
inline CellObservation accumulate(CellObservation base, std::uint16_t add_hits, std::uint16_t add_misses) {
  std::uint32_t h = static_cast<std::uint32_t>(base.hits) + add_hits;
  std::uint32_t m = static_cast<std::uint32_t>(base.misses) + add_misses;
  while (h >= 0xFFFFU || m >= 0xFFFFU) {
    h >>= 1U;
    m >>= 1U;
  }
  return CellObservation{static_cast<std::uint16_t>(h), static_cast<std::uint16_t>(m)};
}

// Half-open rectangle of cells [ix0, ix0 + width) × [iy0, iy0 + height).
struct CellRect {
  std::int32_t ix0 = 0;
  std::int32_t iy0 = 0;
  std::uint32_t width = 0U;
  std::uint32_t height = 0U;
};

class DpMap final : public TreeListener {
 public:
  struct Options {
    double origin_x_m = 0.0;  // world coordinates of the lower-left corner of cell (0,0)
    double origin_y_m = 0.0;
    double width_m = 0.0;     // covered area; rounded up to whole cells
    double height_m = 0.0;
    double resolution_m = 0.05;           // cell side
    std::uint32_t tile_capacity = 0U;     // tiles that may hold data at once
    std::uint32_t observation_capacity = 0U;  // (node, cell) observations at once
    // The (owner, cell) index (see the top): pays off when a cell holds entries of many
    // lineages (hundreds of particles) and costs 4 B × index_slots_for() of arena. Off,
    // every search is the scan of the cell's list (cheap with few particles, e.g. SDP's
    // bottom level); results are identical either way, only the cost differs.
    bool owner_cell_index = true;
    // A torus instead of a bounded area (SDP-SLAM's bottom level): each axis is rounded
    // up to a power of two of tiles, W × H cells, and cell (ix, iy) is stored where
    // (ix mod W, iy mod H) is, for every int32 coordinate: nothing is out of the map, so
    // the robot may drive any distance. Cells a window apart share storage but not
    // views: a lookup finds only its own lineage's observations (the top of this file),
    // so distinct lineages never see each other's, wherever they are. A lineage must not
    // meet ITSELF across the seam: the caller keeps each lineage's updates within a
    // square of side W/2 (SDP-SLAM: segmentation when the robot leaves it, sdp_slam.h)
    // and its lookups closer than W/2 to that square (BeamModel leaves out longer
    // readings); then every answer is exact: the other copies of a looked-up cell are
    // all outside the square.
    // pop_observation() and location-based extraction give coordinates modulo the
    // window (in [0, W)); unwrap_near() brings them back next to a known place.
    bool wrap = false;
  };

  DpMap() = default;
  DpMap(const DpMap&) = delete;
  DpMap& operator=(const DpMap&) = delete;
  ~DpMap() = default;

  // Arena bytes init() needs for `options` and a tree of `node_capacity` nodes
  // (alignment padding included); 0 iff the options are invalid.
  static std::size_t required_arena_bytes(const Options& options, std::uint32_t node_capacity);
  // True iff the options describe a usable map: finite origin, width/height/resolution
  // > 0, cells per axis < 2^31 and the tile table < 2^32 entries, 1 ≤ tile_capacity ≤
  // capacity::kDpMaxTiles, 1 ≤ observation_capacity ≤ 2^30 (the index stays < 2^31 slots).
  static bool options_valid(const Options& options);
  // Whole cells covering `extent_m` at `resolution_m`, as init() rounds an axis; 0 iff out
  // of range.
  static std::int32_t cells_along(double extent_m, double resolution_m);

  // Validates `options`, keeps a reference to `tree` (initialised first: its capacity
  // sizes the per-node table) and carves all storage from `arena`. Returns false iff the
  // options are invalid, the tree is not initialised, or the arena is too small (the map
  // is then unusable and every update is refused). Call once.
  bool init(Arena& arena, const Options& options, const AncestryTree& tree);

  // ---- geometry ----------------------------------------------------------------------
  std::int32_t width_cells() const { return width_cells_; }
  std::int32_t height_cells() const { return height_cells_; }
  double resolution_m() const { return options_.resolution_m; }
  const Options& options() const { return options_; }
  bool wraps() const { return wrap_; }
  bool in_bounds(std::int32_t ix, std::int32_t iy) const {
    return wrap_ || (ix >= 0 && iy >= 0 && ix < width_cells_ && iy < height_cells_);
  }
  // Cell containing world point (x_m, y_m) (floor). False iff outside the covered area
  // (outputs untouched) or not a finite number; with wrap, iff not finite or beyond
  // 2^30 cells from the origin.
  bool world_to_cell(double x_m, double y_m, std::int32_t* ix, std::int32_t* iy) const;
  // With wrap: moves (ix, iy) by whole windows to the copy nearest (near_ix, near_iy)
  // (within half a window on each axis). Without wrap: no change.
  void unwrap_near(std::int32_t* ix, std::int32_t* iy, std::int32_t near_ix, std::int32_t near_iy) const;
  // World coordinates of the centre of cell (ix, iy); no bounds check.
  void cell_center(std::int32_t ix, std::int32_t iy, double* x_m, double* y_m) const;
  // The cells covering [x0, x1] × [y0, y1] grown by pad_m on every side: clipped to the
  // map without wrap; with wrap, cropped about its centre to half the window on each axis
  // (more would meet the other copies of its cells). Empty (width 0) for an empty box.
  CellRect rect_around(double x0_m, double y0_m, double x1_m, double y1_m, double pad_m) const;

  // ---- the particle's view -----------------------------------------------------------
  // The observation of `particle`'s deepest ancestor-or-self that has one in cell
  // (ix, iy). False (and *out untouched) iff none has one, the cell is outside the map,
  // or `particle` is dead. Cost: tile table → cell head → find_view() (the lockstep
  // search described at the top of this file): O(min(list position, ancestor distance)).
  bool lookup(NodeId particle, std::int32_t ix, std::int32_t iy, CellObservation* out) const {
    if (!in_bounds(ix, iy)) return false;
    const std::uint32_t tile = tile_table_[tile_index(ix, iy)];
    if (tile == kNone) return false;
    return resolve(particle, tile, cell_in_tile(ix, iy), out);
  }

  // Sets `particle`'s own observation of cell (ix, iy) to `value`: in place if it has
  // one there, else a new entry in the cell's and the node's lists (it then shadows the
  // ancestors' for `particle` and its descendants only). A new entry goes to the head
  // of the cell list when `particle` is a leaf (the filter's case), else after its
  // descendants' entries, so that lookups can stop at the first ancestor found. Returns false iff the update is
  // dropped — the degraded path, after which the map is unchanged and consistent:
  // out of the area (out_of_bounds_count), a tile is needed and none is free
  // (tile_oom_count), an observation is needed and none is free (observation_oom_count),
  // or `particle` is not a live tree node (misuse_count). O(1) expected for a leaf
  // (index probe, insertion at the head), O(cell list length) for an inner node.
  bool update(NodeId particle, std::int32_t ix, std::int32_t iy, CellObservation value);
  // lookup() then accumulate() then update(): the particle's own record becomes its
  // current view plus the new evidence. Same result and failure rules as update(), with
  // one find_view() (whose answer, if the particle's own, is updated in place).
  bool add(NodeId particle, std::int32_t ix, std::int32_t iy, std::uint16_t hits, std::uint16_t misses);
  // add() into a run of distinct cells, in order, with the same result as one add() per
  // cell: the run's cell lists are walked side by side, one entry of each per round,
  // with the next entry of each fetched ahead, so that their cache misses (one per entry
  // walked, the cost of a map update) overlap instead of following one another. For the
  // particle of begin_view() (another particle: one add() after the other). Cells must
  // be distinct, and with wrap less than a window apart (a beam's traced cells are): an
  // entry made for one cell is not looked for in the others. Returns the hits + misses
  // of the adds refused (add() false).
  struct CellAdd {
    std::int32_t ix = 0;
    std::int32_t iy = 0;
    std::uint16_t hits = 0U;
    std::uint16_t misses = 0U;
  };
  // Cells walked side by side (a longer run goes in parts): several times the misses a
  // core keeps in flight, so that a round keeps them all busy.
  static constexpr std::uint32_t kMaxRun = 64U;
  std::uint32_t add_run(NodeId particle, const CellAdd* adds, std::uint32_t count);
  // A run of reads and add() calls for one particle (a scan's map update, a scan match)
  // between begin_view() and end_view(): begin_view() marks the owners of its
  // ancestors-or-self, O(depth), so that each lookup() or add() for it walks the cell
  // list testing one mark and one tree number per entry (per-owner tables) instead of
  // the entry's node labels: one cache miss per entry instead of three. Same results as
  // without. Nothing but add() and update() for that particle may change the map or the
  // tree in between (no prune, no other node's first record). ViewScope does both.
  void begin_view(NodeId particle);
  void end_view() { view_particle_ = kNoNode; }
  class ViewScope {
   public:
    ViewScope(DpMap& map, NodeId particle) : map_(map) { map_.begin_view(particle); }
    ~ViewScope() { map_.end_view(); }
    ViewScope(const ViewScope&) = delete;
    ViewScope& operator=(const ViewScope&) = delete;

   private:
    DpMap& map_;
  };

  // Removes the newest observation `node` owns and gives its cell and value: false iff
  // `node` owns none, or is not a live tree node (misuse_count). A root of the forest
  // has no ancestors, so what it owns is its whole view: popping until false hands its
  // map out once per known cell, in no spatial order, and frees the observations (and
  // tiles left empty) as it goes; what it still owns is exactly what has not been handed
  // out. SDP-SLAM copies a permanent submap into the global map this way. O(1) expected.
  bool pop_observation(NodeId node, std::int32_t* ix, std::int32_t* iy, CellObservation* value);

  // ---- extraction --------------------------------------------------------------------
  // Calls f(ix, iy, const CellObservation&) for every cell `particle` knows, in raster
  // order of tiles (row-major) and of cells within a tile. O(tiles in table + cells of
  // touched tiles × list length).
  template <class F>
  void for_each_known_cell(NodeId particle, F&& f) const;
  // Fills row-major buffers of rect.width × rect.height with `particle`'s view:
  // values[i] (left untouched where unknown) and known[i] ∈ {0,1}. Cells outside the
  // map are unknown (with wrap, every cell is inside). Returns the number of known cells.
  std::uint32_t fill_rect(NodeId particle, const CellRect& rect, CellObservation* values,
                          std::uint8_t* known) const;
  // Bounding rectangle (whole tiles, clipped to the map) of every tile ever written.
  // False iff nothing was ever written. With wrap, in window coordinates [0, W).
  bool touched_bounds(CellRect* out) const;
  // Entries (of all nodes) in one cell's list; 0 outside the map. For diagnostics/tests.
  std::uint32_t entries_in_cell(std::int32_t ix, std::int32_t iy) const;
  // Observations owned by `node`. O(1).
  std::uint32_t observation_count(NodeId node) const;
  // True iff `node` itself (not an ancestor) holds an observation of cell (ix, iy): an
  // add() there then takes no new observation. Cost as lookup().
  bool owns(NodeId node, std::int32_t ix, std::int32_t iy) const;

  // ---- TreeListener (called by AncestryTree::prune) ----------------------------------
  // Defined inline (no key function), so that the vtable and type info are emitted
  // where the map is used: the core is built without RTTI, tests with UBSan's vptr check.
  // Frees every observation `node` owns (and tiles left empty).
  void on_node_removed(NodeId node) override { remove_node(node); }
  // Gives `parent`'s observations to `child`, except in cells where `child` has its own
  // (newer) one: there the parent's is freed.
  void on_node_merged(NodeId parent, NodeId child) override { merge_node(parent, child); }

  // ---- accounting --------------------------------------------------------------------
  // Bytes of one observation slot (the pool's entries, without the index share).
  static constexpr std::size_t kObservationBytes = 24U;
  // Slots of the (owner, cell) index for a given observation capacity (see the top).
  static std::size_t index_slots_for(std::uint32_t observation_capacity);
  std::uint32_t tiles_used() const { return tiles_pool_.size(); }
  std::uint32_t tiles_peak() const { return tiles_pool_.peak_used(); }
  std::uint32_t tile_capacity() const { return tiles_pool_.capacity(); }
  std::uint32_t observations_used() const { return obs_used_; }
  std::uint32_t observations_peak() const { return obs_peak_; }
  std::uint32_t observation_capacity() const { return obs_capacity_; }
  std::uint64_t tile_oom_count() const { return tile_oom_count_; }
  std::uint64_t observation_oom_count() const { return observation_oom_count_; }
  // New (node, cell) observations asked for since init: made, or refused for a full pool.
  // Over one filter step, what the step needed of the pool at once (before merges of
  // single-child nodes gave most of it back).
  std::uint64_t observations_requested() const { return observations_made_ + observation_oom_count_; }
  std::uint64_t out_of_bounds_count() const { return out_of_bounds_count_; }
  std::uint64_t misuse_count() const { return misuse_count_; }
  // Bytes of state: tile table, tile pool, observation pool, owner tables, index.
  std::size_t footprint_bytes() const;

  // Full self-check, O(capacity): pool invariants; the owner tables are a bijection
  // between owners in use and the nodes that have observations, an owner is in use iff
  // its list is non-empty, its count equals its list's length, and the free stack holds
  // exactly the other owners; every observation is in exactly one cell list and one
  // owner list, and they agree on its owner and cell; no node has two
  // observations in one cell, no entry follows an entry of one of its ancestors, and no
  // entry follows one of an older tree of the forest (what lets lookups stop early); the backward cell links mirror the forward ones; the
  // index holds exactly the observations, each findable by its (owner, cell) key;
  // every node with observations is live in the tree; the
  // tile table and tile back-references agree; each tile's count equals its entries
  // and no tile in use is empty; list lengths add up to the pool counts.
  bool invariants_hold() const;
  // The mutable state, for snapshots (core/state_io.h): what init() did not fix.
  void transfer_state(StateIo& io);

 private:
  static constexpr std::uint32_t kNone = 0xFFFFFFFFU;
  static constexpr std::uint32_t kSideLog2 = capacity::kDpTileSideLog2;
  static constexpr std::uint32_t kSideMask = capacity::kDpTileSideCells - 1U;

  struct Observation {
    std::uint32_t owner;  // owner slot; owner_node_[owner] is the node it belongs to
    std::uint32_t next_in_cell;
    std::uint32_t prev_in_cell;  // kNone at the head of the cell list
    std::uint32_t next_in_node;
    std::uint32_t location;  // (tile slot << 2k) | cell in tile
    CellObservation value;
  };
  static_assert(sizeof(Observation) == kObservationBytes, "observation entries must stay compact");
  struct Tile {
    std::uint32_t head[capacity::kDpTileCells];  // first observation per cell, kNone if empty
    std::uint32_t count;                         // observations in this tile
    std::uint32_t table_index;                   // back-reference into tile_table_
  };

  // Masks are all ones without wrap (in_bounds() was checked), tiles − 1 with it.
  std::uint32_t tile_index(std::int32_t ix, std::int32_t iy) const {
    return ((static_cast<std::uint32_t>(iy) >> kSideLog2) & tile_mask_y_) * tiles_x_ +
           ((static_cast<std::uint32_t>(ix) >> kSideLog2) & tile_mask_x_);
  }
  static std::uint32_t cell_in_tile(std::int32_t ix, std::int32_t iy) {
    return ((static_cast<std::uint32_t>(iy) & kSideMask) << kSideLog2) | (static_cast<std::uint32_t>(ix) & kSideMask);
  }

  // Deepest ancestor-or-self of `particle` with an entry in cell `c` of tile slot `slot`.
  bool resolve(NodeId particle, std::uint32_t slot, std::uint32_t c, CellObservation* out) const {
    if (!tree_->contains(particle)) return false;
    const std::uint32_t e = find_view(particle, slot, c);
    if (e == kNone) return false;
    *out = obs_[e].value;
    return true;
  }
  // Entry of `particle`'s (live) deepest ancestor-or-self in that cell, kNone if none:
  // the lockstep of the cell-list scan (lists keep every node's entry before its
  // ancestors' entries, see update(), so the first ancestor-or-self found is the
  // deepest) and the ancestor walk probing the index; both exact, first to end wins.
  // For the particle of begin_view(), find_marked_view().
  std::uint32_t find_view(NodeId particle, std::uint32_t slot, std::uint32_t c) const;
  std::uint32_t find_marked_view(std::uint32_t slot, std::uint32_t c) const;
  // Home slot: a Fibonacci hash of (owner, tile) plus the cell in the tile times 4, so
  // that the cells of one tile that a beam visits in a row probe nearby slots (a cache
  // line holds 16) instead of a random line each, while a tile an owner has filled
  // occupies at most a quarter of its 1024-slot window (linear probing stays short).
  std::uint32_t index_home(std::uint32_t owner, std::uint32_t location) const {
    const std::uint64_t key = (static_cast<std::uint64_t>(owner) << 32U) | (location >> (2U * kSideLog2));
    const auto base = static_cast<std::uint32_t>((key * 0x9E3779B97F4A7C15ULL) >> index_shift_);
    return (base + ((location & (capacity::kDpTileCells - 1U)) << 2U)) & index_mask_;
  }
  // The observation of `owner` at `location`, kNone if none. O(1) expected.
  std::uint32_t index_find(std::uint32_t owner, std::uint32_t location) const {
    if (index_ == nullptr) {  // no index: the owner's entry, if any, is in the cell list
      std::uint32_t e = tiles_[location >> (2U * kSideLog2)].head[location & (capacity::kDpTileCells - 1U)];
      while (e != kNone && obs_[e].owner != owner) e = obs_[e].next_in_cell;
      return e;
    }
    for (std::uint32_t i = index_home(owner, location);; i = (i + 1U) & index_mask_) {
      const std::uint32_t e = index_[i];
      if (e == kNone) return kNone;
      if (obs_[e].owner == owner && obs_[e].location == location) return e;
    }
  }
  // Moves every entry of owner `from` to owner `into` and frees `from`. Where `into`
  // already has an entry in the cell, one record survives in `into`'s slot: `from`'s
  // value if `from_is_newer`, else `into`'s; the other entry is released.
  void fold_owner(std::uint32_t from, std::uint32_t into, bool from_is_newer);
  void index_insert(std::uint32_t e);
  void index_erase(std::uint32_t e);
  // New entry of `particle` (live, no entry in this cell yet) in cell `c` of tile-table
  // entry `ti`; the tail of update()/add() with their exhaustion rules.
  bool insert(NodeId particle, std::uint32_t ti, std::uint32_t c, CellObservation value);
  void remove_node(NodeId node);
  void merge_node(NodeId parent, NodeId child);
  void unlink_from_cell(std::uint32_t e);
  void release_observation(std::uint32_t e);
  bool obs_in_use(std::uint32_t e) const { return e < obs_fresh_ && obs_[e].owner != kNone; }
  void release_owner(std::uint32_t owner);
  void location_to_cell(std::uint32_t location, std::int32_t* ix, std::int32_t* iy) const;

  Options options_{};
  const AncestryTree* tree_ = nullptr;
  std::int32_t width_cells_ = 0;
  std::int32_t height_cells_ = 0;
  std::uint32_t tiles_x_ = 0U;
  std::uint32_t tiles_y_ = 0U;
  bool wrap_ = false;
  std::uint32_t tile_mask_x_ = 0xFFFFFFFFU;
  std::uint32_t tile_mask_y_ = 0xFFFFFFFFU;
  std::uint32_t* tile_table_ = nullptr;  // tiles_x_ · tiles_y_ entries: tile slot or kNone
  ArenaPool<Tile> tiles_pool_;
  Tile* tiles_ = nullptr;  // slot 0 of tiles_pool_ (slots are contiguous)
  // Observation slots: obs_capacity_ of them, obs_used_ in use. Slots from obs_fresh_ on
  // were never handed out; the others that are free (owner kNone) form a stack through
  // next_in_node from obs_free_ (kNone when empty).
  Observation* obs_ = nullptr;
  std::uint32_t obs_capacity_ = 0U;
  std::uint32_t obs_fresh_ = 0U;
  std::uint32_t obs_used_ = 0U;
  std::uint32_t obs_peak_ = 0U;
  std::uint32_t obs_free_ = kNone;
  // Owner tables, node_capacity_ entries each, one arena block. An owner is in use iff
  // it is not on the free stack; then owner_node_[o] is its node,
  // node_owner_[owner_node_[o]] == o, owner_head_[o] its first observation (never
  // kNone) and owner_count_[o] ≥ 1 its list length. node_owner_[n] is kNone for a node
  // without observations.
  std::uint32_t* owner_node_ = nullptr;
  std::uint32_t* node_owner_ = nullptr;
  std::uint32_t* owner_head_ = nullptr;
  std::uint32_t* owner_count_ = nullptr;
  std::uint32_t* owner_free_ = nullptr;  // stack of free owners, owner_free_count_ deep
  std::uint32_t* owner_tree_ = nullptr;  // tree sequence of owner_node_[o] (fixed for the owner's life)
  std::uint32_t* owner_mark_ = nullptr;  // view_mark_ iff the owner's node is an ancestor-or-self of view_particle_
  std::uint32_t owner_free_count_ = 0U;
  NodeId view_particle_ = kNoNode;  // begin_view()'s particle, kNoNode outside a view
  std::uint32_t view_tree_ = 0U;
  std::uint32_t view_mark_ = 0U;
  std::uint32_t* index_ = nullptr;  // (owner, location) → observation, kNone = empty slot;
                                    // nullptr when Options::owner_cell_index is off
  std::uint32_t index_mask_ = 0U;   // slots − 1
  std::uint32_t index_shift_ = 63U;  // 64 − log2(slots)
  std::uint32_t node_capacity_ = 0U;
  std::uint32_t touched_tx0_ = kNone, touched_ty0_ = kNone, touched_tx1_ = 0U, touched_ty1_ = 0U;
  std::uint64_t tile_oom_count_ = 0U;
  std::uint64_t observation_oom_count_ = 0U;
  std::uint64_t observations_made_ = 0U;
  std::uint64_t out_of_bounds_count_ = 0U;
  std::uint64_t misuse_count_ = 0U;
};

template <class F>
void DpMap::for_each_known_cell(NodeId particle, F&& f) const {
  if (tree_ == nullptr || !tree_->contains(particle)) return;
  for (std::uint32_t t = 0U; t < tiles_x_ * tiles_y_; ++t) {
    const std::uint32_t slot = tile_table_[t];
    if (slot == kNone) continue;
    const std::int32_t tx0 = static_cast<std::int32_t>((t % tiles_x_) << kSideLog2);
    const std::int32_t ty0 = static_cast<std::int32_t>((t / tiles_x_) << kSideLog2);
    for (std::uint32_t c = 0U; c < capacity::kDpTileCells; ++c) {
      CellObservation v;
      if (resolve(particle, slot, c, &v)) {
        f(tx0 + static_cast<std::int32_t>(c & kSideMask), ty0 + static_cast<std::int32_t>(c >> kSideLog2),
          static_cast<const CellObservation&>(v));
      }
    }
  }
}

}  // namespace sdpslam
