#pragma once
// A particle's map view remembered over a burst of reads that leave the map unchanged:
// the scan matcher's hill climb (scan_matcher.h) scores up to 1 + 6·iterations·levels
// poses, and neighbouring poses read mostly the same cells. Each DpMap lookup walks the
// cell's observation list (a cache miss per entry: most of a run's time), so the first
// read of a cell goes to the map and later ones are answered from here.
//
// Exact: lookup() returns what DpMap::lookup() returns for the same particle and cell,
// as long as the map is not written between begin() and the last lookup() (the caller's
// contract), so results are bit-identical with and without the cache. Fixed storage from
// the arena (capacity::kViewCacheSlots × 16 bytes); begin() is O(1) (a generation
// counter); past 3/4 of the slots new cells are read through uncached.
#include <cstddef>
#include <cstdint>

#include "sdpslam/core/arena.h"
#include "sdpslam/core/capacities.h"
#include "sdpslam/core/bottom/dp_map.h"
#include "sdpslam/core/state_io.h"

namespace sdpslam {

class ViewCache {
 public:
  static std::size_t required_arena_bytes(std::uint32_t slots);
  // `slots` a power of two ≥ 16. False iff it is not or the arena is too small.
  bool init(Arena& arena, std::uint32_t slots);
  bool ready() const { return slots_ != nullptr; }

  // Starts a burst of reads of `particle`'s view in `map`: forgets every cell.
  void begin(const DpMap& map, NodeId particle);
  // DpMap::lookup(particle, ix, iy, out) of the current burst.
  bool lookup(std::int32_t ix, std::int32_t iy, CellObservation* out);

  // Reads answered here / passed to the map since init (for benchmarks and tests).
  std::uint64_t hits() const { return hits_; }
  std::uint64_t misses() const { return misses_; }
  // The mutable state, for snapshots (core/state_io.h): what init() did not fix.
  void transfer_state(StateIo& io);

 private:
  struct Slot {
    std::uint64_t key;         // (ix, iy) as two u32
    std::uint32_t generation;  // bit 31: the particle has an observation here
    CellObservation value;
  };
  static_assert(sizeof(Slot) == 16U, "view cache slots stay 16 bytes");
  static constexpr std::uint32_t kSeen = 0x80000000U;

  Slot* slots_ = nullptr;
  std::uint32_t mask_ = 0U;
  std::uint32_t shift_ = 0U;
  std::uint32_t limit_ = 0U;  // entries held at most (3/4 of the slots)
  std::uint32_t used_ = 0U;
  std::uint32_t generation_ = 0U;  // < kSeen
  const DpMap* map_ = nullptr;
  NodeId particle_ = kNoNode;
  std::uint64_t hits_ = 0U;
  std::uint64_t misses_ = 0U;
};

}  // namespace sdpslam
