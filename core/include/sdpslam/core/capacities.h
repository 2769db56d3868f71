#pragma once
// Build-time capacities of the core, one place for all of them.
//
// Each value can be overridden for a build profile with -DSDPSLAM_<NAME>=value; the
// static_asserts keep every value inside the range the algorithms are written for.
// Run-time sized storage (grid tiles, observation pools) is chosen at init from
// options and carved from an Arena; its upper bounds live here too.
#include <cstddef>
#include <cstdint>

namespace sdpslam::capacity {

#ifndef SDPSLAM_MAX_BOTTOM_PARTICLES
#define SDPSLAM_MAX_BOTTOM_PARTICLES 512
#endif
#ifndef SDPSLAM_MAX_BEAMS
#define SDPSLAM_MAX_BEAMS 1081
#endif

// Bottom-level (DP-SLAM) particles; the DP-SLAM baseline runs up to this many.
inline constexpr std::uint32_t kMaxBottomParticles = SDPSLAM_MAX_BOTTOM_PARTICLES;
static_assert(kMaxBottomParticles >= 1U && kMaxBottomParticles <= 4096U, "kMaxBottomParticles out of range");

// Beams in one laser scan (1081 covers a 270 deg / 0.25 deg scanner; URG-04LX has 682).
inline constexpr std::uint32_t kMaxBeams = SDPSLAM_MAX_BEAMS;
static_assert(kMaxBeams >= 2U && kMaxBeams <= 4096U, "kMaxBeams out of range");

}  // namespace sdpslam::capacity

// ---- Ancestry tree and distributed particle map (DP-Mapping, paper §II-A) ----------
namespace sdpslam::capacity {

#ifndef SDPSLAM_DP_TILE_SIDE_LOG2
#define SDPSLAM_DP_TILE_SIDE_LOG2 4
#endif

// Ancestry-tree nodes to provision per bottom-level particle: after prune the tree holds
// at most 2·N − 1 nodes, and resampling adds N children before the next prune.
inline constexpr std::uint32_t kAncestryNodesPerParticle = 3U;
static_assert(static_cast<std::uint64_t>(kMaxBottomParticles) * kAncestryNodesPerParticle < 0x7FFFFFFFULL,
              "ancestry node ids must fit NodeId with room for the kNoNode marker");

// DpMap tiles are square blocks of 2^k × 2^k cells allocated on first write, so that
// unexplored space costs one u32 index entry per tile (16×16 cells = 1 KiB by default).
inline constexpr std::uint32_t kDpTileSideLog2 = SDPSLAM_DP_TILE_SIDE_LOG2;
static_assert(kDpTileSideLog2 >= 2U && kDpTileSideLog2 <= 6U, "kDpTileSideLog2 out of range [2,6]");
inline constexpr std::uint32_t kDpTileSideCells = 1U << kDpTileSideLog2;
inline constexpr std::uint32_t kDpTileCells = kDpTileSideCells * kDpTileSideCells;
// A DpMap observation addresses its cell as (tile slot << 2k) | cell-in-tile in 32 bits.
inline constexpr std::uint32_t kDpMaxTiles = 0xFFFFFFFFU >> (2U * kDpTileSideLog2);

}  // namespace sdpslam::capacity
