// Ancestry tree (paper §II-A): prune and merge, O(1) ancestor labels, path entries and
// commitment, exhaustion. The randomised test checks invariants_hold() after every
// operation over thousands of resampling generations.
#include <CppUTest/TestHarness.h>

#include <cstdint>
#include <vector>

#include "sdpslam/core/bottom/ancestry_tree.h"
#include "test_rng.h"

using sdpslam::AncestryTree;
using sdpslam::kNoNode;
using sdpslam::NodeId;
using sdpslam::Pose2;

namespace {

struct Recorder final : sdpslam::TreeListener {
  std::vector<NodeId> removed;
  std::vector<std::pair<NodeId, NodeId>> merged;
  void on_node_removed(NodeId n) override { removed.push_back(n); }
  void on_node_merged(NodeId p, NodeId c) override { merged.emplace_back(p, c); }
};

struct Collector final : sdpslam::PoseSink {
  std::vector<std::int64_t> stamps;
  void on_committed(std::int64_t stamp_us, const Pose2&) override { stamps.push_back(stamp_us); }
};

// Reference answer by walking parent links.
bool naive_is_ancestor_or_self(const AncestryTree& t, NodeId a, NodeId d) {
  for (NodeId x = d; x != kNoNode; x = t.parent(x)) {
    if (x == a) return true;
  }
  return false;
}

struct TreeFixture {
  std::vector<unsigned char> buffer;
  sdpslam::Arena arena;
  AncestryTree tree;
  TreeFixture(std::uint32_t nodes, std::uint32_t paths) {
    buffer.resize(AncestryTree::required_arena_bytes(nodes, paths));
    arena.reset(buffer.data(), buffer.size());
    CHECK_TRUE(tree.init(arena, nodes, paths));
  }
};

std::vector<std::int64_t> path_stamps(const AncestryTree& t, NodeId leaf) {
  std::vector<std::int64_t> s;
  t.for_each_pose_from_root(leaf, [&](std::int64_t stamp_us, const Pose2&) { s.push_back(stamp_us); });
  return s;
}

}  // namespace

TEST_GROUP(AncestryTree){};

TEST(AncestryTree, init_refuses_zero_capacities_and_a_too_small_arena) {
  alignas(16) static unsigned char small[64];
  sdpslam::Arena arena(small, sizeof small);
  AncestryTree a;
  CHECK_FALSE(a.init(arena, 0U, 10U));
  AncestryTree b;
  CHECK_FALSE(b.init(arena, 10U, 0U));
  AncestryTree c;
  CHECK_FALSE(c.init(arena, 100U, 100U));
  LONGS_EQUAL(0, c.capacity());
  LONGS_EQUAL(kNoNode, c.create_root());
  CHECK_TRUE(c.invariants_hold());
}

TEST(AncestryTree, required_arena_bytes_is_enough) {
  std::vector<unsigned char> buf(AncestryTree::required_arena_bytes(300U, 1000U));
  sdpslam::Arena arena(buf.data(), buf.size());
  AncestryTree t;
  CHECK_TRUE(t.init(arena, 300U, 1000U));
  LONGS_EQUAL(300, t.capacity());
  LONGS_EQUAL(1000, t.path_entry_capacity());
}

TEST(AncestryTree, children_know_their_ancestors_before_and_after_prune) {
  TreeFixture f(16U, 16U);
  AncestryTree& t = f.tree;
  const NodeId r = t.create_root();
  const NodeId a = t.add_child(r);
  const NodeId b = t.add_child(r);
  const NodeId a1 = t.add_child(a);
  CHECK_TRUE(t.is_ancestor_or_self(r, a1));
  CHECK_TRUE(t.is_ancestor_or_self(a, a1));
  CHECK_TRUE(t.is_ancestor_or_self(a1, a1));
  CHECK_FALSE(t.is_ancestor_or_self(b, a1));
  CHECK_FALSE(t.is_ancestor_or_self(a1, a));
  LONGS_EQUAL(2, t.depth(a1));
  CHECK_TRUE(t.invariants_hold());
  t.set_active(r, false);
  t.set_active(a, false);
  t.prune(nullptr);  // a has one child: merged into a1
  CHECK_TRUE(t.invariants_hold());
  CHECK_FALSE(t.contains(a));
  LONGS_EQUAL(r, t.parent(a1));
  LONGS_EQUAL(1, t.depth(a1));
  CHECK_TRUE(t.is_ancestor_or_self(r, a1));
  CHECK_FALSE(t.is_ancestor_or_self(b, a1));
}

TEST(AncestryTree, prune_removes_inactive_leaves_recursively) {
  TreeFixture f(16U, 16U);
  AncestryTree& t = f.tree;
  const NodeId r = t.create_root();
  const NodeId a = t.add_child(r);
  const NodeId a1 = t.add_child(a);
  const NodeId a2 = t.add_child(a1);
  const NodeId b = t.add_child(r);
  for (NodeId n : {r, a, a1, a2}) t.set_active(n, false);
  Recorder rec;
  t.prune(&rec);
  CHECK_TRUE(t.invariants_hold());
  // a2, a1, a go (children first); r is left with one child and merges into b.
  LONGS_EQUAL(3U, rec.removed.size());
  LONGS_EQUAL(a2, rec.removed[0]);
  LONGS_EQUAL(a1, rec.removed[1]);
  LONGS_EQUAL(a, rec.removed[2]);
  LONGS_EQUAL(1U, rec.merged.size());
  LONGS_EQUAL(r, rec.merged[0].first);
  LONGS_EQUAL(b, rec.merged[0].second);
  LONGS_EQUAL(1, t.size());
  LONGS_EQUAL(b, t.first_root());
}

TEST(AncestryTree, merge_keeps_the_child_id_and_chains_collapse) {
  TreeFixture f(16U, 16U);
  AncestryTree& t = f.tree;
  NodeId x = t.create_root();
  const NodeId r = x;
  const NodeId other = t.add_child(r);
  for (int i = 0; i < 5; ++i) {
    t.set_active(x, false);
    x = t.add_child(x);
  }
  t.set_active(r, true);  // an active node is never merged away
  Recorder rec;
  t.prune(&rec);
  CHECK_TRUE(t.invariants_hold());
  CHECK_TRUE(t.contains(x));
  CHECK_TRUE(t.contains(r));
  CHECK_TRUE(t.contains(other));
  LONGS_EQUAL(r, t.parent(x));
  LONGS_EQUAL(3, t.size());
  LONGS_EQUAL(4U, rec.merged.size());
  for (const auto& m : rec.merged) CHECK_FALSE(t.contains(m.first));
}

TEST(AncestryTree, provisional_labels_answer_like_a_parent_walk) {
  TreeFixture f(256U, 16U);
  AncestryTree& t = f.tree;
  sdpslam::test::SplitMix64 rng(7U);
  std::vector<NodeId> nodes{t.create_root()};
  t.prune(nullptr);
  for (int i = 0; i < 120; ++i) {  // several generations without any prune
    const NodeId p = nodes[rng.below(static_cast<std::uint32_t>(nodes.size()))];
    nodes.push_back(t.add_child(p));
    if (i == 60) t.prune(nullptr);  // half labelled, half provisional
  }
  CHECK_TRUE(t.invariants_hold());
  for (NodeId a : nodes) {
    for (NodeId d : nodes) {
      if (!t.contains(a) || !t.contains(d)) continue;
      CHECK_EQUAL(naive_is_ancestor_or_self(t, a, d), t.is_ancestor_or_self(a, d));
    }
  }
}

TEST(AncestryTree, dead_ids_are_refused_and_counted) {
  TreeFixture f(8U, 8U);
  AncestryTree& t = f.tree;
  LONGS_EQUAL(kNoNode, t.add_child(3U));
  CHECK_FALSE(t.set_active(kNoNode, false));
  CHECK_FALSE(t.append_pose(5U, 1, Pose2{}));
  LONGS_EQUAL(3, t.misuse_count());
  CHECK_FALSE(t.is_ancestor_or_self(1U, 2U));
  LONGS_EQUAL(0, t.child_count(1U));
  CHECK_TRUE(t.invariants_hold());
}

TEST(AncestryTree, node_ids_are_recycled_after_removal) {
  TreeFixture f(4U, 4U);
  AncestryTree& t = f.tree;
  const NodeId r = t.create_root();
  const NodeId a = t.add_child(r);
  const NodeId b = t.add_child(r);
  t.set_active(a, false);
  t.prune(nullptr);
  CHECK_FALSE(t.contains(a));
  const NodeId c = t.add_child(b);
  const NodeId d = t.add_child(b);
  CHECK_TRUE(c == a || d == a);  // the freed slot was reused
  CHECK_TRUE(t.invariants_hold());
  LONGS_EQUAL(4, t.size());
}

TEST(AncestryTree, exhaustion_is_counted_and_survived) {
  TreeFixture f(5U, 4U);
  AncestryTree& t = f.tree;
  const NodeId r = t.create_root();
  std::vector<NodeId> kids;
  for (int i = 0; i < 8; ++i) {
    const NodeId c = t.add_child(r);
    if (c != kNoNode) kids.push_back(c);
    CHECK_TRUE(t.invariants_hold());
  }
  LONGS_EQUAL(4U, kids.size());
  LONGS_EQUAL(4, t.node_oom_count());
  LONGS_EQUAL(kNoNode, t.create_root());
  LONGS_EQUAL(5, t.node_oom_count());
  for (int i = 0; i < 6; ++i) t.append_pose(kids[0], i, Pose2{});
  LONGS_EQUAL(4, t.pose_count(kids[0]));
  LONGS_EQUAL(2, t.path_oom_count());
  // Recovery: pruning frees nodes and path entries, and the tree works again.
  t.set_active(kids[0], false);
  t.set_active(kids[1], false);
  t.prune(nullptr);
  CHECK_TRUE(t.invariants_hold());
  LONGS_EQUAL(0, t.path_entries_used());
  CHECK(t.add_child(kids[2]) != kNoNode);
  CHECK_TRUE(t.append_pose(kids[2], 9, Pose2{}));
  CHECK_TRUE(t.invariants_hold());
}

TEST(AncestryTree, merge_prepends_the_parents_poses_in_time_order) {
  TreeFixture f(8U, 32U);
  AncestryTree& t = f.tree;
  const NodeId r = t.create_root();
  t.append_pose(r, 1, Pose2{});
  const NodeId a = t.add_child(r);
  t.append_pose(a, 2, Pose2{});
  t.append_pose(a, 3, Pose2{});
  const NodeId a1 = t.add_child(a);
  t.append_pose(a1, 4, Pose2{});
  const NodeId b = t.add_child(r);
  t.append_pose(b, 5, Pose2{});
  t.set_active(r, false);
  t.set_active(a, false);
  t.prune(nullptr);
  CHECK_TRUE(t.invariants_hold());
  LONGS_EQUAL(3, t.pose_count(a1));  // 2, 3 merged in before 4
  const std::vector<std::int64_t> expect{1, 2, 3, 4};
  CHECK_TRUE(expect == path_stamps(t, a1));
  std::int64_t last = 0;
  CHECK_TRUE(t.last_pose(b, &last, nullptr));
  LONGS_EQUAL(5, last);
}

TEST(AncestryTree, commitment_emits_shared_poses_and_keeps_the_newest) {
  TreeFixture f(8U, 32U);
  AncestryTree& t = f.tree;
  const NodeId r = t.create_root();
  for (int i = 1; i <= 4; ++i) t.append_pose(r, i, Pose2{});
  const NodeId a = t.add_child(r);
  Collector sink;
  LONGS_EQUAL(0, t.drain_committed(sink));  // one child: the root may still merge
  const NodeId b = t.add_child(r);
  t.set_active(r, false);
  t.prune(nullptr);
  LONGS_EQUAL(3, t.drain_committed(sink));
  const std::vector<std::int64_t> committed{1, 2, 3};
  CHECK_TRUE(committed == sink.stamps);
  LONGS_EQUAL(1, t.pose_count(r));
  std::int64_t last = 0;
  CHECK_TRUE(t.last_pose(a, &last, nullptr));
  LONGS_EQUAL(4, last);
  LONGS_EQUAL(1, t.path_entries_used());
  // b dies, the root merges into a: the kept pose travels and is emitted later.
  t.set_active(b, false);
  t.prune(nullptr);
  CHECK_TRUE(t.invariants_hold());
  const std::vector<std::int64_t> rest{4};
  CHECK_TRUE(rest == path_stamps(t, a));
  LONGS_EQUAL(3U, t.committed_count());
}

TEST(AncestryTree, a_lineage_that_never_branches_commits_as_it_goes) {
  // One particle: every step a child, the parent retired and merged into it. Its poses
  // are all the filter has; without commitment they would fill the path pool (4 here)
  // and the trajectory would be lost.
  TreeFixture f(4U, 4U);
  AncestryTree& t = f.tree;
  NodeId p = t.create_root();
  Collector sink;
  for (int step = 1; step <= 20; ++step) {
    const NodeId c = t.add_child(p);
    CHECK(c != kNoNode);
    t.set_active(p, false);
    t.prune(nullptr);
    CHECK_TRUE(t.append_pose(c, step, Pose2{}));
    t.drain_committed(sink);
    CHECK_TRUE(t.invariants_hold());
    LONGS_EQUAL(1, t.path_entries_used());  // the newest stays for last_pose()
    p = c;
  }
  LONGS_EQUAL(19U, sink.stamps.size());
  for (std::size_t k = 0; k < sink.stamps.size(); ++k) LONGS_EQUAL(static_cast<long>(k + 1), sink.stamps[k]);
  std::int64_t last = 0;
  CHECK_TRUE(t.last_pose(p, &last, nullptr));
  LONGS_EQUAL(20, last);
}

TEST(AncestryTree, a_leaf_root_beside_another_root_keeps_its_poses) {
  // Two roots (two independent lineages, as segments of SDP-SLAM have): neither holds
  // what the other's particles share, so nothing is committed from a leaf root.
  TreeFixture f(8U, 16U);
  AncestryTree& t = f.tree;
  const NodeId a = t.create_root();
  const NodeId b = t.create_root();
  for (int i = 1; i <= 3; ++i) {
    t.append_pose(a, i, Pose2{});
    t.append_pose(b, 10 + i, Pose2{});
  }
  Collector sink;
  LONGS_EQUAL(0, t.drain_committed(sink));
  LONGS_EQUAL(3, t.pose_count(a));
  // An inactive sole root with one child is not a lineage of its own either.
  TreeFixture g(8U, 16U);
  AncestryTree& u = g.tree;
  const NodeId r = u.create_root();
  for (int i = 1; i <= 3; ++i) u.append_pose(r, i, Pose2{});
  u.add_child(r);
  u.set_active(r, false);
  LONGS_EQUAL(0, u.drain_committed(sink));
}

TEST(AncestryTree, empty_tree_after_everything_dies) {
  TreeFixture f(8U, 8U);
  AncestryTree& t = f.tree;
  const NodeId r = t.create_root();
  t.add_child(r);
  t.set_active(r, false);
  t.set_active(t.first_child(r), false);
  t.prune(nullptr);
  LONGS_EQUAL(0, t.size());
  LONGS_EQUAL(kNoNode, t.first_root());
  CHECK_TRUE(t.invariants_hold());
  CHECK(t.create_root() != kNoNode);
  CHECK_TRUE(t.invariants_hold());
}

// Resampling with random parents, thousands of generations: invariants after every
// operation, the 2N−1 bound after every prune, the 3N pool never exhausted, and
// ancestor queries equal to a parent walk.
static void run_random_resampling(std::uint32_t n, std::uint32_t generations, std::uint64_t seed) {
  TreeFixture f(AncestryTree::node_capacity_for(n), 4U);
  AncestryTree& t = f.tree;
  sdpslam::test::SplitMix64 rng(seed);
  std::vector<NodeId> particles{t.create_root()};
  std::vector<NodeId> next;
  for (std::uint32_t g = 0; g < generations; ++g) {
    next.clear();
    // Skewed draws: a few parents get many children, many get none.
    const std::uint32_t favourites = 1U + rng.below(static_cast<std::uint32_t>(particles.size()));
    for (std::uint32_t i = 0; i < n; ++i) {
      const std::uint32_t k = (rng.below(4U) == 0U) ? rng.below(static_cast<std::uint32_t>(particles.size()))
                                                      : rng.below(favourites);
      const NodeId c = t.add_child(particles[k]);
      CHECK(c != kNoNode);
      next.push_back(c);
      CHECK_TRUE(t.invariants_hold());
    }
    for (NodeId p : particles) {
      t.set_active(p, false);
      CHECK_TRUE(t.invariants_hold());
    }
    t.prune(nullptr);
    CHECK_TRUE(t.invariants_hold());
    CHECK(t.size() <= 2U * n - 1U);
    particles.swap(next);
    if (g % 97U == 0U) {
      for (int q = 0; q < 50; ++q) {
        const NodeId a = particles[rng.below(n)];
        NodeId d = particles[rng.below(n)];
        for (std::uint32_t up = rng.below(4U); up > 0U && t.parent(d) != kNoNode; --up) d = t.parent(d);
        CHECK_EQUAL(naive_is_ancestor_or_self(t, d, a), t.is_ancestor_or_self(d, a));
        CHECK_EQUAL(naive_is_ancestor_or_self(t, a, d), t.is_ancestor_or_self(a, d));
      }
    }
  }
  LONGS_EQUAL(0, t.node_oom_count());
  CHECK(t.peak_used() <= 3U * n);
  LONGS_EQUAL(n, t.active_count());
}

TEST(AncestryTree, random_resampling_keeps_invariants_and_size_bound_small_population) {
  run_random_resampling(5U, 4000U, 1U);
}

TEST(AncestryTree, random_resampling_keeps_invariants_and_size_bound_large_population) {
  run_random_resampling(40U, 1500U, 2U);
}
