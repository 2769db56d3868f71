#pragma once
// Ancestry tree of the bottom-level DP-SLAM particle filter (paper §II-A, "DP-Mapping";
// Eliazar & Parr, DP-SLAM, IJCAI 2003 §3).
//
// The leaves are the current particles; inner nodes are the ancestors they descend from.
// Every node owns (a) the map observations it made (kept by DpMap, which listens to the
// tree through TreeListener) and (b) the poses it added to the trajectory (path entries,
// kept here). A particle's map and path are the union of its own and its ancestors'.
//
// Life cycle per filter step (Algorithm 1 line 3):
//   1. resampling: for every drawn parent p, `add_child(p)`, `set_active(child, true)`;
//      then `set_active(p, false)` for every particle of the old generation;
//   2. `prune(&map)`: removes inactive childless nodes and merges every inactive node
//      with a single child into that child (§II-A: "a particle that generates a single
//      child has its information merged with the information of its child"), then
//      recomputes the DFS labels that make ancestor queries O(1);
//   3. the new particles record poses (`append_pose`) and map updates (DpMap::update);
//   4. `drain_committed(sink)` hands the poses every particle agrees on to a sink.
//
// Node ids are slot indices of a fixed pool and are recycled after a node is removed.
// Ids are stable: prune never changes the id of a node that survives it; a merge keeps
// the CHILD's id (so the id a caller holds for a current particle never changes) and
// frees the parent's. Active nodes are never removed nor merged away, so a caller can
// keep any node alive (e.g. the last particle of an anchored segment, Algorithm 1
// line 5) by leaving it active.
//
// Size bound: after prune every inactive node has ≥2 children and every leaf is active,
// so size() ≤ 2·A − 1 for A active nodes (A ≥ 1). During resampling the old generation
// (≤ 2N − 1 nodes) gains N children, so a node pool of 3·N
// (capacity::kAncestryNodesPerParticle · N) is never exhausted in normal operation;
// add_child() still refuses and counts if it is.
//
// Memory: everything comes from the Arena given to init(); no heap, no exceptions.
// Cost: add_child/set_active/append_pose/is_ancestor_or_self O(1) (see the exception in
// is_ancestor_or_self), prune O(size + path work of merges), invariants_hold O(capacity).
#include <cstddef>
#include <cstdint>

#include "sdpslam/core/arena.h"
#include "sdpslam/core/capacities.h"
#include "sdpslam/core/pool.h"
#include "sdpslam/core/pose2.h"
#include "sdpslam/core/state_io.h"

namespace sdpslam {

using NodeId = std::uint32_t;
inline constexpr NodeId kNoNode = 0xFFFFFFFFU;

// Told by AncestryTree::prune() about every node whose information leaves the tree.
// Called synchronously, in post-order (children before parents), before the node's slot
// is released; the listener must not call back into the tree's mutating functions.
class TreeListener {
 public:
  // `node` had no child and was inactive: its information will never be inherited.
  virtual void on_node_removed(NodeId node) = 0;
  // `parent` (inactive, exactly one child) is merged into `child`: everything `parent`
  // recorded now belongs to `child`, except where `child` has its own (newer) record.
  // After the call `parent`'s id is released; `child` takes parent's place in the tree.
  virtual void on_node_merged(NodeId parent, NodeId child) = 0;

 protected:
  ~TreeListener() = default;
};

// Receives poses that every current particle shares (drain_committed()).
class PoseSink {
 public:
  virtual void on_committed(std::int64_t stamp_us, const Pose2& pose) = 0;

 protected:
  ~PoseSink() = default;
};

class AncestryTree {
 private:
  // Hot data for ancestor queries, indexed by NodeId. A node is labelled iff
  // anchor == its own id; a node added since the last prune has anchor = the nearest
  // labelled ancestor.
  struct Label {
    std::uint32_t pre = 0U;
    std::uint32_t post = 0U;
    std::uint32_t depth = 0U;
    NodeId anchor = kNoNode;
    std::uint32_t tree = 0U;  // tree_sequence(): create_root() order of the node's tree
  };
 public:
  AncestryTree() = default;
  AncestryTree(const AncestryTree&) = delete;
  AncestryTree& operator=(const AncestryTree&) = delete;

  // Node capacity that add_child() can never exhaust for a filter of `particles`
  // particles that prunes after every resampling (see "Size bound" above).
  static constexpr std::uint32_t node_capacity_for(std::uint32_t particles) {
    return capacity::kAncestryNodesPerParticle * particles;
  }
  // Arena bytes init() needs for these capacities (alignment padding included).
  static std::size_t required_arena_bytes(std::uint32_t node_capacity, std::uint32_t path_entry_capacity);

  // Carves the node pool, label table and path-entry pool from `arena`. Returns false
  // iff a capacity is 0, node_capacity ≥ 0x7FFFFFFF, or the arena is too small (the tree
  // is then unusable: capacity() == 0 and every operation is refused). Call once.
  bool init(Arena& arena, std::uint32_t node_capacity, std::uint32_t path_entry_capacity);

  // ---- structure -------------------------------------------------------------------
  // A new root, active, with no poses. Several roots may coexist (a forest: e.g. the
  // particles of a new segment restart from a fresh root, Algorithm 1 line 6).
  // kNoNode iff the node pool is exhausted (node_oom_count() bumps) or not initialised.
  NodeId create_root();
  // A new child of `parent`, active, depth = depth(parent) + 1, no poses, labelled
  // provisionally until the next prune (see is_ancestor_or_self). kNoNode iff the pool
  // is exhausted (node_oom_count() bumps) or `parent` is not a live node
  // (misuse_count() bumps).
  NodeId add_child(NodeId parent);
  // Marks whether `node` is a current particle. False (misuse_count() bumps) iff `node`
  // is not live.
  bool set_active(NodeId node, bool active);

  // §II-A prune and merge, then relabel. Repeats until no rule applies (a removal can
  // make the parent childless, a merge can leave the grandparent with one child): after
  // it, every leaf is active and every inactive node has ≥2 children. `listener` (may be
  // nullptr) is called for every removal and merge. Path entries of a removed node are
  // freed; those of a merged parent are prepended to the child's in O(1).
  // Returns the number of nodes released (removed + merged-away parents).
  std::uint32_t prune(TreeListener* listener);

  // ---- queries (O(1) unless stated) --------------------------------------------------
  bool contains(NodeId node) const { return node < capacity_ && nodes_.slot_in_use(node); }
  bool is_active(NodeId node) const;
  NodeId parent(NodeId node) const;           // kNoNode for a root or a dead id
  NodeId first_child(NodeId node) const;      // kNoNode if none / dead id
  NodeId next_sibling(NodeId node) const;     // next child of the same parent (or next root)
  NodeId first_root() const { return first_root_; }  // kNoNode iff the tree is empty
  std::uint32_t child_count(NodeId node) const;       // 0 for a dead id
  // Edges from the node's root; exact after prune, parent's + 1 for a node added since.
  std::uint32_t depth(NodeId node) const { return contains(node) ? labels_[node].depth : 0U; }
  // Which tree of the forest `node` belongs to: 1 for the first create_root(), one more
  // for each later root; a child inherits its parent's, and prune keeps it (removals and
  // merges stay inside one tree). Newer trees have larger numbers, so DpMap can order
  // its cell lists by tree. 0 for a dead id. Wraps after 2^32 roots (not reachable:
  // one root per segment).
  std::uint32_t tree_sequence(NodeId node) const { return contains(node) ? labels_[node].tree : 0U; }
  // The same without the liveness check, for callers that hold live ids (DpMap).
  std::uint32_t tree_sequence_unchecked(NodeId node) const { return labels_[node].tree; }

  // True iff `ancestor` is `descendant` or one of its ancestors. O(1) (two interval
  // comparisons on DFS pre/post numbers) whenever `ancestor` existed at the last prune;
  // when `ancestor` was added since, O(k) with k = generations added since the last
  // prune (k ≤ 1 in the normal cycle). False if either id is dead.
  bool is_ancestor_or_self(NodeId ancestor, NodeId descendant) const {
    if (ancestor == descendant) return contains(ancestor);
    if (!contains(ancestor) || !contains(descendant)) return false;
    const Label& a = labels_[ancestor];
    const Label& d = labels_[descendant];
    if (a.anchor == ancestor) {
      const Label& da = labels_[d.anchor];
      return a.pre <= da.pre && da.post <= a.post;
    }
    return provisional_is_ancestor(ancestor, descendant);
  }

  // Hot-loop form of is_ancestor_or_self for many candidate ancestors of one live
  // descendant (DpMap lookups): the descendant's anchor interval is read once.
  // Preconditions (unchecked): `descendant` and every queried `ancestor` are live.
  class DescendantQuery {
   public:
    DescendantQuery(const AncestryTree& tree, NodeId descendant)
        : tree_(tree), labels_(tree.labels_), descendant_(descendant) {
      const Label& anchor = labels_[labels_[descendant].anchor];
      pre_ = anchor.pre;
      post_ = anchor.post;
    }
    bool has_ancestor_or_self(NodeId ancestor) const {
      const Label& a = labels_[ancestor];
      if (a.anchor == ancestor) return a.pre <= pre_ && post_ <= a.post;
      return ancestor == descendant_ || tree_.provisional_is_ancestor(ancestor, descendant_);
    }
    std::uint32_t depth(NodeId live) const { return labels_[live].depth; }

   private:
    const AncestryTree& tree_;
    const Label* labels_;
    NodeId descendant_;
    std::uint32_t pre_ = 0U;
    std::uint32_t post_ = 0U;
  };

  // ---- path entries ------------------------------------------------------------------
  // Appends a pose to `node`'s own path (callers append in time order). False iff
  // `node` is dead (misuse_count() bumps) or the path-entry pool is exhausted: the
  // documented degraded path is that the pose is NOT recorded and path_oom_count()
  // bumps; earlier poses and the tree are unaffected, the trajectory just has a gap.
  bool append_pose(NodeId node, std::int64_t stamp_us, const Pose2& pose);
  // Uncommitted poses of `node` alone (including those merged in from ancestors).
  std::uint32_t pose_count(NodeId node) const;
  // Latest pose on the root→`node` path (own or inherited). Because drain_committed()
  // always keeps a root's newest pose, this is false only iff no pose was ever recorded
  // on that path (or `node` is dead). O(depth) in the worst case, O(1) when `node` has
  // poses of its own.
  bool last_pose(NodeId node, std::int64_t* stamp_us, Pose2* pose) const;
  // Calls f(stamp_us, pose) for every uncommitted pose on the path root→`leaf`, oldest
  // first. Cost O(depth + poses). Committed poses went to the sink and are not repeated.
  // Uses an internal scratch array: not reentrant (do not call it from inside `f`).
  template <class F>
  void for_each_pose_from_root(NodeId leaf, F&& f) const;
  // Commitment: while a root has ≥2 children its own poses are shared by every particle
  // of that tree and can never change, so they are emitted to `sink` in time order and
  // their entries freed (memory does not grow with run length) — all but the newest,
  // which stays so that last_pose() always has an answer; it is emitted by a later
  // drain, possibly after a merge carried it into a child. The same holds for the only
  // root of the tree when it is an active leaf: one particle (or all of them, on one
  // node) whose lineage never branched, e.g. a one-particle filter, which never
  // resamples. Other roots with fewer than two children keep theirs. Emitted poses
  // followed by for_each_pose_from_root(leaf) reproduce the leaf's full trajectory
  // exactly. Returns the number of poses emitted. O(emitted).
  std::uint32_t drain_committed(PoseSink& sink);

  // ---- accounting --------------------------------------------------------------------
  std::uint32_t size() const { return nodes_.size(); }
  std::uint32_t capacity() const { return capacity_; }
  std::uint32_t active_count() const { return active_count_; }
  std::uint32_t peak_used() const { return nodes_.peak_used(); }
  std::uint32_t node_oom_count() const { return node_oom_count_; }
  std::uint32_t path_entries_used() const { return paths_.size(); }
  std::uint32_t path_entry_capacity() const { return paths_.capacity(); }
  std::uint32_t path_entries_peak() const { return paths_.peak_used(); }
  std::uint32_t path_oom_count() const { return path_oom_count_; }
  std::uint32_t misuse_count() const { return misuse_count_; }
  std::uint64_t committed_count() const { return committed_count_; }
  std::size_t footprint_bytes() const;

  // Full self-check, O(capacity + path entries): parent/child links agree and child
  // counts match; every live node is reachable from a root (no orphan) and the pool's
  // count equals the reachable count (no leak); node pool and path pool invariants;
  // path lists are well-formed and their lengths add up to the path pool's count; the
  // active count matches; after a prune (until the next add_child/create_root/
  // set_active) every leaf is active, every inactive node has ≥2 children and
  // size ≤ 2·active − 1; DFS labels nest exactly as the tree does.
  bool invariants_hold() const;
  // The mutable state, for snapshots (core/state_io.h): what init() did not fix.
  void transfer_state(StateIo& io);

 private:
  struct Node {
    NodeId parent = kNoNode;
    NodeId first_child = kNoNode;
    NodeId next_sibling = kNoNode;
    NodeId prev_sibling = kNoNode;
    std::uint32_t child_count = 0U;
    std::uint32_t path_head = kNoNode;  // oldest own pose (index into paths_)
    std::uint32_t path_tail = kNoNode;  // newest own pose
    std::uint32_t path_count = 0U;
    bool active = true;
  };
  struct PathEntry {
    std::int64_t stamp_us = 0;
    Pose2 pose{};
    std::uint32_t next = kNoNode;
  };

  bool provisional_is_ancestor(NodeId ancestor, NodeId descendant) const;
  Node& node(NodeId id) { return *nodes_.at_index(id); }
  const Node& node(NodeId id) const { return *nodes_.at_index(id); }
  const PathEntry& path_entry(std::uint32_t index) const { return *paths_.at_index(index); }
  NodeId allocate_node(NodeId parent);
  void unlink(NodeId id);
  void replace_in_parent(NodeId old_id, NodeId new_id);
  void free_path(NodeId id);
  void relabel();

  ArenaPool<Node> nodes_;
  ArenaPool<PathEntry> paths_;
  Label* labels_ = nullptr;
  NodeId* scratch_ = nullptr;  // capacity_ entries, for root-ward walks replayed top-down
  std::uint32_t capacity_ = 0U;
  NodeId first_root_ = kNoNode;
  NodeId last_root_ = kNoNode;
  std::uint32_t active_count_ = 0U;
  std::uint32_t label_counter_ = 0U;  // next free DFS number (new roots take fresh ones)
  std::uint32_t tree_counter_ = 0U;   // create_root() calls: the newest tree's sequence
  std::uint32_t node_oom_count_ = 0U;
  std::uint32_t path_oom_count_ = 0U;
  std::uint32_t misuse_count_ = 0U;
  std::uint64_t committed_count_ = 0U;
  bool pruned_ = false;  // no structural change since the last prune
};

template <class F>
void AncestryTree::for_each_pose_from_root(NodeId leaf, F&& f) const {
  if (!contains(leaf)) return;
  // Climb once into the init-time scratch array, then replay it top-down.
  std::uint32_t n = 0U;
  for (NodeId id = leaf; id != kNoNode && n < capacity_; id = node(id).parent) scratch_[n++] = id;
  while (n > 0U) {
    const Node& nd = node(scratch_[--n]);
    for (std::uint32_t e = nd.path_head; e != kNoNode; e = path_entry(e).next) {
      const PathEntry& pe = path_entry(e);
      f(pe.stamp_us, pe.pose);
    }
  }
}

}  // namespace sdpslam
