// Probabilistic Graph of Segments: equation (4) probabilities, accumulation modes,
// sampling, permanent levels and the chain of submap frames (Fig. 3 (l)).
#include <CppUTest/TestHarness.h>

#include <cmath>
#include <limits>

#include "sdpslam/core/arena.h"
#include "top/segment_graph.h"
#include "top_level_fixtures.h"

using sdpslam::PgsAccumulation;
using sdpslam::PgsNodeInput;
using sdpslam::PgsStatus;
using sdpslam::Pose2;
using sdpslam::SegmentGraph;
using sdpslam::SegmentGraphOptions;

namespace {

constexpr double kPi = 3.14159265358979323846;
alignas(16) unsigned char g_buffer[256U * 1024U];

// A fresh graph over the shared buffer for each test.
struct Fixture {
  sdpslam::Arena arena{g_buffer, sizeof g_buffer};
  SegmentGraph graph;
  explicit Fixture(const SegmentGraphOptions& o) { CHECK_TRUE(graph.init(o, arena)); }
};

SegmentGraphOptions options(std::uint32_t levels, std::uint32_t nodes, PgsAccumulation mode = PgsAccumulation::kSum) {
  SegmentGraphOptions o;
  o.max_levels = levels;
  o.nodes_per_level = nodes;
  o.accumulation = mode;
  o.prior_error_m = 1.0;
  return o;
}

// Adds a level of `count` nodes with particle ids base+i, identity initial poses and the
// given final pose.
std::uint32_t add(SegmentGraph& g, std::uint32_t count, const Pose2& final_pose = Pose2{}, std::uint32_t base = 0U) {
  PgsNodeInput in[16];
  for (std::uint32_t i = 0; i < count; ++i) {
    in[i].particle_id = base + i;
    in[i].final_pose = final_pose;
  }
  const auto r = g.add_level(in, count);
  CHECK_TRUE(r.status == PgsStatus::kOk);
  return r.level;
}

void check_pose(const Pose2& e, const Pose2& a, double tol = 1e-12) {
  DOUBLES_EQUAL(e.x_m, a.x_m, tol);
  DOUBLES_EQUAL(e.y_m, a.y_m, tol);
  DOUBLES_EQUAL(0.0, sdpslam::normalize_angle_rad(e.heading_rad - a.heading_rad), tol);
}

}  // namespace

TEST_GROUP(SegmentGraph){};

TEST(SegmentGraph, probabilities_sum_to_one_and_order_inversely_to_error) {
  Fixture f(options(4U, 3U));
  SegmentGraph& g = f.graph;
  add(g, 3U);
  add(g, 3U);
  const double errors[3][3] = {{0.5, 1.5, 2.0}, {0.25, 3.0, 0.75}, {1.25, 4.0, 0.6}};
  for (std::uint32_t a = 0; a < 3U; ++a) {
    for (std::uint32_t b = 0; b < 3U; ++b) LONGS_EQUAL(PgsStatus::kOk, g.record_error(0U, a, b, errors[a][b]));
  }
  double inv_total = 0.0;
  for (auto& row : errors) {
    for (double e : row) inv_total += 1.0 / e;
  }
  double sum = 0.0;
  for (std::uint32_t a = 0; a < 3U; ++a) {
    for (std::uint32_t b = 0; b < 3U; ++b) {
      const double p = g.pair_probability(0U, a, b);
      DOUBLES_EQUAL((1.0 / errors[a][b]) / inv_total, p, 1e-12);  // corrected equation (4)
      sum += p;
      for (std::uint32_t c = 0; c < 3U; ++c) {
        for (std::uint32_t d = 0; d < 3U; ++d) {
          if (errors[c][d] > errors[a][b]) CHECK(g.pair_probability(0U, c, d) < p);
        }
      }
    }
  }
  DOUBLES_EQUAL(1.0, sum, 1e-12);
}

TEST(SegmentGraph, unsampled_edges_take_the_prior_error_and_share_probability_evenly) {
  SegmentGraphOptions o = options(4U, 4U);
  o.prior_error_m = 2.5;
  Fixture f(o);
  add(f.graph, 2U);
  add(f.graph, 4U);
  DOUBLES_EQUAL(2.5, f.graph.edge_error(0U, 1U, 3U), 0.0);
  LONGS_EQUAL(0, f.graph.edge_sample_count(0U, 1U, 3U));
  DOUBLES_EQUAL(1.0 / 8.0, f.graph.pair_probability(0U, 1U, 3U), 1e-15);
  // A sampled edge with a better error than the prior gains probability.
  f.graph.record_error(0U, 0U, 0U, 0.5);
  CHECK(f.graph.pair_probability(0U, 0U, 0U) > 1.0 / 8.0);
  CHECK(f.graph.pair_probability(0U, 1U, 3U) < 1.0 / 8.0);
}

TEST(SegmentGraph, zero_error_is_raised_to_the_floor_instead_of_dividing_by_zero) {
  SegmentGraphOptions o = options(4U, 2U);
  o.error_floor_m = 1e-3;
  Fixture f(o);
  add(f.graph, 2U);
  add(f.graph, 2U);
  f.graph.record_error(0U, 0U, 0U, 0.0);
  DOUBLES_EQUAL(1e-3, f.graph.edge_error(0U, 0U, 0U), 0.0);
  const double p = f.graph.pair_probability(0U, 0U, 0U);
  CHECK(std::isfinite(p));
  DOUBLES_EQUAL(1000.0 / (1000.0 + 3.0), p, 1e-12);
}

TEST(SegmentGraph, sum_accumulation_favours_the_rarely_sampled_edge) {
  Fixture f(options(4U, 2U, PgsAccumulation::kSum));
  add(f.graph, 1U);
  add(f.graph, 2U);
  for (int i = 0; i < 10; ++i) f.graph.record_error(0U, 0U, 0U, 0.1);  // often, good: sum 1.0
  f.graph.record_error(0U, 0U, 1U, 0.5);                                // once, worse: sum 0.5
  DOUBLES_EQUAL(1.0, f.graph.edge_error(0U, 0U, 0U), 1e-12);
  DOUBLES_EQUAL(0.5, f.graph.edge_error(0U, 0U, 1U), 1e-12);
  CHECK(f.graph.pair_probability(0U, 0U, 1U) > f.graph.pair_probability(0U, 0U, 0U));
  LONGS_EQUAL(10, f.graph.edge_sample_count(0U, 0U, 0U));
}

TEST(SegmentGraph, mean_accumulation_favours_the_lower_mean_error) {
  Fixture f(options(4U, 2U, PgsAccumulation::kMean));
  add(f.graph, 1U);
  add(f.graph, 2U);
  for (int i = 0; i < 10; ++i) f.graph.record_error(0U, 0U, 0U, 0.1);
  f.graph.record_error(0U, 0U, 1U, 0.5);
  DOUBLES_EQUAL(0.1, f.graph.edge_error(0U, 0U, 0U), 1e-12);
  DOUBLES_EQUAL(0.5, f.graph.edge_error(0U, 0U, 1U), 1e-12);
  CHECK(f.graph.pair_probability(0U, 0U, 0U) > f.graph.pair_probability(0U, 0U, 1U));
}

TEST(SegmentGraph, conditional_sampling_frequencies_match_probabilities) {
  Fixture f(options(4U, 5U));
  add(f.graph, 2U);
  add(f.graph, 5U);
  const double errors[5] = {0.2, 0.4, 0.8, 1.6, 0.3};
  double inv_total = 0.0;
  for (std::uint32_t b = 0; b < 5U; ++b) {
    f.graph.record_error(0U, 1U, b, errors[b]);
    inv_total += 1.0 / errors[b];
  }
  f.graph.record_error(0U, 0U, 3U, 0.01);  // another row must not leak into p(b | a=1)
  sdpslam::test::SplitMix64 rng(2024U);
  constexpr int kDraws = 20000;
  int counts[5] = {};
  for (int i = 0; i < kDraws; ++i) {
    const auto pick = f.graph.sample_next(0U, 1U, rng.uniform());
    CHECK_TRUE(pick.status == PgsStatus::kOk);
    ++counts[pick.node];
  }
  double chi2 = 0.0;
  for (std::uint32_t b = 0; b < 5U; ++b) {
    const double expected = kDraws * (1.0 / errors[b]) / inv_total;
    chi2 += (counts[b] - expected) * (counts[b] - expected) / expected;
  }
  CHECK_TEXT(chi2 < 18.5, "chi-square over 4 degrees of freedom beyond p = 0.001");
}

TEST(SegmentGraph, previous_node_sampling_uses_the_column_of_the_edge_matrix) {
  Fixture f(options(4U, 3U));
  add(f.graph, 3U);
  add(f.graph, 2U);
  const double errors[3] = {0.1, 1.0, 10.0};
  for (std::uint32_t a = 0; a < 3U; ++a) f.graph.record_error(0U, a, 1U, errors[a]);
  sdpslam::test::SplitMix64 rng(5U);
  int counts[3] = {};
  for (int i = 0; i < 11100; ++i) ++counts[f.graph.sample_previous(1U, 1U, rng.uniform()).node];
  // Expected 10000 : 1000 : 100.
  CHECK(std::abs(counts[0] - 10000) < 300);
  CHECK(std::abs(counts[1] - 1000) < 120);
  CHECK(std::abs(counts[2] - 100) < 40);
}

TEST(SegmentGraph, pair_sampling_frequencies_match_probabilities) {
  Fixture f(options(4U, 4U));
  add(f.graph, 3U);
  add(f.graph, 4U);
  sdpslam::test::SplitMix64 err_rng(3U);
  for (std::uint32_t a = 0; a < 3U; ++a) {
    for (std::uint32_t b = 0; b < 4U; ++b) f.graph.record_error(0U, a, b, 0.1 + err_rng.uniform());
  }
  sdpslam::test::SplitMix64 rng(99U);
  constexpr int kDraws = 30000;
  int counts[3][4] = {};
  for (int i = 0; i < kDraws; ++i) {
    const auto pick = f.graph.sample_pair(0U, rng.uniform());
    ++counts[pick.node_a][pick.node_b];
  }
  double chi2 = 0.0;
  for (std::uint32_t a = 0; a < 3U; ++a) {
    for (std::uint32_t b = 0; b < 4U; ++b) {
      const double expected = kDraws * f.graph.pair_probability(0U, a, b);
      chi2 += (counts[a][b] - expected) * (counts[a][b] - expected) / expected;
    }
  }
  CHECK_TEXT(chi2 < 31.3, "chi-square over 11 degrees of freedom beyond p = 0.001");
}

TEST(SegmentGraph, sampling_is_an_inverse_cdf_of_u_in_index_order) {
  Fixture f(options(4U, 3U));
  add(f.graph, 1U);
  add(f.graph, 3U);  // three unsampled edges: equal weights
  LONGS_EQUAL(0, f.graph.sample_next(0U, 0U, 0.0).node);
  LONGS_EQUAL(0, f.graph.sample_next(0U, 0U, 0.33).node);
  LONGS_EQUAL(1, f.graph.sample_next(0U, 0U, 0.34).node);
  LONGS_EQUAL(2, f.graph.sample_next(0U, 0U, 0.9999999999).node);
  CHECK_TRUE(f.graph.sample_next(0U, 0U, 1.0).status == PgsStatus::kBadArgument);
  CHECK_TRUE(f.graph.sample_next(0U, 0U, -0.1).status == PgsStatus::kBadArgument);
  CHECK_TRUE(f.graph.sample_next(0U, 0U, std::nan("")).status == PgsStatus::kBadArgument);
}

TEST(SegmentGraph, full_graph_refuses_new_level_and_counts_it) {
  Fixture f(options(3U, 2U));
  add(f.graph, 2U);
  add(f.graph, 2U);
  add(f.graph, 2U);
  PgsNodeInput in[2];
  const auto r = f.graph.add_level(in, 2U);
  CHECK_TRUE(r.status == PgsStatus::kFull);
  LONGS_EQUAL(1, f.graph.full_count());
  LONGS_EQUAL(3, f.graph.levels_used());
  LONGS_EQUAL(6, f.graph.live_node_count());
  LONGS_EQUAL(8, f.graph.live_edge_count());
  CHECK_TRUE(f.graph.invariants_hold());
}

TEST(SegmentGraph, make_oldest_permanent_releases_the_level_and_its_slot_is_reused) {
  Fixture f(options(3U, 4U));
  SegmentGraph& g = f.graph;
  add(g, 4U, Pose2{}, 100U);
  add(g, 3U, Pose2{}, 200U);
  add(g, 2U, Pose2{}, 300U);
  g.record_error(0U, 2U, 1U, 0.3);
  g.record_error(1U, 0U, 0U, 0.7);
  const auto perm = g.make_oldest_permanent(2U);
  CHECK_TRUE(perm.status == PgsStatus::kOk);
  LONGS_EQUAL(102, perm.node.particle_id);
  LONGS_EQUAL(0, perm.node.level);
  LONGS_EQUAL(3, perm.released_nodes);
  LONGS_EQUAL(12, perm.released_edges);
  LONGS_EQUAL(1, g.permanent_level_count());
  LONGS_EQUAL(1, g.first_live_level());
  LONGS_EQUAL(2, g.levels_used());
  CHECK_FALSE(g.is_live(0U));
  LONGS_EQUAL(0, g.node_count(0U));
  CHECK_TRUE(g.node(0U, 0U) == nullptr);
  LONGS_EQUAL(5, g.live_node_count());
  LONGS_EQUAL(6, g.live_edge_count());
  CHECK_TRUE(g.invariants_hold());
  // Edges of the surviving levels are untouched; those into the permanent level are gone.
  DOUBLES_EQUAL(0.7, g.edge_error(1U, 0U, 0U), 1e-15);
  CHECK(g.edge_error(0U, 2U, 1U) < 0.0);
  LONGS_EQUAL(PgsStatus::kNoLevel, g.record_error(0U, 2U, 1U, 0.1));
  // The freed slot takes the next level.
  LONGS_EQUAL(3, add(g, 4U, Pose2{}, 400U));
  LONGS_EQUAL(400, g.node(3U, 0U)->particle_id);
  LONGS_EQUAL(3, g.levels_used());
  LONGS_EQUAL(3, g.peak_levels_used());
  CHECK_TRUE(g.invariants_hold());
}

TEST(SegmentGraph, first_level_after_permanence_is_sampled_conditionally_on_the_anchor) {
  Fixture f(options(3U, 3U));
  SegmentGraph& g = f.graph;
  add(g, 2U);
  add(g, 3U);
  g.record_error(0U, 1U, 2U, 0.001);  // anchor 1 → node 2 is by far the best
  g.record_error(0U, 0U, 0U, 0.001);  // a row that is released with node 0
  (void)g.make_oldest_permanent(1U);
  sdpslam::test::SplitMix64 rng(1U);
  int counts[3] = {};
  for (int i = 0; i < 3000; ++i) ++counts[g.sample_first(rng.uniform()).node];
  CHECK(counts[2] > 2900);
}

TEST(SegmentGraph, first_level_without_anchor_uses_the_marginal_then_uniform) {
  Fixture f(options(3U, 3U));
  SegmentGraph& g = f.graph;
  add(g, 2U);
  sdpslam::test::SplitMix64 rng(8U);
  int uniform[2] = {};
  for (int i = 0; i < 2000; ++i) ++uniform[g.sample_first(rng.uniform()).node];
  CHECK(std::abs(uniform[0] - 1000) < 100);
  add(g, 2U);
  g.record_error(0U, 1U, 0U, 0.01);
  g.record_error(0U, 1U, 1U, 0.01);
  int marginal[2] = {};
  for (int i = 0; i < 2000; ++i) ++marginal[g.sample_first(rng.uniform()).node];
  CHECK(marginal[1] > 1950);
}

TEST(SegmentGraph, chain_of_known_poses_composes_into_the_global_frame) {
  Fixture f(options(8U, 2U));
  SegmentGraph& g = f.graph;
  // Each segment drives 1 m, then turns 90°: left, left, right, right.
  const double turns[4] = {kPi / 2.0, kPi / 2.0, -kPi / 2.0, -kPi / 2.0};
  for (double turn : turns) add(g, 2U, Pose2{1.0, 0.0, turn});
  add(g, 2U);
  const std::uint32_t choices[5] = {0U, 1U, 0U, 1U, 1U};
  Pose2 frames[5];
  LONGS_EQUAL(PgsStatus::kOk, g.compose_chain(choices, 5U, frames));
  check_pose(Pose2{0.0, 0.0, 0.0}, frames[0]);
  check_pose(Pose2{1.0, 0.0, kPi / 2.0}, frames[1]);
  check_pose(Pose2{1.0, 1.0, kPi}, frames[2]);
  check_pose(Pose2{0.0, 1.0, kPi / 2.0}, frames[3]);
  check_pose(Pose2{0.0, 2.0, 0.0}, frames[4]);
  LONGS_EQUAL(PgsStatus::kNoLevel, g.compose_chain(choices, 6U, frames));
}

TEST(SegmentGraph, chain_around_a_square_loop_returns_to_the_start) {
  Fixture f(options(8U, 2U));
  SegmentGraph& g = f.graph;
  // Each segment drives 1 m and turns left 90°: four segments go round a square, and the
  // headings pass through +-pi (angle wrapping).
  for (int k = 0; k < 5; ++k) add(g, 2U, Pose2{1.0, 0.0, kPi / 2.0});
  const std::uint32_t choices[5] = {1U, 0U, 1U, 0U, 1U};
  Pose2 frames[5];
  LONGS_EQUAL(PgsStatus::kOk, g.compose_chain(choices, 5U, frames));
  check_pose(Pose2{1.0, 1.0, kPi}, frames[2]);
  check_pose(Pose2{0.0, 1.0, -kPi / 2.0}, frames[3]);
  check_pose(Pose2{0.0, 0.0, 0.0}, frames[4]);
}

TEST(SegmentGraph, transform_places_the_next_submap_start_on_the_previous_submap_end) {
  Fixture f(options(4U, 1U));
  SegmentGraph& g = f.graph;
  PgsNodeInput a;
  a.initial_pose = Pose2{0.0, 0.0, 0.0};
  a.final_pose = Pose2{3.0, 1.0, 0.4};
  PgsNodeInput b;
  b.initial_pose = Pose2{-0.5, 0.2, -0.3};  // the next submap does not start at its origin
  b.final_pose = Pose2{2.0, 0.0, 0.0};
  g.add_level(&a, 1U);
  g.add_level(&b, 1U);
  Pose2 t;
  LONGS_EQUAL(PgsStatus::kOk, g.transform_between(0U, 0U, 0U, t));
  // The same robot pose: b's initial pose, mapped into a's frame, is a's final pose.
  check_pose(a.final_pose, t.compose(b.initial_pose));
  check_pose(a.final_pose.compose(b.initial_pose.inverse()), t);
  LONGS_EQUAL(PgsStatus::kBadNode, g.transform_between(0U, 0U, 1U, t));
  LONGS_EQUAL(PgsStatus::kNoLevel, g.transform_between(1U, 0U, 0U, t));
}

TEST(SegmentGraph, permanent_levels_keep_the_chain_in_the_same_global_frame) {
  Fixture f(options(3U, 2U));
  SegmentGraph& g = f.graph;
  const Pose2 steps[3] = {{2.0, 0.0, 0.3}, {1.0, 0.5, -0.2}, {0.5, 0.0, 1.0}};
  for (const Pose2& s : steps) add(g, 2U, s);
  const std::uint32_t before_choice[3] = {1U, 0U, 1U};
  Pose2 before[3];
  g.compose_chain(before_choice, 3U, before);
  const auto p0 = g.make_oldest_permanent(1U);
  check_pose(before[0], p0.frame_in_global);
  const auto p1 = g.make_oldest_permanent(0U);
  check_pose(before[1], p1.frame_in_global);
  check_pose(before[1], g.anchor_frame());
  Pose2 after[1];
  LONGS_EQUAL(PgsStatus::kOk, g.compose_chain(&before_choice[2], 1U, after));
  check_pose(before[2], after[0], 1e-12);
  LONGS_EQUAL(2, g.permanent_level_count());
  CHECK_TRUE(g.invariants_hold());
}

TEST(SegmentGraph, chain_errors_are_recorded_on_every_edge_or_not_at_all) {
  Fixture f(options(4U, 2U));
  SegmentGraph& g = f.graph;
  for (int k = 0; k < 4; ++k) add(g, 2U);
  const std::uint32_t chain[4] = {0U, 1U, 1U, 0U};
  LONGS_EQUAL(PgsStatus::kOk, g.record_chain_error(0U, chain, 4U, 0.4));
  LONGS_EQUAL(1, g.edge_sample_count(0U, 0U, 1U));
  LONGS_EQUAL(1, g.edge_sample_count(1U, 1U, 1U));
  LONGS_EQUAL(1, g.edge_sample_count(2U, 1U, 0U));
  DOUBLES_EQUAL(0.4, g.edge_error(2U, 1U, 0U), 1e-15);
  const std::uint32_t bad[4] = {0U, 1U, 5U, 0U};
  LONGS_EQUAL(PgsStatus::kBadNode, g.record_chain_error(0U, bad, 4U, 0.4));
  LONGS_EQUAL(1, g.edge_sample_count(0U, 0U, 1U));  // nothing recorded
  LONGS_EQUAL(PgsStatus::kNoLevel, g.record_chain_error(1U, chain, 4U, 0.4));  // runs past the end
  CHECK_TRUE(g.invariants_hold());
}

TEST(SegmentGraph, misuse_is_refused_and_counted) {
  Fixture f(options(3U, 2U));
  SegmentGraph& g = f.graph;
  PgsNodeInput in[3];
  CHECK_TRUE(g.add_level(in, 3U).status == PgsStatus::kBadArgument);  // above nodes_per_level
  CHECK_TRUE(g.add_level(in, 0U).status == PgsStatus::kBadArgument);
  CHECK_TRUE(g.add_level(nullptr, 1U).status == PgsStatus::kBadArgument);
  add(g, 2U);
  add(g, 2U);
  LONGS_EQUAL(PgsStatus::kBadArgument, g.record_error(0U, 0U, 0U, std::numeric_limits<double>::infinity()));
  LONGS_EQUAL(PgsStatus::kBadArgument, g.record_error(0U, 0U, 0U, -0.1));
  LONGS_EQUAL(PgsStatus::kBadNode, g.record_error(0U, 2U, 0U, 0.1));
  LONGS_EQUAL(PgsStatus::kNoLevel, g.record_error(1U, 0U, 0U, 0.1));  // no level 2 yet
  CHECK_TRUE(g.sample_previous(0U, 0U, 0.5).status == PgsStatus::kNoLevel);
  CHECK_TRUE(g.make_oldest_permanent(2U).status == PgsStatus::kBadNode);
  CHECK(g.pair_probability(0U, 2U, 0U) < 0.0);
  LONGS_EQUAL(9, g.misuse_count());
  LONGS_EQUAL(0, g.edge_sample_count(0U, 0U, 0U));
  CHECK_TRUE(g.invariants_hold());
}

TEST(SegmentGraph, init_refuses_bad_options_and_short_arenas) {
  SegmentGraphOptions o = options(1U, 2U);
  CHECK_FALSE(o.valid());
  LONGS_EQUAL(0, SegmentGraph::required_bytes(o));
  o = options(4U, sdpslam::capacity::kMaxPgsNodesPerLevel + 1U);
  CHECK_FALSE(o.valid());
  o = options(4U, 2U);
  o.prior_error_m = 0.0;
  CHECK_FALSE(o.valid());
  alignas(16) static unsigned char small[64];
  sdpslam::Arena arena(small, sizeof small);
  SegmentGraph g;
  CHECK_FALSE(g.init(options(4U, 2U), arena));
  CHECK_FALSE(g.initialised());
  CHECK_TRUE(g.add_level(nullptr, 0U).status == PgsStatus::kNotInitialised);
  CHECK_TRUE(g.invariants_hold());
  sdpslam::Arena big(g_buffer, sizeof g_buffer);
  CHECK_TRUE(g.init(options(4U, 2U), big));
  CHECK(big.used_bytes() <= SegmentGraph::required_bytes(options(4U, 2U)));
  CHECK_FALSE(g.init(options(4U, 2U), big));
}

TEST(SegmentGraph, long_run_of_levels_and_permanence_keeps_invariants) {
  Fixture f(options(5U, 6U));
  SegmentGraph& g = f.graph;
  sdpslam::test::SplitMix64 rng(77U);
  std::uint32_t permanent = 0U;
  for (int step = 0; step < 300; ++step) {
    const auto count = static_cast<std::uint32_t>(1U + rng.next() % 6U);
    PgsNodeInput in[6];
    for (std::uint32_t i = 0; i < count; ++i) in[i].final_pose = Pose2{rng.uniform(), rng.uniform(), rng.uniform()};
    auto r = g.add_level(in, count);
    if (r.status == PgsStatus::kFull) {
      const auto first = g.sample_first(rng.uniform());
      CHECK_TRUE(g.make_oldest_permanent(first.node).status == PgsStatus::kOk);
      ++permanent;
      CHECK_TRUE(g.invariants_hold());
      r = g.add_level(in, count);
    }
    CHECK_TRUE(r.status == PgsStatus::kOk);
    // A few sampled chains with errors, as the top level would record them.
    for (int s = 0; s < 3 && g.levels_used() >= 2U; ++s) {
      std::uint32_t chain[5];
      chain[0] = g.sample_first(rng.uniform()).node;
      for (std::uint32_t k = 1; k < g.levels_used(); ++k) {
        chain[k] = g.sample_next(g.first_live_level() + k - 1U, chain[k - 1U], rng.uniform()).node;
      }
      LONGS_EQUAL(PgsStatus::kOk, g.record_chain_error(g.first_live_level(), chain, g.levels_used(), rng.uniform()));
      Pose2 frames[5];
      LONGS_EQUAL(PgsStatus::kOk, g.compose_chain(chain, g.levels_used(), frames));
    }
    CHECK_TRUE(g.invariants_hold());
  }
  LONGS_EQUAL(permanent, g.permanent_level_count());
  LONGS_EQUAL(300 - 5, permanent);
  LONGS_EQUAL(permanent, g.full_count());
  LONGS_EQUAL(5, g.peak_levels_used());
  LONGS_EQUAL(0, g.misuse_count());
}
