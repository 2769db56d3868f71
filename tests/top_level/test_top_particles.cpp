// The top-level particle set (paper Algorithm 1 lines 9-12) through its own API:
// ranking, elitism, diversification from the PGS, SegSLAM's local analysis and the
// extension to a new level.
#include <CppUTest/TestHarness.h>

#include <cstdint>

#include "sdpslam/core/arena.h"
#include "sdpslam/core/rng.h"
#include "top/segment_graph.h"
#include "top/top_particles.h"

using sdpslam::Arena;
using sdpslam::PgsNodeInput;
using sdpslam::PgsStatus;
using sdpslam::Rng;
using sdpslam::SegmentGraph;
using sdpslam::SegmentGraphOptions;
using sdpslam::TopologyMode;
using sdpslam::TopParticleOptions;
using sdpslam::TopParticles;

namespace {

alignas(16) unsigned char g_buffer[256U * 1024U];

constexpr std::uint32_t kNodes = 5U;  // PGS nodes per level (bottom particles)

TopParticleOptions options(std::uint32_t particles, std::uint32_t max_levels) {
  TopParticleOptions o;
  o.particles = particles;
  o.max_levels = max_levels;
  o.topology = TopologyMode::kSdp;
  o.segslam_window = 2U;
  o.elite_fraction = 0.2;
  o.worst_fraction = 0.2;
  o.diversify_levels = 2U;
  o.follow_best_fraction = 0.25;
  o.prior_error_m = 1.0;
  return o;
}

// A PGS with `levels` live levels of kNodes nodes, and the particle set over the same arena.
struct Rig {
  Arena arena{g_buffer, sizeof g_buffer};
  SegmentGraph graph;
  TopParticles top;
  Rig(const TopParticleOptions& o, std::uint32_t levels) {
    SegmentGraphOptions g;
    g.max_levels = o.max_levels;
    g.nodes_per_level = kNodes;
    CHECK_TRUE(graph.init(g, arena));
    CHECK_TRUE(top.init(o, arena));
    PgsNodeInput in[kNodes];
    for (std::uint32_t i = 0; i < kNodes; ++i) in[i].particle_id = i;
    for (std::uint32_t l = 0; l < levels; ++l) CHECK_TRUE(graph.add_level(in, kNodes).status == PgsStatus::kOk);
  }
  // Particle p: choice (p + level) % kNodes at every live level, error 0.1 × (p + 1)
  // (so rank = index).
  void distinct_choices() {
    for (std::uint32_t p = 0; p < top.size(); ++p) {
      for (std::uint32_t l = graph.first_live_level(); l < graph.level_end(); ++l) top.set_choice(p, l, (p + l) % kNodes);
      top.set_error(p, 0.1 * (p + 1U));
    }
  }
};

}  // namespace

TEST_GROUP(TopParticles){};

TEST(TopParticles, ranking_is_by_error_stable_with_unevaluated_particles_at_the_prior) {
  Rig rig(options(5U, 4U), 1U);
  TopParticles& top = rig.top;
  top.set_error(0U, 0.5);
  top.set_error(2U, 0.2);
  top.set_error(3U, 1.0);  // ties with the prior of particles 1 and 4
  LONGS_EQUAL(2U, top.rank());
  const std::uint32_t expected[5] = {2U, 0U, 1U, 3U, 4U};
  for (std::uint32_t r = 0; r < 5U; ++r) LONGS_EQUAL(expected[r], top.ranked(r));
  CHECK_FALSE(top.has_error(1U));
  DOUBLES_EQUAL(1.0, top.key(4U), 0.0);
}

TEST(TopParticles, the_error_summary_counts_only_evaluated_particles) {
  Rig rig(options(6U, 4U), 1U);
  double mean = -1.0;
  double sd = -1.0;
  std::uint32_t count = 99U;
  rig.top.error_summary(&mean, &sd, &count);
  LONGS_EQUAL(0U, count);
  DOUBLES_EQUAL(0.0, mean, 0.0);
  rig.top.set_error(1U, 0.2);
  rig.top.set_error(4U, 0.6);
  rig.top.error_summary(&mean, &sd, &count);
  LONGS_EQUAL(2U, count);
  DOUBLES_EQUAL(0.4, mean, 1e-12);
  DOUBLES_EQUAL(0.2, sd, 1e-12);
}

TEST(TopParticles, elitism_keeps_the_elite_and_copies_it_over_the_worst) {
  Rig rig(options(10U, 4U), 3U);  // elite 2, worst 2
  TopParticles& top = rig.top;
  rig.distinct_choices();
  Rng rng(7U);
  top.resample_and_diversify(rig.graph, rng);
  // The elite (particles 0 and 1) are untouched.
  for (std::uint32_t p = 0; p < 2U; ++p) {
    for (std::uint32_t l = 0; l < 3U; ++l) LONGS_EQUAL((p + l) % kNodes, top.choice(p, l));
    DOUBLES_EQUAL(0.1 * (p + 1U), top.key(p), 1e-15);
  }
  // The worst two became the elite's copies (best over worst), then diversified: their
  // errors are the elite's.
  DOUBLES_EQUAL(0.1, top.key(9U), 1e-15);
  DOUBLES_EQUAL(0.2, top.key(8U), 1e-15);
  DOUBLES_EQUAL(0.3, top.key(2U), 1e-15);
  // Every choice is a node of its level.
  for (std::uint32_t p = 0; p < top.size(); ++p) {
    for (std::uint32_t l = 0; l < 3U; ++l) CHECK(top.choice(p, l) < kNodes);
  }
}

TEST(TopParticles, diversification_resamples_the_non_elite_from_the_graph) {
  TopParticleOptions o = options(20U, 4U);
  o.diversify_levels = 8U;  // each non-elite particle re-samples level 1 almost surely
  Rig rig(o, 2U);
  TopParticles& top = rig.top;
  rig.distinct_choices();
  // Level 1 given level 0: every edge into node 3 is far better than the rest, so a
  // re-sampled choice at level 1 is almost surely 3.
  for (std::uint32_t a = 0; a < kNodes; ++a) {
    for (std::uint32_t b = 0; b < kNodes; ++b) {
      CHECK_TRUE(rig.graph.record_error(0U, a, b, b == 3U ? 1e-4 : 10.0) == PgsStatus::kOk);
    }
  }
  Rng rng(11U);
  top.resample_and_diversify(rig.graph, rng);
  std::uint32_t at_three = 0U;
  for (std::uint32_t p = 4U; p < top.size(); ++p) at_three += top.choice(p, 1U) == 3U ? 1U : 0U;
  CHECK(at_three >= 15U);  // of 16
  // The elite (the best 4) kept their own, 3 only where it was theirs.
  for (std::uint32_t p = 0; p < 4U; ++p) LONGS_EQUAL((p + 1U) % kNodes, top.choice(p, 1U));
}

TEST(TopParticles, segslam_topology_makes_older_choices_follow_the_best) {
  TopParticleOptions o = options(10U, 6U);
  o.topology = TopologyMode::kSegSlam;
  o.segslam_window = 2U;
  Rig rig(o, 5U);
  TopParticles& top = rig.top;
  rig.distinct_choices();
  Rng rng(3U);
  top.resample_and_diversify(rig.graph, rng);
  // Levels 0..2 are before the window (levels 3 and 4): every particle but the elite
  // (particles 0 and 1) has the best's (particle 0's) choices there...
  for (std::uint32_t p = 2U; p < top.size(); ++p) {
    for (std::uint32_t l = 0; l < 3U; ++l) LONGS_EQUAL(top.choice(0U, l), top.choice(p, l));
  }
  // ... while the elite's own are kept.
  for (std::uint32_t l = 0; l < 5U; ++l) LONGS_EQUAL((1U + l) % kNodes, top.choice(1U, l));
  // The SDP topology re-samples anywhere: with it, some older choice differs from the best's.
  Rig sdp(options(10U, 6U), 5U);
  sdp.distinct_choices();
  Rng rng2(3U);
  sdp.top.resample_and_diversify(sdp.graph, rng2);
  std::uint32_t differing = 0U;
  for (std::uint32_t p = 2U; p < 10U; ++p) {
    for (std::uint32_t l = 0; l < 3U; ++l) differing += sdp.top.choice(p, l) != sdp.top.choice(0U, l) ? 1U : 0U;
  }
  CHECK(differing > 0U);
}

TEST(TopParticles, extension_gives_the_best_ranks_the_bottom_best_and_samples_the_rest) {
  Rig rig(options(8U, 4U), 2U);  // follow 0.25 of 8: the best 2
  TopParticles& top = rig.top;
  rig.distinct_choices();
  // Level 1 given level 0 prefers node 2 strongly; the bottom's best is node 4.
  for (std::uint32_t a = 0; a < kNodes; ++a) {
    for (std::uint32_t b = 0; b < kNodes; ++b) {
      CHECK_TRUE(rig.graph.record_error(0U, a, b, b == 2U ? 1e-6 : 10.0) == PgsStatus::kOk);
    }
  }
  Rng rng(5U);
  top.extend_to_level(1U, 4U, rig.graph, rng);
  LONGS_EQUAL(4U, top.choice(0U, 1U));
  LONGS_EQUAL(4U, top.choice(1U, 1U));
  for (std::uint32_t p = 2U; p < 8U; ++p) LONGS_EQUAL(2U, top.choice(p, 1U));
  // A level the graph cannot sample (not live): everyone takes the bottom's best.
  top.extend_to_level(3U, 1U, rig.graph, rng);
  for (std::uint32_t p = 0; p < 8U; ++p) LONGS_EQUAL(1U, top.choice(p, 3U));
}

TEST(TopParticles, the_same_seed_gives_the_same_choices) {
  std::uint16_t first[12][3];
  for (int run = 0; run < 2; ++run) {
    Rig rig(options(12U, 4U), 3U);
    rig.distinct_choices();
    Rng rng(99U);
    for (int round = 0; round < 4; ++round) rig.top.resample_and_diversify(rig.graph, rng);
    for (std::uint32_t p = 0; p < 12U; ++p) {
      for (std::uint32_t l = 0; l < 3U; ++l) {
        if (run == 0) {
          first[p][l] = rig.top.choice(p, l);
        } else {
          LONGS_EQUAL(first[p][l], rig.top.choice(p, l));
        }
      }
    }
  }
}

TEST(TopParticles, init_refuses_invalid_options_and_a_short_arena) {
  TopParticleOptions bad = options(0U, 4U);
  LONGS_EQUAL(0U, TopParticles::required_bytes(bad));
  Arena arena(g_buffer, sizeof g_buffer);
  TopParticles top;
  CHECK_FALSE(top.init(bad, arena));
  bad = options(4U, 1U);  // one level
  CHECK_FALSE(top.init(bad, arena));
  bad = options(4U, 4U);
  bad.elite_fraction = 0.7;
  bad.worst_fraction = 0.5;
  CHECK_FALSE(top.init(bad, arena));
  const TopParticleOptions good = options(4U, 4U);
  const std::size_t need = TopParticles::required_bytes(good);
  CHECK(need > 0U);
  Arena small(g_buffer, need - 1U);
  CHECK_FALSE(top.init(good, small));
  Arena enough(g_buffer, need);
  CHECK_TRUE(top.init(good, enough));
  CHECK(TopParticleOptions::from(sdpslam::SdpOptions{}).valid());
}
