#pragma once
// The copy of a permanent submap's map into the global map's permanent part (paper §III
// anchorage; permanent_map.h), a slice per call within a budget of cells.
//
// Each known cell of the submap's DP-map view goes to the permanent map at its place in
// the global frame (the submap's frame at the copy; the DP map's cell frame: same origin
// and resolution, no edge), tagged with its level. A cell refused (every tile taken) or
// too far out for int32 cells is counted as dropped.
//
// Two ways, decided at the first call, once the level's other submaps are released:
//  - pop: prune has then merged the submap's whole lineage into its node (every
//    ancestor was inactive with one child), which is a root; its observations are
//    popped one by one (work in proportion to its known cells, and the DP map's pool
//    refills as it goes). A popped observation counts kPopCostCells against the budget:
//    it is a read and a global-map update, each a cell-list search, where a strip's
//    cell is one read and mostly empty;
//  - rows (the fallback): the rectangle is read in strips of rows into the caller's
//    buffer (work in proportion to its area).
// When the copy is complete the submap's node is released (its observations return to
// the pool).
//
// Memory: no storage of its own; the job is its state (transfer_state()).
#include <cstdint>

#include "sdpslam/core/bottom/dpslam_filter.h"
#include "sdpslam/core/pose2.h"
#include "sdpslam/core/state_io.h"
#include "top/permanent_map.h"
#include "top/skeleton_reader.h"

namespace sdpslam {

// What one call of work() did.
struct TransferStep {
  std::uint32_t work_cells = 0U;     // budget used (at least 1 while a copy is active)
  std::uint64_t cells_copied = 0U;   // cell updates offered to the permanent map
  std::uint64_t cells_dropped = 0U;  // ... refused, or out of int32 cells
  bool popped = false;               // the way was decided now: pop
  bool by_rows = false;              // ... rows
  bool released = false;             // the copy ended and the submap's node was released
  std::uint64_t observations_freed = 0U;  // DP-map observations returned to the pool
};

class MapTransfer {
 public:
  static constexpr std::uint32_t kPopCostCells = 4U;

  bool active() const { return job_.active; }
  // Starts the copy of `node`'s view over `rect` at `frame` (its level's frame in the
  // global frame), its cells tagged `tag` (level + 1).
  void start(NodeId node, const Pose2& frame, std::uint32_t tag, const CellRect& rect);
  // The copy within `budget_cells`.
  TransferStep work(std::uint32_t budget_cells, DpSlamFilter& filter, PermanentMap& map, const FineBuffer& fine);
  // While a copy is active: the node and the part of its rectangle not copied yet (a
  // popped node keeps only the cells not copied; in rows, the rows not copied).
  bool pending(NodeId* node, CellRect* rest) const;
  // The tag of the active copy (its level + 1); 0 when none is active.
  std::uint32_t tag() const { return job_.active ? job_.tag : 0U; }

  void transfer_state(StateIo& io) { io.value(job_); }

 private:
  enum class Mode : std::uint8_t { kUndecided, kPop, kRows };
  struct Job {
    bool active = false;
    Mode mode = Mode::kUndecided;
    NodeId node = kNoNode;
    Pose2 frame;             // the level's frame in the global frame at the copy
    std::uint32_t tag = 0U;  // PermanentMap tag of its cells: level + 1
    CellRect rect{};
    std::uint32_t next_row = 0U;
  };
  void copy_cell(std::int32_t ix, std::int32_t iy, const CellObservation& v, const DpMap& dp, PermanentMap& map,
                 TransferStep* step) const;

  Job job_{};
};

}  // namespace sdpslam
