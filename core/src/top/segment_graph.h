#pragma once
// The Probabilistic Graph of Segments (PGS) of SDP-SLAM (paper §III, Algorithm 1 lines
// 8 and 12, Fig. 3 (c), (f), (i), (l)), with bounded memory.
//
// A level is one segment of the path; its nodes are the submaps the bottom-level
// particles built for it (one node per particle, identified by an opaque particle id for
// queries on the ancestry tree, with the submap's initial and final robot poses in the
// submap's own frame). Every node of level k is connected to every node of level k+1;
// an edge accumulates the ICP nearest-neighbour errors of the sampled submap
// combinations that used it.
//
// Edge probability (equation (4), read as printed upside down):
//   p(a, b) = (1/E_ab) / Σ_ij (1/E_ij)        over all edges between levels k and k+1,
// with E_ab the effective error of the edge:
//   - never sampled:             options.prior_error_m (so such edges can be chosen);
//   - Accumulation::kSum:        the sum of the recorded errors (the paper's choice; an
//                                edge sampled often piles up error, so rarely sampled
//                                edges are favoured: exploration);
//   - Accumulation::kMean:       the mean recorded error (favours the best match);
//   - raised to options.error_floor_m if smaller (a perfect match has error 0).
// Conditional sampling uses the same weights restricted to one row or column:
//   p(b | a) = (1/E_ab) / Σ_j (1/E_aj),  p(a | b) = (1/E_ab) / Σ_i (1/E_ib).
// All sampling takes a uniform number u in [0, 1) from the caller's deterministic RNG and
// walks the nodes in index order (inverse CDF), so results are reproducible.
//
// Bounded memory: options.max_levels live levels in a ring of fixed slots, each with
// room for options.nodes_per_level nodes and the nodes_per_level² edges to the next
// level, all carved from an Arena at init. When the ring is full add_level() refuses
// (kFull, counted); the caller then makes the oldest level PERMANENT with the node the
// best top-level particle chose (make_oldest_permanent): the other nodes of that level
// and all its edges are released and its slot is reused. The chosen node is kept as the
// anchor (with its place in the global frame and its edges to the next level, which are
// then frozen), so chains still compose into one global frame and the new oldest live
// level can still be sampled conditionally on it.
//
// Frame convention (Fig. 3 (l)). Each submap lives in its own frame. Its initial pose is
// the first robot pose and its final pose the last robot pose of its segment, both in
// that frame. The robot pose that ends segment k is the one that starts segment k+1, so
//   T_ab = final_a ⊕ initial_b⁻¹
// is the pose of submap b's frame in submap a's frame: a point p of submap b is at
// T_ab ⊕ p in submap a. When bottom particles restart at the origin (initial_b =
// identity), T_ab = final_a. The global frame is the frame of the submap of the first
// segment ever added (level 0).
//
// Cost: add_level O(N²) (zeroing edges), record_error O(1), pair_probability and
// sample_pair O(N²), conditional sampling O(N), make_oldest_permanent O(N),
// invariants_hold O(L·N²). Nothing allocates after init.
#include <cstddef>
#include <cstdint>

#include "sdpslam/core/arena.h"
#include "sdpslam/core/capacities.h"
#include "sdpslam/core/pose2.h"
#include "sdpslam/core/sdp_options.h"  // PgsAccumulation
#include "sdpslam/core/state_io.h"

namespace sdpslam {

// What add_level() needs to know about one submap.
struct PgsNodeInput {
  std::uint32_t particle_id = 0U;  // opaque: the bottom-level particle (ancestry node) id
  Pose2 initial_pose;              // first robot pose of the segment, submap frame
  Pose2 final_pose;                // last robot pose of the segment, submap frame
};

struct PgsNode {
  std::uint32_t particle_id = 0U;
  std::uint32_t level = 0U;  // the segment index (absolute, never reused)
  std::uint32_t index = 0U;  // position within its level
  Pose2 initial_pose;
  Pose2 final_pose;
};

struct SegmentGraphOptions {
  std::uint32_t max_levels = 32U;       // in [2, capacity::kMaxPgsLevels]
  std::uint32_t nodes_per_level = 10U;  // in [1, capacity::kMaxPgsNodesPerLevel]
  PgsAccumulation accumulation = PgsAccumulation::kSum;
  double prior_error_m = 1.0;    // > 0, finite
  double error_floor_m = 1e-6;   // > 0, finite

  bool valid() const;
};

enum class PgsStatus : std::uint8_t {
  kOk,
  kNotInitialised,
  kFull,         // add_level: every level slot is live; make the oldest permanent first
  kNoLevel,      // the level is not live (never added, or already permanent), or the
                 // operation needs a neighbouring level that is not live
  kBadNode,      // node index not in the level
  kBadArgument,  // count 0 or above nodes_per_level, u outside [0, 1), error not finite
                 // or negative, null array with a count
};

const char* to_string(PgsStatus status);

struct PgsLevelResult {
  PgsStatus status = PgsStatus::kNotInitialised;
  std::uint32_t level = 0U;  // the new level's index (== segment index) when kOk
};

struct PgsPick {
  PgsStatus status = PgsStatus::kNotInitialised;
  std::uint32_t node = 0U;
};

struct PgsPairPick {
  PgsStatus status = PgsStatus::kNotInitialised;
  std::uint32_t node_a = 0U;  // in level k
  std::uint32_t node_b = 0U;  // in level k + 1
};

struct PgsPermanentResult {
  PgsStatus status = PgsStatus::kNotInitialised;
  PgsNode node;             // the node that became permanent
  Pose2 frame_in_global;    // its submap frame in the global frame
  std::uint32_t released_nodes = 0U;
  std::uint32_t released_edges = 0U;
};

class SegmentGraph {
 public:
  SegmentGraph() = default;
  SegmentGraph(const SegmentGraph&) = delete;
  SegmentGraph& operator=(const SegmentGraph&) = delete;

  // Arena bytes init() takes (padding included); 0 iff the options are invalid or the
  // size does not fit size_t.
  static std::size_t required_bytes(const SegmentGraphOptions& options);
  // False iff already initialised, options invalid, or the arena is too small (the
  // graph then stays uninitialised). Call once.
  bool init(const SegmentGraphOptions& options, Arena& arena);
  bool initialised() const { return nodes_ != nullptr; }
  const SegmentGraphOptions& options() const { return options_; }

  // ---- levels (Algorithm 1 line 8) --------------------------------------------------
  // Appends a level with `count` nodes (node i gets index i). kFull iff all max_levels
  // slots are live (full_count() bumps; nothing changes). Edges from the previous level
  // start unsampled.
  PgsLevelResult add_level(const PgsNodeInput* nodes, std::uint32_t count);
  std::uint32_t first_live_level() const { return first_live_; }
  std::uint32_t live_level_count() const { return live_count_; }
  // Levels ever added (== index the next add_level will return).
  std::uint32_t level_end() const { return first_live_ + live_count_; }
  bool is_live(std::uint32_t level) const { return level >= first_live_ && level < level_end(); }
  // 0 iff the level is not live.
  std::uint32_t node_count(std::uint32_t level) const;
  // nullptr iff the level is not live or index is out of range.
  const PgsNode* node(std::uint32_t level, std::uint32_t index) const;

  // ---- errors (Algorithm 1 line 12) -------------------------------------------------
  // Adds one ICP error sample to the edge (level: a) → (level+1: b). error_m must be
  // finite and >= 0 (an ICP result without overlap must not be recorded).
  PgsStatus record_error(std::uint32_t level, std::uint32_t a, std::uint32_t b, double error_m);
  // Adds error_m to every edge of the chain choices[0] (first_level), choices[1]
  // (first_level+1), ... (count >= 2); all-or-nothing (nothing recorded on failure).
  PgsStatus record_chain_error(std::uint32_t first_level, const std::uint32_t* choices, std::uint32_t count,
                               double error_m);
  // Effective error E_ab as defined above; negative iff the edge does not exist.
  double edge_error(std::uint32_t level, std::uint32_t a, std::uint32_t b) const;
  // Samples recorded on the edge; 0 also when it does not exist.
  std::uint32_t edge_sample_count(std::uint32_t level, std::uint32_t a, std::uint32_t b) const;
  // p(a, b) of equation (4); negative iff the edge does not exist.
  double pair_probability(std::uint32_t level, std::uint32_t a, std::uint32_t b) const;

  // ---- sampling (Algorithm 1 line 10), u in [0, 1) ----------------------------------
  // (a, b) from p(a, b) over the edges between level and level+1.
  PgsPairPick sample_pair(std::uint32_t level, double u) const;
  // b in level+1 from p(b | a).
  PgsPick sample_next(std::uint32_t level, std::uint32_t a, double u) const;
  // a in level-1 from p(a | b), b in `level` (level-1 must be live).
  PgsPick sample_previous(std::uint32_t level, std::uint32_t b, double u) const;
  // A node of the oldest live level: conditional on the permanent anchor if there is
  // one, else from the marginal Σ_b p(a, b) of the first edge layer, else uniform.
  PgsPick sample_first(double u) const;

  // ---- transforms (Fig. 3 (l)) ------------------------------------------------------
  // T_ab = a.final ⊕ b.initial⁻¹ (see the frame convention above).
  static Pose2 transform_between(const PgsNode& a, const PgsNode& b);
  // Same for level: a and level+1: b; kOk iff both nodes exist.
  PgsStatus transform_between(std::uint32_t level, std::uint32_t a, std::uint32_t b, Pose2& out) const;
  // Places the chosen submap of each live level, from the oldest live level on
  // (choices[i] in level first_live_level()+i, 1 <= count <= live_level_count()), in
  // the global frame: out_poses[i] is that submap's frame in the global frame.
  PgsStatus compose_chain(const std::uint32_t* choices, std::uint32_t count, Pose2* out_poses) const;

  // ---- permanent levels -------------------------------------------------------------
  // Fixes the oldest live level to node `chosen`, releases the level's slot (its other
  // nodes and all its edges) and keeps `chosen` as the anchor. kNoLevel iff no level is
  // live, kBadNode iff chosen is out of range.
  PgsPermanentResult make_oldest_permanent(std::uint32_t chosen);
  bool has_anchor() const { return permanent_count_ > 0U; }
  // The most recent permanent node and its frame in the global frame (valid iff has_anchor()).
  const PgsNode& anchor() const { return anchor_; }
  const Pose2& anchor_frame() const { return anchor_frame_; }
  // Moves the anchor's frame (loop closure adjusted it); later chains compose from it.
  // Ignored (counted as misuse) without an anchor.
  void set_anchor_frame(const Pose2& frame) {
    if (has_anchor()) anchor_frame_ = frame;
    else ++misuse_count_;
  }

  // ---- diagnostics ------------------------------------------------------------------
  std::uint32_t levels_used() const { return live_count_; }
  std::uint32_t peak_levels_used() const { return peak_live_; }  // never decreases
  std::uint32_t live_node_count() const;
  std::uint32_t live_edge_count() const;
  std::uint32_t permanent_level_count() const { return permanent_count_; }
  std::uint32_t full_count() const { return full_count_; }      // refused add_level calls
  std::uint32_t misuse_count() const { return misuse_count_; }  // other refused calls
  // Full self-check: ring bookkeeping, node counts, node labels, edge sanity, counters.
  bool invariants_hold() const;

  // The mutable state, for snapshots (core/state_io.h): what init() did not fix.
  void transfer_state(StateIo& io);

 private:
  struct Edge {
    double error_sum_m = 0.0;
    std::uint32_t samples = 0U;
  };

  std::uint32_t slot_of(std::uint32_t level) const { return (head_ + (level - first_live_)) % options_.max_levels; }
  const Edge* edge_ptr(std::uint32_t level, std::uint32_t a, std::uint32_t b) const;
  Edge* edge_ptr(std::uint32_t level, std::uint32_t a, std::uint32_t b) {
    return const_cast<Edge*>(static_cast<const SegmentGraph*>(this)->edge_ptr(level, a, b));
  }
  double effective_error(const Edge& e) const;
  double weight(const Edge& e) const { return 1.0 / effective_error(e); }
  PgsStatus refuse(PgsStatus s) const {
    ++misuse_count_;
    return s;
  }
  // The checks of every sample_*() call, in order: initialised, u in [0, 1), then
  // levels_live() (whether the levels it draws from are live, asked only when the graph
  // is initialised). kOk, or the refusal (counted).
  template <class LevelsLive>
  PgsStatus check_sampling(double u, LevelsLive&& levels_live) const;  // segment_graph.cpp

  SegmentGraphOptions options_;
  PgsNode* nodes_ = nullptr;          // max_levels × nodes_per_level
  Edge* edges_ = nullptr;             // max_levels × nodes_per_level²: slot(k) → level k+1
  std::uint32_t* level_nodes_ = nullptr;  // node count per slot, 0 when the slot is free
  Edge* anchor_edges_ = nullptr;      // anchor → oldest live level (frozen)
  PgsNode anchor_;
  Pose2 anchor_frame_;
  std::uint32_t head_ = 0U;        // slot of first_live_
  std::uint32_t first_live_ = 0U;
  std::uint32_t live_count_ = 0U;
  std::uint32_t peak_live_ = 0U;
  std::uint32_t permanent_count_ = 0U;
  std::uint32_t full_count_ = 0U;
  mutable std::uint32_t misuse_count_ = 0U;
};

}  // namespace sdpslam
