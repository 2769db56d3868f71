#pragma once
// A submap's free-space skeleton (paper §III, anchorage; Fig. 2 (b)) and, for loop
// closure, its obstacle points, read from the DP map a slice at a time.
//
// The submap's patch is its path's cells padded (SubmapStore: path_rect), cropped about
// its centre to the patch side. It is read from the DP map through the submap's
// ancestry node in strips of coarse rows (reading a cell costs microseconds: the cell's
// observation list is searched for the submap's lineage), within a budget of cells per
// call of work(), so that no scan pays for a whole patch. Each coarse cell
// (downsample × downsample fine cells) is occupied if any of its known cells has the
// occupancy of occupied_threshold or more, else free if any has free_threshold or less,
// else unknown. Once the whole patch is classified, the skeleton is extracted
// (free_space_skeleton.h) into the store, its bounds into the submap's box, and the
// obstacle points: occupied coarse cells beside a free one, at most obstacle_points,
// evenly by stride, as half fine cells from the map's origin (CellPoint).
//
// One job at a time. The fine cells of a strip are read into a buffer the caller lends
// (FineBuffer: shared with the map transfer, which runs between jobs).
//
// Memory: init() carves the coarse patch and the skeleton's work grids from an Arena;
// work() allocates nothing. The job is the state outside the arena (transfer_state()).
#include <cstddef>
#include <cstdint>

#include "sdpslam/core/arena.h"
#include "sdpslam/core/bottom/dpslam_filter.h"
#include "sdpslam/core/state_io.h"
#include "top/free_space_skeleton.h"
#include "top/submap_store.h"

namespace sdpslam {

struct SkeletonReaderOptions {
  std::uint32_t patch_side = 0U;  // coarse cells, the border included, >= 3
  std::uint32_t downsample = 1U;  // fine cells per coarse cell side, >= 1
  std::uint32_t skeleton_points = 0U;  // per submap, >= 1
  std::uint32_t obstacle_points = 0U;  // per submap; 0 = none extracted
  double occupied_threshold = 0.65;
  double free_threshold = 0.35;
  double min_clearance_m = 0.1;

  bool valid() const;
};

// The caller's buffer for one strip of fine cells.
struct FineBuffer {
  CellObservation* values = nullptr;
  std::uint8_t* known = nullptr;
  std::size_t cells = 0U;
};

// What one call of work() did.
struct SkeletonStep {
  std::uint32_t cells_read = 0U;
  bool extracted = false;  // a skeleton was extracted (the job ended on a non-empty patch)
  std::uint32_t truncated_points = 0U;  // skeleton points beyond skeleton_points, dropped
};

class SkeletonReader {
 public:
  SkeletonReader() = default;
  SkeletonReader(const SkeletonReader&) = delete;
  SkeletonReader& operator=(const SkeletonReader&) = delete;

  static std::size_t required_bytes(const SkeletonReaderOptions& options);
  bool init(const SkeletonReaderOptions& options, Arena& arena);

  bool active() const { return job_.active; }
  bool is_job(std::uint32_t level, std::uint32_t node) const {
    return job_.active && job_.level == level && job_.node == node;
  }
  // Starts the job of live level `level`'s submap `node` (not done until the job ends;
  // its counts and box reset).
  void start(SubmapStore& store, std::uint32_t level, std::uint32_t node);
  // The job, within `budget_cells` cells read (at least one strip); marks the submap
  // skeleton_done when it ends.
  SkeletonStep work(std::uint32_t budget_cells, const DpSlamFilter& filter, SubmapStore& store, const FineBuffer& fine);

  void transfer_state(StateIo& io);

 private:
  struct Job {
    bool active = false;
    std::uint32_t level = 0U;
    std::uint32_t node = 0U;
    CellRect rect{};  // the patch (fine cells)
    std::uint32_t coarse_width = 0U;
    std::uint32_t coarse_height = 0U;
    std::uint32_t next_coarse_row = 0U;
  };
  void extract_obstacles(Submap& sm, CellPoint* out, const CellRect& r, std::uint32_t cw, std::uint32_t ch) const;

  SkeletonReaderOptions options_{};
  FreeSpaceSkeleton skeleton_;
  CellState* coarse_ = nullptr;  // patch_side²
  Job job_{};
};

}  // namespace sdpslam
