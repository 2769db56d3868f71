// Distributed particle map (paper §II-A): geometry, views through the ancestry tree,
// merge/remove hooks, exhaustion and misuse, extraction.
#include <CppUTest/TestHarness.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <map>
#include <utility>

#include "dp_fixture.h"
#include "sdpslam/core/bottom/dp_map.h"
#include "sdpslam/core/bottom/view_cache.h"
#include "test_rng.h"

using sdpslam::CellObservation;
using sdpslam::DpMap;
using sdpslam::kNoNode;
using sdpslam::NodeId;
using sdpslam::test::DpFixture;
using sdpslam::test::small_options;

namespace {
CellObservation obs(std::uint16_t h, std::uint16_t m) { return CellObservation{h, m}; }
bool view_is(const DpMap& map, NodeId p, std::int32_t ix, std::int32_t iy, CellObservation expect) {
  CellObservation v;
  return map.lookup(p, ix, iy, &v) && v == expect;
}
}  // namespace

TEST_GROUP(DpMap){};

TEST(DpMap, invalid_options_are_refused) {
  DpMap::Options o = small_options(4U, 4U);
  CHECK_TRUE(DpMap::options_valid(o));
  o.resolution_m = 0.0;
  CHECK_FALSE(DpMap::options_valid(o));
  LONGS_EQUAL(0U, DpMap::required_arena_bytes(o, 8U));
  o = small_options(0U, 4U);
  CHECK_FALSE(DpMap::options_valid(o));
  o = small_options(4U, 0U);
  CHECK_FALSE(DpMap::options_valid(o));
  o = small_options(4U, 4U);
  o.width_m = -1.0;
  CHECK_FALSE(DpMap::options_valid(o));
  o = small_options(4U, 4U);
  o.origin_x_m = std::numeric_limits<double>::quiet_NaN();
  CHECK_FALSE(DpMap::options_valid(o));
  o = small_options(4U, 4U);
  o.width_m = 1e9;  // 2e10 cells per axis
  CHECK_FALSE(DpMap::options_valid(o));
}

TEST(DpMap, init_refuses_a_too_small_arena_and_then_refuses_updates) {
  std::vector<unsigned char> buf(sdpslam::AncestryTree::required_arena_bytes(8U, 8U) + 100U);
  sdpslam::Arena arena(buf.data(), buf.size());
  sdpslam::AncestryTree tree;
  CHECK_TRUE(tree.init(arena, 8U, 8U));
  DpMap map;
  CHECK_FALSE(map.init(arena, small_options(4U, 64U), tree));
  const NodeId r = tree.create_root();
  CHECK_FALSE(map.update(r, 0, 0, obs(1, 0)));
  CellObservation v;
  CHECK_FALSE(map.lookup(r, 0, 0, &v));
  CHECK_TRUE(map.invariants_hold());
}

TEST(DpMap, grid_covers_the_area_in_whole_cells) {
  DpFixture f(8U, 8U, small_options(4U, 16U));
  LONGS_EQUAL(48, f.map.width_cells());
  LONGS_EQUAL(40, f.map.height_cells());
}

TEST(DpMap, world_to_cell_floors_and_rejects_outside_and_nan) {
  DpFixture f(8U, 8U, small_options(4U, 16U));
  std::int32_t ix = -7;
  std::int32_t iy = -7;
  CHECK_TRUE(f.map.world_to_cell(-1.0, 2.0, &ix, &iy));
  LONGS_EQUAL(0, ix);
  LONGS_EQUAL(0, iy);
  CHECK_TRUE(f.map.world_to_cell(-0.951, 2.049, &ix, &iy));
  LONGS_EQUAL(0, ix);
  LONGS_EQUAL(0, iy);
  CHECK_TRUE(f.map.world_to_cell(1.399, 3.999, &ix, &iy));
  LONGS_EQUAL(47, ix);
  LONGS_EQUAL(39, iy);
  ix = iy = -7;
  CHECK_FALSE(f.map.world_to_cell(-1.001, 2.5, &ix, &iy));
  CHECK_FALSE(f.map.world_to_cell(1.401, 2.5, &ix, &iy));
  CHECK_FALSE(f.map.world_to_cell(0.0, 4.001, &ix, &iy));
  CHECK_FALSE(f.map.world_to_cell(std::nan(""), 2.5, &ix, &iy));
  LONGS_EQUAL(-7, ix);  // outputs untouched on failure
  double x = 0.0;
  double y = 0.0;
  f.map.cell_center(0, 39, &x, &y);
  DOUBLES_EQUAL(-0.975, x, 1e-12);
  DOUBLES_EQUAL(3.975, y, 1e-12);
}

TEST(DpMap, rect_around_covers_a_padded_box_clipped_or_cropped) {
  DpFixture f(8U, 8U, small_options(4U, 16U));
  // [-0.51, 0.01] x [2.49, 3.01] grown by 0.1 m: cells 7..22 on both axes.
  sdpslam::CellRect r = f.map.rect_around(-0.51, 2.49, 0.01, 3.01, 0.1);
  LONGS_EQUAL(7, r.ix0);
  LONGS_EQUAL(7, r.iy0);
  LONGS_EQUAL(16U, r.width);
  LONGS_EQUAL(16U, r.height);
  // Clipped to the map without wrap.
  r = f.map.rect_around(-2.0, 1.0, 5.0, 9.0, 0.0);
  LONGS_EQUAL(0, r.ix0);
  LONGS_EQUAL(0, r.iy0);
  LONGS_EQUAL(48U, r.width);
  LONGS_EQUAL(40U, r.height);
  // An empty box gives an empty rectangle.
  LONGS_EQUAL(0U, f.map.rect_around(1.0, 3.0, 0.0, 3.5, 0.1).width);
  // With wrap: no edge, but at most half the window on each axis, about the centre.
  DpMap::Options o = small_options(4U, 16U);
  o.wrap = true;
  DpFixture w(8U, 8U, o);
  const std::int32_t half_w = w.map.width_cells() / 2;
  const std::int32_t half_h = w.map.height_cells() / 2;
  r = w.map.rect_around(-0.99, 2.01, 2.99, 6.01, 0.0);  // cells 0..79 on both axes
  LONGS_EQUAL((80 - half_w) / 2, r.ix0);
  LONGS_EQUAL(half_w, static_cast<std::int32_t>(r.width));
  LONGS_EQUAL((80 - half_h) / 2, r.iy0);
  LONGS_EQUAL(half_h, static_cast<std::int32_t>(r.height));
  CHECK(half_w < 80 && half_h < 80);
}

TEST(DpMap, accumulate_adds_and_halves_both_counts_on_saturation) {
  CHECK_TRUE(obs(3, 4) == sdpslam::accumulate(obs(1, 1), 2, 3));
  const CellObservation s = sdpslam::accumulate(obs(65530, 100), 10, 1);
  LONGS_EQUAL(32770, s.hits);  // 65540 / 2
  LONGS_EQUAL(50, s.misses);   // 101 / 2
  const CellObservation z = sdpslam::accumulate(obs(65535, 65535), 65535, 65535);
  CHECK(z.hits < 65535 && z.misses < 65535);
  CHECK_TRUE(z.hits == z.misses);
}

TEST(DpMap, a_child_sees_its_ancestors_observations_and_shadows_them) {
  DpFixture f(16U, 8U, small_options(4U, 64U));
  auto& t = f.tree;
  auto& m = f.map;
  const NodeId r = t.create_root();
  CHECK_TRUE(m.update(r, 5, 5, obs(1, 0)));
  const NodeId a = t.add_child(r);
  const NodeId b = t.add_child(r);
  CHECK_TRUE(view_is(m, a, 5, 5, obs(1, 0)));
  CHECK_TRUE(m.update(a, 5, 5, obs(2, 0)));
  CHECK_TRUE(view_is(m, a, 5, 5, obs(2, 0)));
  CHECK_TRUE(view_is(m, b, 5, 5, obs(1, 0)));
  CHECK_TRUE(view_is(m, r, 5, 5, obs(1, 0)));
  const NodeId a1 = t.add_child(a);
  CHECK_TRUE(view_is(m, a1, 5, 5, obs(2, 0)));  // nearest ancestor wins
  CellObservation v;
  CHECK_FALSE(m.lookup(a1, 6, 5, &v));
  CHECK_TRUE(m.invariants_hold());
}

TEST(DpMap, update_in_place_uses_no_new_entry) {
  DpFixture f(8U, 8U, small_options(4U, 2U));
  const NodeId r = f.tree.create_root();
  CHECK_TRUE(f.map.update(r, 1, 1, obs(1, 0)));
  CHECK_TRUE(f.map.update(r, 1, 1, obs(5, 1)));
  CHECK_TRUE(f.map.add(r, 1, 1, 1, 1));
  LONGS_EQUAL(1, f.map.observations_used());
  CHECK_TRUE(view_is(f.map, r, 1, 1, obs(6, 2)));
}

TEST(DpMap, add_starts_from_the_inherited_view) {
  DpFixture f(8U, 8U, small_options(4U, 8U));
  const NodeId r = f.tree.create_root();
  CHECK_TRUE(f.map.add(r, 2, 3, 4, 1));
  const NodeId c = f.tree.add_child(r);
  CHECK_TRUE(f.map.add(c, 2, 3, 1, 0));
  CHECK_TRUE(view_is(f.map, c, 2, 3, obs(5, 1)));
  CHECK_TRUE(view_is(f.map, r, 2, 3, obs(4, 1)));
}

TEST(DpMap, removing_a_node_frees_its_observations_and_empty_tiles) {
  DpFixture f(8U, 8U, small_options(9U, 64U));
  auto& t = f.tree;
  const NodeId r = t.create_root();
  const NodeId a = t.add_child(r);
  const NodeId b = t.add_child(r);
  CHECK_TRUE(f.map.update(a, 0, 0, obs(1, 0)));
  CHECK_TRUE(f.map.update(a, 40, 30, obs(1, 0)));
  CHECK_TRUE(f.map.update(b, 0, 0, obs(0, 1)));
  LONGS_EQUAL(2, f.map.tiles_used());
  t.set_active(a, false);
  t.prune(&f.map);
  CHECK_TRUE(f.map.invariants_hold());
  LONGS_EQUAL(1, f.map.observations_used());
  LONGS_EQUAL(1, f.map.tiles_used());
  LONGS_EQUAL(2, f.map.tiles_peak());
  CHECK_TRUE(view_is(f.map, b, 0, 0, obs(0, 1)));
}

// A chain folded by prune leaves a root that owns its whole view: popping it hands every
// known cell out once, with the view's value, frees each observation and empty tile as
// it goes, and what the node still owns (its view) is exactly what was not popped.
TEST(DpMap, popping_a_root_hands_out_its_whole_view_once_and_frees_it) {
  DpFixture f(8U, 8U, small_options(9U, 64U));
  auto& t = f.tree;
  const NodeId r = t.create_root();
  CHECK_TRUE(f.map.update(r, 0, 0, obs(1, 1)));
  CHECK_TRUE(f.map.update(r, 5, 7, obs(2, 0)));
  const NodeId a = t.add_child(r);
  CHECK_TRUE(f.map.update(a, 0, 0, obs(3, 4)));    // shadows r's
  CHECK_TRUE(f.map.update(a, 40, 30, obs(0, 9)));  // another tile
  const NodeId other = t.create_root();           // another tree: untouched
  CHECK_TRUE(f.map.update(other, 5, 7, obs(7, 7)));
  t.set_active(r, false);
  t.prune(&f.map);  // r folds into a
  LONGS_EQUAL(kNoNode, t.parent(a));
  LONGS_EQUAL(3, f.map.observation_count(a));
  LONGS_EQUAL(2, f.map.tiles_used());  // (0,0) and (5,7) share one
  std::vector<CellObservation> want{obs(3, 4), obs(2, 0), obs(0, 9)};  // (0,0) (5,7) (40,30)
  std::vector<int> seen(3, 0);
  std::int32_t ix = 0;
  std::int32_t iy = 0;
  CellObservation v;
  for (std::uint32_t left = 3U; left > 0U; --left) {
    CHECK_TRUE(f.map.pop_observation(a, &ix, &iy, &v));
    const int k = (ix == 0 && iy == 0) ? 0 : (ix == 5 && iy == 7) ? 1 : (ix == 40 && iy == 30) ? 2 : -1;
    CHECK_TRUE(k >= 0);
    CHECK_TRUE(v == want[static_cast<std::size_t>(k)]);
    ++seen[static_cast<std::size_t>(k)];
    CellObservation still;
    CHECK_FALSE(f.map.lookup(a, ix, iy, &still));  // gone from the view
    LONGS_EQUAL(left - 1U, f.map.observation_count(a));
    CHECK_TRUE(f.map.invariants_hold());
  }
  CHECK_TRUE(seen == std::vector<int>(3, 1));
  CHECK_FALSE(f.map.pop_observation(a, &ix, &iy, &v));
  LONGS_EQUAL(1, f.map.observations_used());  // the other tree's
  LONGS_EQUAL(1, f.map.tiles_used());
  CHECK_TRUE(view_is(f.map, other, 5, 7, obs(7, 7)));
  // A dead node is misuse, counted; the node itself stays live and writable.
  const std::uint32_t misuse = f.map.misuse_count();
  CHECK_FALSE(f.map.pop_observation(static_cast<NodeId>(7U), &ix, &iy, &v));
  LONGS_EQUAL(misuse + 1U, f.map.misuse_count());
  CHECK_TRUE(f.map.update(a, 1, 1, obs(1, 0)));
  CHECK_TRUE(f.map.invariants_hold());
}

TEST(DpMap, merge_relabels_to_the_child_except_where_the_child_is_newer) {
  DpFixture f(8U, 8U, small_options(4U, 64U));
  auto& t = f.tree;
  const NodeId r = t.create_root();
  const NodeId p = t.add_child(r);
  const NodeId q = t.add_child(r);
  CHECK_TRUE(f.map.update(p, 1, 1, obs(1, 0)));
  CHECK_TRUE(f.map.update(p, 2, 2, obs(2, 0)));
  const NodeId c = t.add_child(p);
  CHECK_TRUE(f.map.update(c, 2, 2, obs(9, 9)));
  t.set_active(p, false);
  t.prune(&f.map);  // p has one child: merged into c
  CHECK_TRUE(f.map.invariants_hold());
  CHECK_FALSE(t.contains(p));
  LONGS_EQUAL(2, f.map.observation_count(c));
  LONGS_EQUAL(2, f.map.observations_used());
  LONGS_EQUAL(1, f.map.entries_in_cell(2, 2));
  CHECK_TRUE(view_is(f.map, c, 1, 1, obs(1, 0)));
  CHECK_TRUE(view_is(f.map, c, 2, 2, obs(9, 9)));
  CellObservation v;
  CHECK_FALSE(f.map.lookup(q, 1, 1, &v));
}

// A parent with more observations than its only child keeps its entries: the child's
// are moved into them (the child's newer value wins where both have one) and the
// result belongs to the child. Views, counts and the cell order must be as if the
// parent's had been relabelled.
TEST(DpMap, merge_into_a_smaller_child_moves_the_childs_side_and_keeps_its_values) {
  DpFixture f(8U, 8U, small_options(4U, 64U));
  auto& t = f.tree;
  const NodeId r = t.create_root();
  const NodeId p = t.add_child(r);
  const NodeId q = t.add_child(r);
  CHECK_TRUE(f.map.update(r, 3, 3, obs(5, 5)));
  for (std::int32_t i = 0; i < 4; ++i) CHECK_TRUE(f.map.update(p, i, 0, obs(1, static_cast<std::uint16_t>(i))));
  const NodeId c = t.add_child(p);
  CHECK_TRUE(f.map.update(c, 1, 0, obs(9, 9)));  // shadows p's
  CHECK_TRUE(f.map.update(c, 3, 3, obs(7, 7)));  // shadows r's
  LONGS_EQUAL(2, f.map.entries_in_cell(1, 0));
  t.set_active(p, false);
  t.prune(&f.map);
  CHECK_TRUE(f.map.invariants_hold());
  CHECK_FALSE(t.contains(p));
  LONGS_EQUAL(0, f.map.observation_count(p));
  LONGS_EQUAL(5, f.map.observation_count(c));
  LONGS_EQUAL(6, f.map.observations_used());
  LONGS_EQUAL(1, f.map.entries_in_cell(1, 0));
  LONGS_EQUAL(2, f.map.entries_in_cell(3, 3));
  CHECK_TRUE(view_is(f.map, c, 0, 0, obs(1, 0)));
  CHECK_TRUE(view_is(f.map, c, 1, 0, obs(9, 9)));
  CHECK_TRUE(view_is(f.map, c, 2, 0, obs(1, 2)));
  CHECK_TRUE(view_is(f.map, c, 3, 3, obs(7, 7)));
  CHECK_TRUE(view_is(f.map, q, 3, 3, obs(5, 5)));
  CellObservation v;
  CHECK_FALSE(f.map.lookup(q, 0, 0, &v));
  // The merged node is an ancestor now: its descendants still shadow it, and a later
  // write by it lands behind theirs (the order lookups rely on).
  const NodeId d = t.add_child(c);
  CHECK_TRUE(f.map.update(d, 2, 0, obs(4, 4)));
  CHECK_TRUE(f.map.update(c, 2, 0, obs(6, 6)));
  CHECK_TRUE(f.map.update(d, 5, 5, obs(4, 5)));
  CHECK_TRUE(f.map.update(c, 5, 5, obs(8, 8)));  // a new entry of an inner node
  CHECK_TRUE(f.map.invariants_hold());
  CHECK_TRUE(view_is(f.map, d, 2, 0, obs(4, 4)));
  CHECK_TRUE(view_is(f.map, c, 2, 0, obs(6, 6)));
  CHECK_TRUE(view_is(f.map, d, 5, 5, obs(4, 5)));
  CHECK_TRUE(view_is(f.map, c, 5, 5, obs(8, 8)));
  CHECK_TRUE(view_is(f.map, d, 3, 3, obs(7, 7)));
  LONGS_EQUAL(6, f.map.observation_count(c));
  // Removing the merged node frees everything it owns, whichever side it came from.
  t.set_active(c, false);
  t.set_active(d, false);
  t.set_active(q, false);
  t.set_active(r, false);
  t.prune(&f.map);
  CHECK_TRUE(f.map.invariants_hold());
  LONGS_EQUAL(0, f.map.observations_used());
  LONGS_EQUAL(0, f.map.tiles_used());
}

TEST(DpMap, merge_into_a_larger_child_moves_the_parents_side) {
  DpFixture f(8U, 8U, small_options(4U, 64U));
  auto& t = f.tree;
  const NodeId r = t.create_root();
  const NodeId p = t.add_child(r);
  const NodeId q = t.add_child(r);
  CHECK_TRUE(f.map.update(p, 0, 0, obs(1, 1)));
  CHECK_TRUE(f.map.update(p, 20, 20, obs(2, 2)));  // a tile of its own
  const NodeId c = t.add_child(p);
  for (std::int32_t i = 0; i < 4; ++i) CHECK_TRUE(f.map.update(c, i, 1, obs(3, static_cast<std::uint16_t>(i))));
  CHECK_TRUE(f.map.update(c, 0, 0, obs(9, 9)));
  t.set_active(p, false);
  t.prune(&f.map);
  CHECK_TRUE(f.map.invariants_hold());
  LONGS_EQUAL(6, f.map.observation_count(c));
  LONGS_EQUAL(6, f.map.observations_used());
  LONGS_EQUAL(2, f.map.tiles_used());
  LONGS_EQUAL(1, f.map.entries_in_cell(0, 0));
  CHECK_TRUE(view_is(f.map, c, 0, 0, obs(9, 9)));
  CHECK_TRUE(view_is(f.map, c, 20, 20, obs(2, 2)));
  CHECK_TRUE(view_is(f.map, c, 3, 1, obs(3, 3)));
  CellObservation v;
  CHECK_FALSE(f.map.lookup(q, 20, 20, &v));
}

// A single lineage that merges every generation (one fresh child per step, the filter's
// common case) keeps exactly one owner's worth of entries: views stay exact and no
// storage leaks however long the chain.
TEST(DpMap, a_long_chain_of_merges_keeps_views_and_storage_exact) {
  DpFixture f(6U, 8U, small_options(4U, 64U));
  auto& t = f.tree;
  NodeId cur = t.create_root();
  for (std::uint16_t g = 0; g < 200U; ++g) {
    const NodeId next = t.add_child(cur);
    CHECK(next != kNoNode);
    const std::int32_t ix = static_cast<std::int32_t>(g % 10U);
    CHECK_TRUE(f.map.update(next, ix, 0, obs(g, 1)));
    if (g % 3U == 0U) CHECK_TRUE(f.map.update(next, 30, 30, obs(g, 2)));
    t.set_active(cur, false);
    t.prune(&f.map);
    CHECK_TRUE(f.map.invariants_hold());
    cur = next;
    const std::uint32_t distinct = (g + 1U < 10U ? g + 1U : 10U) + 1U;
    LONGS_EQUAL(distinct, f.map.observations_used());
    LONGS_EQUAL(distinct, f.map.observation_count(cur));
    CHECK_TRUE(view_is(f.map, cur, ix, 0, obs(g, 1)));
  }
  CHECK_TRUE(view_is(f.map, cur, 30, 30, obs(198, 2)));
  CHECK_TRUE(view_is(f.map, cur, 0, 0, obs(190, 1)));
}

TEST(DpMap, observation_exhaustion_is_counted_and_leaves_views_unchanged) {
  DpFixture f(8U, 8U, small_options(4U, 3U));
  auto& t = f.tree;
  const NodeId r = t.create_root();
  CHECK_TRUE(f.map.update(r, 0, 0, obs(1, 0)));
  CHECK_TRUE(f.map.update(r, 1, 0, obs(2, 0)));
  CHECK_TRUE(f.map.update(r, 2, 0, obs(3, 0)));
  const NodeId c = t.add_child(r);
  CHECK_FALSE(f.map.update(c, 0, 0, obs(7, 7)));
  CHECK_FALSE(f.map.update(c, 3, 0, obs(7, 7)));
  LONGS_EQUAL(2, f.map.observation_oom_count());
  CHECK_TRUE(f.map.invariants_hold());
  CHECK_TRUE(view_is(f.map, c, 0, 0, obs(1, 0)));  // still the inherited value
  CellObservation v;
  CHECK_FALSE(f.map.lookup(c, 3, 0, &v));
  CHECK_TRUE(f.map.update(r, 2, 0, obs(4, 0)));  // in place still works
  CHECK_TRUE(view_is(f.map, c, 2, 0, obs(4, 0)));
}

// add_run() walks a run's cell lists side by side; the map must end exactly as with one
// add() per cell in the same order: every arena byte (the same slots, links and values),
// the same refusals and counters. On a bounded map, with runs that leave it, runs longer
// than kMaxRun, and pools that run out; in a view (the side-by-side walk) and outside
// one (one add() after the other).
TEST(DpMap, add_run_ends_exactly_as_one_add_per_cell_in_order) {
  for (std::uint32_t variant = 0U; variant < 4U; ++variant) {
    const bool in_view = (variant & 1U) != 0U;
    const bool short_pools = (variant & 2U) != 0U;
    DpMap::Options o = small_options(short_pools ? 4U : 9U, short_pools ? 400U : 6000U);
    o.owner_cell_index = false;  // views are taken without the index
    DpFixture a(64U, 64U, o);
    DpFixture b(64U, 64U, o);
    sdpslam::test::SplitMix64 rng(17U + variant);
    std::vector<NodeId> current{a.tree.create_root()};
    LONGS_EQUAL(current[0], b.tree.create_root());
    std::uint32_t refused = 0U;
    std::uint32_t long_runs = 0U;
    NodeId old = kNoNode;  // from generation 20 on, a particle of the older of two trees
    for (std::uint32_t g = 0U; g < 40U; ++g) {
      if (g == 20U) {  // a new tree (SDP-SLAM's next segment) while the old one still writes
        old = current[0];
        for (std::size_t k = 1U; k < current.size(); ++k) {
          a.tree.set_active(current[k], false);
          b.tree.set_active(current[k], false);
        }
        const NodeId root = a.tree.create_root();
        LONGS_EQUAL(root, b.tree.create_root());
        current.assign(1U, root);
      }
      std::vector<NodeId> next;
      for (std::uint32_t k = 0U; k < 6U; ++k) {
        const NodeId parent = current[rng.below(static_cast<std::uint32_t>(current.size()))];
        const NodeId c = a.tree.add_child(parent);
        LONGS_EQUAL(c, b.tree.add_child(parent));
        next.push_back(c);
      }
      for (NodeId p : current) {
        a.tree.set_active(p, false);
        b.tree.set_active(p, false);
      }
      a.tree.prune(&a.map);
      b.tree.prune(&b.map);
      current.swap(next);
      std::vector<NodeId> writers = current;
      if (old != kNoNode) writers.push_back(old);
      for (NodeId p : writers) {
        if (in_view) {
          a.map.begin_view(p);
          b.map.begin_view(p);
        }
        for (std::uint32_t r = 0U; r < 3U; ++r) {
          // A straight run of distinct cells from a random start, partly outside the map.
          const std::uint32_t n = 1U + rng.below(2U * DpMap::kMaxRun);
          if (n > DpMap::kMaxRun) ++long_runs;
          std::int32_t dx = static_cast<std::int32_t>(rng.below(3U)) - 1;
          const std::int32_t dy = static_cast<std::int32_t>(rng.below(3U)) - 1;
          if (dx == 0 && dy == 0) dx = 1;
          const std::int32_t x0 = static_cast<std::int32_t>(rng.below(56U)) - 4;
          const std::int32_t y0 = static_cast<std::int32_t>(rng.below(48U)) - 4;
          std::vector<DpMap::CellAdd> run(n);
          std::uint32_t expected = 0U;
          for (std::uint32_t i = 0U; i < n; ++i) {
            const auto k = static_cast<std::int32_t>(i);
            run[i] = DpMap::CellAdd{x0 + k * dx, y0 + k * dy, static_cast<std::uint16_t>(rng.below(3U)),
                                    static_cast<std::uint16_t>(rng.below(3U))};
            if (!a.map.add(p, run[i].ix, run[i].iy, run[i].hits, run[i].misses)) {
              expected += static_cast<std::uint32_t>(run[i].hits) + run[i].misses;
              ++refused;
            }
          }
          LONGS_EQUAL(expected, b.map.add_run(p, run.data(), n));
        }
        a.map.end_view();
        b.map.end_view();
      }
      CHECK_TRUE(a.buffer == b.buffer);
      CHECK_TRUE(b.map.invariants_hold());
      LONGS_EQUAL(a.map.observations_used(), b.map.observations_used());
      LONGS_EQUAL(a.map.observations_peak(), b.map.observations_peak());
      LONGS_EQUAL(a.map.tiles_used(), b.map.tiles_used());
      LONGS_EQUAL(a.map.observation_oom_count(), b.map.observation_oom_count());
      LONGS_EQUAL(a.map.tile_oom_count(), b.map.tile_oom_count());
      LONGS_EQUAL(a.map.out_of_bounds_count(), b.map.out_of_bounds_count());
      LONGS_EQUAL(a.map.observations_requested(), b.map.observations_requested());
    }
    CHECK(long_runs > 0U);
    CHECK(a.map.out_of_bounds_count() > 0U);
    if (short_pools) CHECK(a.map.observation_oom_count() + a.map.tile_oom_count() > 0U);
    CHECK(refused > a.map.out_of_bounds_count() || !short_pools);
  }
}

TEST(DpMap, tile_exhaustion_is_counted_and_existing_tiles_still_accept) {
  DpFixture f(8U, 8U, small_options(1U, 64U));
  const NodeId r = f.tree.create_root();
  CHECK_TRUE(f.map.update(r, 0, 0, obs(1, 0)));
  CHECK_FALSE(f.map.update(r, 16, 0, obs(1, 0)));  // next tile
  LONGS_EQUAL(1, f.map.tile_oom_count());
  LONGS_EQUAL(0, f.map.observation_oom_count());
  LONGS_EQUAL(1, f.map.observations_used());
  CHECK_TRUE(f.map.update(r, 15, 15, obs(1, 0)));  // same tile
  CHECK_TRUE(f.map.invariants_hold());
}

TEST(DpMap, out_of_bounds_and_dead_particles_are_refused_and_counted) {
  DpFixture f(8U, 8U, small_options(4U, 64U));
  const NodeId r = f.tree.create_root();
  CHECK_FALSE(f.map.update(r, -1, 0, obs(1, 0)));
  CHECK_FALSE(f.map.update(r, 48, 0, obs(1, 0)));
  CHECK_FALSE(f.map.update(r, 0, 40, obs(1, 0)));
  LONGS_EQUAL(3, f.map.out_of_bounds_count());
  CHECK_FALSE(f.map.update(5U, 0, 0, obs(1, 0)));
  CHECK_FALSE(f.map.update(kNoNode, 0, 0, obs(1, 0)));
  LONGS_EQUAL(2, f.map.misuse_count());
  CellObservation v;
  CHECK_FALSE(f.map.lookup(r, 48, 0, &v));
  CHECK_FALSE(f.map.lookup(kNoNode, 0, 0, &v));
  LONGS_EQUAL(0, f.map.observations_used());
  CHECK_TRUE(f.map.invariants_hold());
}

TEST(DpMap, extraction_matches_lookup_and_touched_bounds_cover_written_tiles) {
  DpFixture f(8U, 8U, small_options(9U, 64U));
  auto& t = f.tree;
  const NodeId r = t.create_root();
  CHECK_FALSE(f.map.touched_bounds(nullptr));
  CHECK_TRUE(f.map.update(r, 17, 3, obs(1, 2)));
  const NodeId c = t.add_child(r);
  CHECK_TRUE(f.map.update(c, 47, 39, obs(3, 4)));
  sdpslam::CellRect b;
  CHECK_TRUE(f.map.touched_bounds(&b));
  LONGS_EQUAL(16, b.ix0);
  LONGS_EQUAL(0, b.iy0);
  LONGS_EQUAL(32U, b.width);   // tiles 1..2 clipped to 48 cells
  LONGS_EQUAL(40U, b.height);  // tiles 0..2 clipped to 40 cells
  std::vector<std::int32_t> seen;
  f.map.for_each_known_cell(c, [&](std::int32_t ix, std::int32_t iy, const CellObservation& v) {
    seen.push_back(ix);
    seen.push_back(iy);
    seen.push_back(v.hits);
  });
  const std::vector<std::int32_t> expect{17, 3, 1, 47, 39, 3};
  CHECK_TRUE(expect == seen);
  sdpslam::CellRect rect{46, 38, 4, 3};  // partly outside the map
  std::vector<CellObservation> values(12);
  std::vector<std::uint8_t> known(12, 9);
  LONGS_EQUAL(1, f.map.fill_rect(c, rect, values.data(), known.data()));
  LONGS_EQUAL(1, known[1 * 4 + 1]);
  CHECK_TRUE(values[1 * 4 + 1] == obs(3, 4));
  LONGS_EQUAL(0, known[0]);
  LONGS_EQUAL(0, known[11]);
  LONGS_EQUAL(0, f.map.fill_rect(r, rect, values.data(), known.data()));
}

TEST(DpMap, footprint_reports_the_fixed_storage) {
  DpFixture f(8U, 8U, small_options(4U, 100U));
  CHECK(f.map.footprint_bytes() >= 100U * 20U + 4U * 1024U + 9U * 4U);
}

TEST(DpMap, an_observation_slot_costs_its_entry_alone_and_freed_slots_are_reused) {
  // Without the index, 100 more observations cost exactly 100 entries: no per-slot
  // bookkeeping beside them, in the arena or in the footprint.
  DpMap::Options small = small_options(9U, 100U);
  small.owner_cell_index = false;
  DpMap::Options big = small;
  big.observation_capacity = 200U;
  LONGS_EQUAL(100U * DpMap::kObservationBytes,
              DpMap::required_arena_bytes(big, 8U) - DpMap::required_arena_bytes(small, 8U));
  DpFixture fs(8U, 8U, small);
  DpFixture fb(8U, 8U, big);
  LONGS_EQUAL(100U * DpMap::kObservationBytes, fb.map.footprint_bytes() - fs.map.footprint_bytes());
  // Fill the pool, free it, fill it again: every slot comes back, the peak stays.
  DpFixture f(8U, 8U, small);
  auto& t = f.tree;
  for (int round = 0; round < 2; ++round) {
    const NodeId r = t.create_root();
    for (std::int32_t i = 0; i < 100; ++i) CHECK_TRUE(f.map.update(r, i % 48, i / 48, obs(1, 0)));
    CHECK_FALSE(f.map.update(r, 47, 39, obs(1, 0)));
    LONGS_EQUAL(100U, f.map.observations_used());
    LONGS_EQUAL(100U, f.map.observations_peak());
    LONGS_EQUAL(round + 1, f.map.observation_oom_count());
    CHECK_TRUE(f.map.invariants_hold());
    // Free half by popping, then the rest with the node.
    std::int32_t ix;
    std::int32_t iy;
    CellObservation v;
    for (int k = 0; k < 50; ++k) CHECK_TRUE(f.map.pop_observation(r, &ix, &iy, &v));
    LONGS_EQUAL(50U, f.map.observations_used());
    CHECK_TRUE(f.map.invariants_hold());
    t.set_active(r, false);
    t.prune(&f.map);
    LONGS_EQUAL(0U, f.map.observations_used());
    CHECK_TRUE(f.map.invariants_hold());
  }
}

TEST(DpMap, views_stay_exact_across_a_forest_when_an_older_tree_is_written_after_newer_ones) {
  // SDP-SLAM's case: every segment is a new tree, and the global map's root (an older
  // tree) keeps being written. Lookups skip newer trees and stop at older ones.
  DpFixture f(16U, 16U, small_options(9U, 64U));
  const NodeId r1 = f.tree.create_root();
  const NodeId a1 = f.tree.add_child(r1);
  const NodeId b1 = f.tree.add_child(r1);
  CHECK_TRUE(f.map.update(r1, 5, 5, obs(1, 0)));
  const NodeId r2 = f.tree.create_root();
  CHECK_TRUE(f.map.update(r2, 5, 5, obs(2, 0)));
  const NodeId c2 = f.tree.add_child(r2);
  const NodeId d2 = f.tree.add_child(r2);
  CHECK_TRUE(f.map.update(c2, 5, 5, obs(3, 0)));
  CHECK_TRUE(f.map.update(a1, 5, 5, obs(4, 0)));   // older tree, written last
  CHECK_TRUE(f.map.add(b1, 5, 5, 0U, 2U));         // its view (r1's) plus two misses
  const NodeId r3 = f.tree.create_root();
  LONGS_EQUAL(1, f.tree.tree_sequence(a1));
  LONGS_EQUAL(2, f.tree.tree_sequence(d2));
  LONGS_EQUAL(3, f.tree.tree_sequence(r3));
  CHECK_TRUE(view_is(f.map, c2, 5, 5, obs(3, 0)));
  CHECK_TRUE(view_is(f.map, d2, 5, 5, obs(2, 0)));
  CHECK_TRUE(view_is(f.map, a1, 5, 5, obs(4, 0)));
  CHECK_TRUE(view_is(f.map, b1, 5, 5, obs(1, 2)));
  CHECK_TRUE(view_is(f.map, r1, 5, 5, obs(1, 0)));
  CellObservation v;
  CHECK_FALSE(f.map.lookup(r3, 5, 5, &v));
  CHECK_TRUE(f.map.invariants_hold());
  CHECK_TRUE(f.tree.invariants_hold());
}

TEST(DpMap, view_cache_answers_exactly_what_the_map_answers) {
  DpFixture f(16U, 16U, small_options(9U, 64U));
  const NodeId root = f.tree.create_root();
  for (std::int32_t i = 0; i < 6; ++i) CHECK_TRUE(f.map.update(root, i, 2, obs(static_cast<std::uint16_t>(i), 1)));
  const NodeId a = f.tree.add_child(root);
  const NodeId b = f.tree.add_child(root);
  CHECK_TRUE(f.map.update(a, 3, 2, obs(9, 9)));
  std::vector<unsigned char> buf(sdpslam::ViewCache::required_arena_bytes(16U));
  sdpslam::Arena arena(buf.data(), buf.size());
  sdpslam::ViewCache cache;
  CHECK_FALSE(cache.init(arena, 12U));  // not a power of two
  CHECK_TRUE(cache.init(arena, 16U));   // holds 12 cells: the rest is read through
  for (const NodeId p : {a, b, a}) {
    cache.begin(f.map, p);
    for (int pass = 0; pass < 2; ++pass) {
      // 8 x 3 cells, some observed, most not, two outside the map (x = -1).
      for (std::int32_t iy = 1; iy <= 3; ++iy) {
        for (std::int32_t ix = -1; ix <= 6; ++ix) {
          CellObservation want{77U, 77U};
          CellObservation got{77U, 77U};
          const bool seen = f.map.lookup(p, ix, iy, &want);
          CHECK_EQUAL(seen, cache.lookup(ix, iy, &got));
          CHECK_TRUE(got == want);
        }
      }
    }
  }
  // 3 bursts x 2 passes x 24 reads; each burst caches 12 cells, answered in its second pass.
  LONGS_EQUAL(3 * 2 * 24, cache.hits() + cache.misses());
  LONGS_EQUAL(3 * 12, cache.hits());
}

// ---- torus (Options::wrap) ---------------------------------------------------------

namespace {
// 2.4 m × 2.0 m asked for: 48 × 40 cells, rounded up to 4 × 4 tiles of 16 = 64 × 64.
DpMap::Options torus_options(std::uint32_t tiles, std::uint32_t observations) {
  DpMap::Options o = small_options(tiles, observations);
  o.wrap = true;
  return o;
}
}  // namespace

TEST(DpMap, a_torus_rounds_each_axis_up_to_a_power_of_two_of_tiles_and_has_no_outside) {
  DpFixture f(8U, 8U, torus_options(8U, 64U));
  CHECK_TRUE(f.map.wraps());
  LONGS_EQUAL(64, f.map.width_cells());
  LONGS_EQUAL(64, f.map.height_cells());
  std::int32_t ix = 0;
  std::int32_t iy = 0;
  // Far outside the asked area, and negative: still a cell, by floor.
  CHECK_TRUE(f.map.world_to_cell(-1.0 - 1000.02, 2.0 + 5000.0, &ix, &iy));
  LONGS_EQUAL(-20001, ix);
  LONGS_EQUAL(100000, iy);
  CHECK_FALSE(f.map.world_to_cell(std::numeric_limits<double>::quiet_NaN(), 0.0, &ix, &iy));
  CHECK_FALSE(f.map.world_to_cell(1.0e12, 0.0, &ix, &iy));  // beyond 2^30 cells
  const NodeId r = f.tree.create_root();
  CHECK_TRUE(f.map.update(r, -20001, 100000, obs(3, 1)));
  CHECK_TRUE(view_is(f.map, r, -20001, 100000, obs(3, 1)));
  LONGS_EQUAL(0U, f.map.out_of_bounds_count());
  CHECK_TRUE(f.map.invariants_hold());
}

TEST(DpMap, on_a_torus_cells_a_window_apart_share_storage_but_lineages_keep_their_views) {
  DpFixture f(8U, 8U, torus_options(8U, 64U));
  const NodeId a = f.tree.create_root();  // one segment's lineage ...
  const NodeId b = f.tree.create_root();  // ... and another's, a window (64 cells) away
  CHECK_TRUE(f.map.update(a, 5, 7, obs(1, 0)));
  CHECK_TRUE(f.map.update(b, 5 + 64, 7 - 128, obs(0, 2)));
  // Same storage cell, two entries; each lineage sees only its own.
  LONGS_EQUAL(2U, f.map.entries_in_cell(5, 7));
  CHECK_TRUE(view_is(f.map, a, 5, 7, obs(1, 0)));
  CHECK_TRUE(view_is(f.map, b, 5 + 64, 7 - 128, obs(0, 2)));
  // The copies of a cell are one cell for its own lineage: the caller keeps a lineage
  // within half a window so that it never asks for two of them.
  CHECK_TRUE(view_is(f.map, a, 5 - 64, 7 + 64, obs(1, 0)));
  CellObservation v;
  CHECK_FALSE(f.map.lookup(a, 6, 7, &v));
  CHECK_TRUE(f.map.invariants_hold());
}

TEST(DpMap, popped_cells_of_a_torus_come_back_next_to_their_place_with_unwrap_near) {
  DpFixture f(8U, 8U, torus_options(8U, 64U));
  const NodeId r = f.tree.create_root();
  // A lineage drawn far from the origin, within half a window (32 cells) of (-1000, 3000).
  const std::int32_t cells[][2] = {{-1000, 3000}, {-1015, 2990}, {-985, 3014}, {-1001, 2999}};
  for (const auto& c : cells) CHECK_TRUE(f.map.update(r, c[0], c[1], obs(1, 1)));
  std::int32_t ix = 0;
  std::int32_t iy = 0;
  CellObservation v;
  std::uint32_t found = 0U;
  while (f.map.pop_observation(r, &ix, &iy, &v)) {
    CHECK(ix >= 0 && ix < 64 && iy >= 0 && iy < 64);  // window coordinates
    f.map.unwrap_near(&ix, &iy, -1000, 3000);
    bool match = false;
    for (const auto& c : cells) match = match || (c[0] == ix && c[1] == iy);
    CHECK_TRUE(match);
    ++found;
  }
  LONGS_EQUAL(4U, found);
  // Without wrap, unwrap_near changes nothing.
  DpFixture g(8U, 8U, small_options(8U, 64U));
  ix = 70;
  iy = -3;
  g.map.unwrap_near(&ix, &iy, 0, 0);
  LONGS_EQUAL(70, ix);
  LONGS_EQUAL(-3, iy);
}

TEST(DpMap, fill_rect_on_a_torus_reads_any_rectangle_in_place) {
  DpFixture f(8U, 8U, torus_options(8U, 64U));
  const NodeId r = f.tree.create_root();
  CHECK_TRUE(f.map.update(r, -3, -2, obs(2, 0)));
  CHECK_TRUE(f.map.update(r, -1, -1, obs(0, 2)));
  const sdpslam::CellRect rect{-4, -3, 4, 3};
  std::vector<CellObservation> values(12U);
  std::vector<std::uint8_t> known(12U);
  LONGS_EQUAL(2U, f.map.fill_rect(r, rect, values.data(), known.data()));
  CHECK_EQUAL(1U, known[1U * 4U + 1U]);  // (-3, -2)
  CHECK_TRUE(values[1U * 4U + 1U] == obs(2, 0));
  CHECK_EQUAL(1U, known[2U * 4U + 3U]);  // (-1, -1)
  CHECK_TRUE(values[2U * 4U + 3U] == obs(0, 2));
}

// The wrap contract, randomised: lineages (a root and a child that shadows some of its
// cells) drawn at random places up to ten windows apart, each writing only within its own
// square of half the window; every lookup closer than half a window to that square gives
// exactly what a private map of the lineage holds, however the lineages share storage.
TEST(DpMap, on_a_torus_lookups_near_a_lineages_square_are_exact_wherever_the_lineages_are) {
  constexpr std::int32_t kWindow = 64;  // torus_options(): 64 × 64 cells
  constexpr std::int32_t kHalf = kWindow / 2;
  constexpr std::uint32_t kLineages = 12U;
  DpFixture f(2U * kLineages, 8U, torus_options(64U, 4096U));
  LONGS_EQUAL(kWindow, f.map.width_cells());
  sdpslam::test::SplitMix64 rng{0x7A11ULL};
  const auto coord = [&rng](std::int32_t lo, std::int32_t span) {
    return lo + static_cast<std::int32_t>(rng.below(static_cast<std::uint32_t>(span)));
  };
  struct Lineage {
    NodeId root = kNoNode;
    NodeId leaf = kNoNode;
    std::int32_t x0 = 0;
    std::int32_t y0 = 0;  // lower corner of its square of kHalf × kHalf cells
    std::map<std::pair<std::int32_t, std::int32_t>, CellObservation> cells;  // what its leaf sees
  };
  std::vector<Lineage> lineages;
  for (std::uint32_t k = 0; k < kLineages; ++k) {
    Lineage l;
    l.root = f.tree.create_root();
    l.x0 = coord(-5 * kWindow, 10 * kWindow);
    l.y0 = coord(-5 * kWindow, 10 * kWindow);
    lineages.push_back(l);
  }
  for (Lineage& l : lineages) {  // every root writes, then every child: interleaved lineages
    for (int i = 0; i < 150; ++i) {
      const std::int32_t x = coord(l.x0, kHalf);
      const std::int32_t y = coord(l.y0, kHalf);
      const CellObservation v = obs(static_cast<std::uint16_t>(rng.below(50U)), static_cast<std::uint16_t>(rng.below(50U)));
      CHECK_TRUE(f.map.update(l.root, x, y, v));
      l.cells[{x, y}] = v;
    }
  }
  for (Lineage& l : lineages) {
    l.leaf = f.tree.add_child(l.root);
    for (int i = 0; i < 60; ++i) {
      const std::int32_t x = coord(l.x0, kHalf);
      const std::int32_t y = coord(l.y0, kHalf);
      const CellObservation v = obs(100U, static_cast<std::uint16_t>(rng.below(50U)));
      CHECK_TRUE(f.map.update(l.leaf, x, y, v));
      l.cells[{x, y}] = v;
    }
  }
  CHECK_TRUE(f.map.invariants_hold());
  std::uint32_t known = 0U;
  for (const Lineage& l : lineages) {
    // Every cell closer than half a window to the square: (x0 - kHalf, x0 + kHalf + kHalf).
    for (std::int32_t y = l.y0 - kHalf + 1; y < l.y0 + 2 * kHalf; ++y) {
      for (std::int32_t x = l.x0 - kHalf + 1; x < l.x0 + 2 * kHalf; ++x) {
        CellObservation v;
        const bool seen = f.map.lookup(l.leaf, x, y, &v);
        const auto it = l.cells.find({x, y});
        CHECK_EQUAL(it != l.cells.end(), seen);
        if (seen) {
          CHECK_TRUE(v == it->second);
          ++known;
        }
      }
    }
  }
  std::uint32_t written = 0U;
  for (const Lineage& l : lineages) written += static_cast<std::uint32_t>(l.cells.size());
  LONGS_EQUAL(written, known);
}
