#pragma once
// The submaps of SDP-SLAM (paper §III, Fig. 3): what the top level knows of each.
//
// Live: for each live PGS level (one per segment), one submap per bottom particle (PGS
// node): its anchored ancestry node, its initial and final poses in the submap frame,
// the bounds of its skeleton, the cells worth reading for its map and its path, its
// free-space skeleton points (ICP, Fig. 2 (b)) and, for loop closure, its obstacle
// points. Storage is by level slot (level % max_levels), as in the PGS.
//
// Permanent: a ring of max_permanent submaps made permanent, oldest first (one per
// level, in level order). Each keeps its frame in the global frame (moved by loop
// closure), the frame its map was copied into the global map with, its chain transform
// from the previous permanent level, and its skeleton and obstacle points, so that later
// samples and loop searches still match against it. When the ring is full the oldest
// is forgotten (the caller counts it).
//
// A permanent submap is kept compactly, so that the ring can hold thousands: its
// skeleton points are stored as the cells of the skeleton's own grid they are the
// centres of (SkeletonCell, 4 bytes instead of a Point2's 16), and come back bit for bit
// (permanent_points()): FreeSpaceSkeleton emits origin + (cell + 0.5) × cell size, and
// the same expression is evaluated again.
//
// Memory: init() carves everything from an Arena (required_bytes()); nothing else
// allocates. The ring's head and count are the only state outside the arena
// (transfer_state()).
#include <cstddef>
#include <cstdint>

#include "sdpslam/core/arena.h"
#include "sdpslam/core/bottom/dp_map.h"
#include "sdpslam/core/bottom/ancestry_tree.h"
#include "sdpslam/core/pose2.h"
#include "sdpslam/core/state_io.h"
#include "sdpslam/core/top/icp2d.h"

namespace sdpslam {

// An obstacle point in half DP-map cells from the map's origin (the submap frame is the
// map's grid frame).
struct CellPoint {
  std::uint16_t ix = 0U;
  std::uint16_t iy = 0U;
};

// A skeleton point as the cell of its skeleton grid whose centre it is.
struct SkeletonCell {
  std::uint16_t x = 0U;
  std::uint16_t y = 0U;
};

// The grid a submap's skeleton points were extracted on (GridPatchView): its origin and
// cell, submap frame; cell_m = 0 until the skeleton exists.
struct SkeletonGrid {
  double origin_x_m = 0.0;
  double origin_y_m = 0.0;
  double cell_m = 0.0;
};

struct Submap {
  NodeId node = kNoNode;
  Pose2 initial;
  Pose2 final_pose;
  double box[4] = {0.0, 0.0, 0.0, 0.0};  // skeleton points' bounds, submap frame
  SkeletonGrid skeleton_grid{};           // where its skeleton points lie
  CellRect map_rect{};                    // cells worth reading for its map
  CellRect path_rect{};                   // its path's cells (skeleton patch seed)
  std::uint32_t point_count = 0U;
  std::uint32_t obstacle_count = 0U;  // loop closure's obstacle points
  bool skeleton_done = false;
};

struct SubmapLevel {
  std::int64_t start_stamp_us = 0;  // exclusive (the previous segment's last scan)
  std::int64_t end_stamp_us = 0;    // inclusive
  std::uint32_t count = 0U;         // its submaps (0: none held)
};

struct PermanentSubmap {
  Pose2 frame_in_global;
  Pose2 frame_in_map;   // the frame its map was copied into the global map with
  Pose2 from_previous;  // this frame in the previous permanent level's frame (chain T)
  double box[4] = {0.0, 0.0, 0.0, 0.0};
  std::uint32_t level = 0U;
  std::uint32_t point_count = 0U;
  std::uint32_t obstacle_count = 0U;
  std::int64_t start_stamp_us = 0;  // its level's start (exclusive)
  Pose2 initial;                    // its segment's initial pose, submap frame
  SkeletonGrid skeleton_grid{};     // its skeleton points' grid (they are kept as cells)
};

struct SubmapStoreOptions {
  std::uint32_t max_levels = 0U;       // live levels, >= 1
  std::uint32_t nodes = 0U;            // submaps per level (bottom particles), >= 1
  std::uint32_t skeleton_points = 0U;  // per submap, >= 1
  std::uint32_t obstacle_points = 0U;  // per submap; 0 = none kept (no loop closure)
  std::uint32_t max_permanent = 0U;    // permanent ring, >= 1

  bool valid() const;
};

class SubmapStore {
 public:
  SubmapStore() = default;
  SubmapStore(const SubmapStore&) = delete;
  SubmapStore& operator=(const SubmapStore&) = delete;

  static std::size_t required_bytes(const SubmapStoreOptions& options);
  // False iff the options are invalid or the arena is too small. Everything starts empty.
  bool init(const SubmapStoreOptions& options, Arena& arena);
  const SubmapStoreOptions& options() const { return options_; }

  // ---- live levels --------------------------------------------------------------------
  Submap& submap(std::uint32_t level, std::uint32_t node) { return submaps_[index(level, node)]; }
  const Submap& submap(std::uint32_t level, std::uint32_t node) const { return submaps_[index(level, node)]; }
  Point2* points(std::uint32_t level, std::uint32_t node) const {
    return points_ + index(level, node) * options_.skeleton_points;
  }
  // Null when no obstacle points are kept.
  CellPoint* obstacles(std::uint32_t level, std::uint32_t node) const {
    return obstacles_ == nullptr ? nullptr : obstacles_ + index(level, node) * options_.obstacle_points;
  }
  SubmapLevel& level(std::uint32_t level) { return levels_[level % options_.max_levels]; }
  const SubmapLevel& level(std::uint32_t level) const { return levels_[level % options_.max_levels]; }

  // ---- permanent ring -----------------------------------------------------------------
  std::uint32_t permanent_count() const { return perm_count_; }
  // The ring slot of the k-th oldest permanent submap (k < permanent_count()). Slots
  // name a submap for as long as it is held.
  std::uint32_t permanent_slot_at(std::uint32_t k) const { return (perm_head_ + k) % options_.max_permanent; }
  PermanentSubmap& permanent(std::uint32_t slot) { return perm_[slot]; }
  const PermanentSubmap& permanent(std::uint32_t slot) const { return perm_[slot]; }
  // Its skeleton points (point_count of them), submap frame, unpacked into the store's
  // one scratch array: valid until the next call.
  const Point2* permanent_points(std::uint32_t slot) const;
  CellPoint* permanent_obstacles(std::uint32_t slot) const {
    return perm_obstacles_ == nullptr ? nullptr : perm_obstacles_ + std::size_t{slot} * options_.obstacle_points;
  }
  // The slot of a permanent level still held; false if it is not (live, forgotten or
  // never made permanent).
  bool find_permanent(std::uint32_t level, std::uint32_t* slot) const;
  // The oldest level held, permanent or live (`first_live` when no permanent one is).
  std::uint32_t first_held_level(std::uint32_t first_live) const {
    return perm_count_ > 0U ? perm_[perm_head_].level : first_live;
  }
  // A new newest permanent submap for live `level`'s submap `node`: its record, skeleton
  // and obstacle points copied (the skeleton points as cells of the submap's
  // skeleton_grid: a point that is not a cell centre of it is kept at the nearest one,
  // within the grid's 65536 cells a side); the caller sets the frames. When the ring is
  // full the oldest is forgotten first (*forgot = true). Returns its slot.
  std::uint32_t make_permanent(std::uint32_t level, std::uint32_t node, bool* forgot);

  // The ring's head and count, for snapshots (state_io.h); the arrays travel with the arena.
  void transfer_state(StateIo& io) {
    io.value(perm_head_);
    io.value(perm_count_);
  }

 private:
  std::size_t index(std::uint32_t level, std::uint32_t node) const {
    return static_cast<std::size_t>(level % options_.max_levels) * options_.nodes + node;
  }

  SubmapStoreOptions options_{};
  Submap* submaps_ = nullptr;      // max_levels × nodes
  Point2* points_ = nullptr;       // max_levels × nodes × skeleton_points
  CellPoint* obstacles_ = nullptr; // max_levels × nodes × obstacle_points (or null)
  SubmapLevel* levels_ = nullptr;  // max_levels
  PermanentSubmap* perm_ = nullptr;  // max_permanent
  SkeletonCell* perm_cells_ = nullptr;  // max_permanent × skeleton_points
  Point2* perm_unpacked_ = nullptr;     // skeleton_points (permanent_points() scratch)
  CellPoint* perm_obstacles_ = nullptr;  // max_permanent × obstacle_points (or null)
  std::uint32_t perm_head_ = 0U;
  std::uint32_t perm_count_ = 0U;
};

}  // namespace sdpslam
