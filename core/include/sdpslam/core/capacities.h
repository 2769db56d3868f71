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
// Observations of one DpMap: its (owner, cell) index has 1.5 slots per observation, and
// slot numbers stay below 2^31. The options' validators refuse more.
inline constexpr std::uint32_t kDpMaxObservations = 1U << 30U;

#ifndef SDPSLAM_VIEW_CACHE_SLOTS_LOG2
#define SDPSLAM_VIEW_CACHE_SLOTS_LOG2 14
#endif
// Cells one scan match remembers of its particle's view (view_cache.h), 16 bytes each,
// allocated only with the scan-matching proposal. A hill climb reads ~10^3-10^4 distinct
// cells; past 3/4 of the slots reads go to the map uncached (same values, slower).
inline constexpr std::uint32_t kViewCacheSlotsLog2 = SDPSLAM_VIEW_CACHE_SLOTS_LOG2;
static_assert(kViewCacheSlotsLog2 >= 4U && kViewCacheSlotsLog2 <= 24U, "kViewCacheSlotsLog2 out of range [4,24]");
inline constexpr std::uint32_t kViewCacheSlots = 1U << kViewCacheSlotsLog2;

}  // namespace sdpslam::capacity

// ---- Top level: ICP matching, free-space skeleton, graph of segments (paper §III) ---
namespace sdpslam::capacity {

#ifndef SDPSLAM_MAX_ICP_POINTS
#define SDPSLAM_MAX_ICP_POINTS 2048
#endif
#ifndef SDPSLAM_ICP_HASH_BUCKETS_LOG2
#define SDPSLAM_ICP_HASH_BUCKETS_LOG2 12
#endif
#ifndef SDPSLAM_MAX_SKELETON_PATCH_SIDE
#define SDPSLAM_MAX_SKELETON_PATCH_SIDE 2048
#endif
#ifndef SDPSLAM_MAX_PGS_LEVELS
#define SDPSLAM_MAX_PGS_LEVELS 256
#endif

// Points in each of the two sets one ICP call aligns (skeleton points of a submap).
inline constexpr std::uint32_t kMaxIcpPoints = SDPSLAM_MAX_ICP_POINTS;
static_assert(kMaxIcpPoints >= 8U && kMaxIcpPoints <= 65536U, "kMaxIcpPoints out of range");
// Buckets of ICP's nearest-neighbour grid hash (a power of two, >= the point count so
// that chains stay short).
inline constexpr std::uint32_t kIcpHashBucketsLog2 = SDPSLAM_ICP_HASH_BUCKETS_LOG2;
static_assert(kIcpHashBucketsLog2 >= 4U && kIcpHashBucketsLog2 <= 20U, "kIcpHashBucketsLog2 out of range [4,20]");
inline constexpr std::uint32_t kIcpHashBuckets = 1U << kIcpHashBucketsLog2;

// Largest side, in cells, of a grid patch whose free-space skeleton is extracted (the
// scratch buffers themselves are sized at init for the patch the caller asks for).
inline constexpr std::uint32_t kMaxSkeletonPatchSide = SDPSLAM_MAX_SKELETON_PATCH_SIDE;
static_assert(kMaxSkeletonPatchSide >= 3U && kMaxSkeletonPatchSide <= 8192U, "kMaxSkeletonPatchSide out of range");

// Levels (segments) the Probabilistic Graph of Segments keeps live before the oldest are
// made permanent; nodes per level are bounded by kMaxBottomParticles (one submap each).
inline constexpr std::uint32_t kMaxPgsLevels = SDPSLAM_MAX_PGS_LEVELS;
static_assert(kMaxPgsLevels >= 2U && kMaxPgsLevels <= 65536U, "kMaxPgsLevels out of range");
// SdpOptions::defer_top_work: processed scans in a row after which the top level's work
// runs anyway (a bottom level processing every scan must not starve it).
inline constexpr std::uint32_t kMaxDeferredTopWork = 3U;
inline constexpr std::uint32_t kMaxPgsNodesPerLevel = kMaxBottomParticles;

}  // namespace sdpslam::capacity

// ---- Bottom-level DP-SLAM particle filter (dpslam_filter.h) ------------------------
namespace sdpslam::capacity {

// Upper bounds DpSlamOptions::validate() enforces on its per-particle provisioning.
// Ancestry nodes per particle: kAncestryNodesPerParticle is enough in normal operation;
// more only buys headroom, fewer is allowed to test the degraded path.
inline constexpr std::uint32_t kDpSlamMaxNodesPerParticle = 16U;
// Uncommitted poses per particle: the depth (in processed scans) back to the common
// ancestor of all particles; beyond it poses are dropped and counted.
inline constexpr std::uint32_t kDpSlamMaxPathEntriesPerParticle = 1000000U;
static_assert(kDpSlamMaxNodesPerParticle >= kAncestryNodesPerParticle, "nodes per particle bound below the tree's need");

}  // namespace sdpslam::capacity

// ---- SDP-SLAM two-level filter (sdp_slam.h) -----------------------------------------
namespace sdpslam::capacity {

#ifndef SDPSLAM_MAX_TOP_PARTICLES
#define SDPSLAM_MAX_TOP_PARTICLES 256
#endif
#ifndef SDPSLAM_MAX_PERMANENT_SUBMAPS
#define SDPSLAM_MAX_PERMANENT_SUBMAPS 4096
#endif

// Top-level particles (samples of submap combinations, paper §III, "60T").
inline constexpr std::uint32_t kMaxTopParticles = SDPSLAM_MAX_TOP_PARTICLES;
static_assert(kMaxTopParticles >= 1U && kMaxTopParticles <= 4096U, "kMaxTopParticles out of range");
// Permanent submaps whose skeletons stay available for loop-closing matches; beyond this
// the oldest are forgotten (counted), their map is already in the global map.
inline constexpr std::uint32_t kMaxPermanentSubmaps = SDPSLAM_MAX_PERMANENT_SUBMAPS;
static_assert(kMaxPermanentSubmaps >= 1U && kMaxPermanentSubmaps <= 65536U, "kMaxPermanentSubmaps out of range");
// Loop-closure constraints SDP-SLAM keeps between submap frames (frame_graph.h).
#ifndef SDPSLAM_MAX_LOOP_CONSTRAINTS
#define SDPSLAM_MAX_LOOP_CONSTRAINTS 16384
#endif
inline constexpr std::uint32_t kMaxLoopConstraints = SDPSLAM_MAX_LOOP_CONSTRAINTS;
static_assert(kMaxLoopConstraints >= 1U && kMaxLoopConstraints <= 1048576U, "kMaxLoopConstraints out of range");
// Bottom particles per segment in SDP-SLAM: a PGS level holds one node per particle and a
// top-level choice is stored in 16 bits.
static_assert(kMaxPgsNodesPerLevel <= 65535U, "PGS node index must fit 16 bits");

}  // namespace sdpslam::capacity
