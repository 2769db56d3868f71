// The improved proposal: the scan matcher alone (recovers a perturbed pose on a known
// map, fails cleanly on an empty map or a scan without returns), its options, and the
// filter with it (more accurate than the odometry proposal with the same particles,
// deterministic, fallbacks counted).
#include <CppUTest/TestHarness.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

#include "filter_harness.h"
#include "sdpslam/core/bottom/scan_matcher.h"

using namespace sdpslam;
using sdpslam::test::FilterRig;

namespace {

// A tree with one root node and a DP map, with the room written into the root from a
// few true poses.
struct MapRig {
  std::vector<unsigned char> buffer;
  Arena arena;
  AncestryTree tree;
  std::unique_ptr<DpMap> map = std::make_unique<DpMap>();
  std::unique_ptr<BeamModel> beam = std::make_unique<BeamModel>();
  std::unique_ptr<RangeScan> scan = std::make_unique<RangeScan>();
  std::unique_ptr<ScanRays> rays = std::make_unique<ScanRays>();
  NodeId root = kNoNode;
  std::vector<test::Segment> world = test::room_world();

  MapRig() {
    DpMap::Options mo;
    mo.origin_x_m = -15.0;
    mo.origin_y_m = -15.0;
    mo.width_m = 30.0;
    mo.height_m = 30.0;
    mo.resolution_m = 0.05;
    mo.tile_capacity = 5000U;
    mo.observation_capacity = 200000U;
    buffer.assign(AncestryTree::required_arena_bytes(8U, 64U) + DpMap::required_arena_bytes(mo, 8U) + 256U, 0);
    arena.reset(buffer.data(), buffer.size());
    CHECK_TRUE(tree.init(arena, 8U, 64U));
    CHECK_TRUE(map->init(arena, mo, tree));
    CHECK_TRUE(beam->init(BeamModelOptions{}, 0.05));
    root = tree.create_root();
  }
  void observe(const Pose2& truth) {
    test::make_scan(world, truth, 0, scan.get());
    prepare_rays(*scan, rays.get());
    beam->update_map(*map, root, *rays, truth);
  }
  void look_from(const Pose2& truth) {
    test::make_scan(world, truth, 0, scan.get());
    prepare_rays(*scan, rays.get());
  }
};

// A corridor 3 m wide whose ends are beyond the laser's reach: the walls fix the
// lateral position and the heading, nothing fixes the position along it.
std::vector<test::Segment> plain_corridor() { return {{-60.0, -1.5, 60.0, -1.5}, {-60.0, 1.5, 60.0, 1.5}}; }

double distance(const Pose2& a, const Pose2& b) { return std::hypot(a.x_m - b.x_m, a.y_m - b.y_m); }

DpSlamOptions improved_options(std::uint32_t particles) {
  DpSlamOptions o = test::sim_options(particles);
  o.proposal = DpSlamOptions::Proposal::kScanMatch;
  return o;
}

std::vector<Pose2> run_loop(const DpSlamOptions& o, std::uint64_t seed, const test::SimRun& run,
                            DpSlamStats* stats = nullptr,
                            const std::vector<test::Segment>& world = test::room_world(),
                            double laser_sigma_m = 0.0) {
  FilterRig rig;
  CHECK_TRUE(rig.init(o, seed));
  rig.laser_sigma_m = laser_sigma_m;
  std::vector<Pose2> est;
  for (std::size_t i = 0; i < run.truth.size(); ++i) est.push_back(rig.step(run, world, i).pose);
  CHECK_TRUE(rig.filter->tree().invariants_hold());
  CHECK_TRUE(rig.filter->map().invariants_hold());
  if (stats != nullptr) *stats = rig.filter->stats();
  return est;
}

}  // namespace

TEST_GROUP(ScanMatcher){};

TEST(ScanMatcher, recovers_a_perturbed_pose_on_a_known_map) {
  MapRig r;
  r.observe(Pose2{0.0, 0.0, 0.0});
  r.observe(Pose2{1.0, 0.2, 0.3});
  const Pose2 truth{0.5, 0.1, 0.15};
  r.look_from(truth);
  const Pose2 guess{0.54, 0.07, 0.165};  // 5 cm and 0.9 degrees off: a bad odometry step
  const ScanMatch m = match_scan(*r.beam, *r.map, r.root, *r.rays, guess, ScanMatcherOptions{});
  std::printf("\n  match %.3f %.3f %.4f after %u evaluations\n", m.pose.x_m, m.pose.y_m, m.pose.heading_rad,
              m.evaluations);
  CHECK(m.outcome == ScanMatch::Outcome::kMatched);
  CHECK(distance(m.pose, truth) < 0.03);
  CHECK(std::fabs(m.pose.heading_rad - truth.heading_rad) < 0.01);
  CHECK(m.log_likelihood > r.beam->log_likelihood_strided(*r.map, r.root, *r.rays, guess, 4U, nullptr));
  const ScanMatcherOptions d;
  CHECK(m.evaluations > 1U);
  CHECK(m.evaluations <= 1U + 6U * d.max_iterations * (d.refinements + 1U));
}

TEST(ScanMatcher, in_a_plain_corridor_the_motion_prior_keeps_the_travel_odometry_measured) {
  // The map holds the scans of the last two updates, 0.2 m apart; the robot has moved on
  // another 0.2 m, which odometry measured exactly. The walls are drawn as dotted lines
  // (one hit per beam): the likelihood alone prefers poses whose hits fall on the old
  // dots, whatever the travel; the prior keeps the odometry's along-track estimate.
  MapRig r;
  r.world = plain_corridor();
  r.observe(Pose2{0.0, 0.0, 0.0});
  r.observe(Pose2{0.2, 0.0, 0.0});
  const Pose2 truth{0.4, 0.0, 0.0};
  r.look_from(truth);
  const MotionModel motion{MotionModelOptions{}};
  const MotionPrior prior = motion.prior(Pose2{0.2, 0.0, 0.0}, Pose2{0.2, 0.0, 0.0});
  const ScanMatch alone = match_scan(*r.beam, *r.map, r.root, *r.rays, prior.predicted, ScanMatcherOptions{});
  const ScanMatch with = match_scan(*r.beam, *r.map, r.root, *r.rays, prior.predicted, ScanMatcherOptions{}, &prior);
  std::printf("\n  along-track error: likelihood alone %+.3f m, with the motion prior %+.3f m\n",
              alone.pose.x_m - truth.x_m, with.pose.x_m - truth.x_m);
  CHECK(with.outcome == ScanMatch::Outcome::kMatched);
  CHECK(std::fabs(with.pose.x_m - truth.x_m) < 0.01);
  CHECK(std::fabs(with.pose.y_m) < 0.02);
  CHECK(std::fabs(with.pose.heading_rad) < 0.01);
  CHECK(std::fabs(alone.pose.x_m - truth.x_m) > std::fabs(with.pose.x_m - truth.x_m));
  // The likelihood it reports is the likelihood at the match, without the prior.
  DOUBLES_EQUAL(r.beam->log_likelihood_strided(*r.map, r.root, *r.rays, with.pose, ScanMatcherOptions{}.beam_stride,
                                               nullptr),
                with.log_likelihood, 1e-9);
}

TEST(ScanMatcher, empty_map_fails_as_map_too_empty_and_keeps_the_initial_pose) {
  MapRig r;
  r.look_from(Pose2{});
  const Pose2 guess{0.3, -0.2, 0.1};
  const ScanMatch m = match_scan(*r.beam, *r.map, r.root, *r.rays, guess, ScanMatcherOptions{});
  CHECK(m.outcome == ScanMatch::Outcome::kMapTooEmpty);
  LONGS_EQUAL(1, m.evaluations);
  DOUBLES_EQUAL(guess.x_m, m.pose.x_m, 0.0);
  DOUBLES_EQUAL(guess.heading_rad, m.pose.heading_rad, 0.0);
}

TEST(ScanMatcher, scan_without_returns_fails_as_too_few_beams) {
  MapRig r;
  r.observe(Pose2{});
  r.look_from(Pose2{});
  for (std::uint32_t i = 0; i < r.scan->beam_count; ++i) r.scan->ranges_m[i] = 0.0F;  // below range_min
  prepare_rays(*r.scan, r.rays.get());
  const ScanMatch m = match_scan(*r.beam, *r.map, r.root, *r.rays, Pose2{}, ScanMatcherOptions{});
  CHECK(m.outcome == ScanMatch::Outcome::kTooFewBeams);
  LONGS_EQUAL(0, m.beams);
}

TEST(ScanMatcher, a_scan_from_elsewhere_scores_too_low) {
  MapRig r;
  r.observe(Pose2{});
  r.look_from(Pose2{});
  for (std::uint32_t i = 0; i < r.scan->beam_count; ++i) r.scan->ranges_m[i] *= 0.5F;  // nothing fits
  prepare_rays(*r.scan, r.rays.get());
  ScanMatcherOptions o;
  o.min_mean_log_likelihood = -1.0;
  const ScanMatch m = match_scan(*r.beam, *r.map, r.root, *r.rays, Pose2{}, o);
  CHECK(m.outcome == ScanMatch::Outcome::kScoreTooLow);
}

TEST(ScanMatcher, strided_likelihood_with_the_weight_stride_equals_log_likelihood_bit_for_bit) {
  MapRig r;
  r.observe(Pose2{});
  r.look_from(Pose2{0.1, 0.0, 0.05});
  const Pose2 at{0.12, -0.01, 0.04};
  BeamScore s;
  const double a = r.beam->log_likelihood(*r.map, r.root, *r.rays, at);
  const double b = r.beam->log_likelihood_strided(*r.map, r.root, *r.rays, at,
                                                  r.beam->options().weight_beam_stride, &s);
  CHECK(std::memcmp(&a, &b, sizeof a) == 0);
  CHECK(s.beams > 50U);
  CHECK(s.known_beams > s.beams / 2U);
}

TEST_GROUP(ImprovedProposal){};

TEST(ImprovedProposal, out_of_range_matcher_options_are_refused_naming_the_key) {
  DpSlamOptions o = improved_options(4);
  CHECK_TRUE(o.validate(nullptr, 0));
  o.match.beam_stride = 0U;
  char why[160];
  CHECK_FALSE(o.validate(why, sizeof why));
  CHECK(std::strstr(why, "proposal.beam_stride") != nullptr);
  o = improved_options(4);
  o.match.min_known_fraction = 1.5;
  CHECK_FALSE(o.validate(why, sizeof why));
  CHECK(std::strstr(why, "proposal.min_known_fraction") != nullptr);
  o = improved_options(4);
  o.proposal_sigma_xy_m = std::nan("");
  CHECK_FALSE(o.validate(why, sizeof why));
  CHECK(std::strstr(why, "proposal.sample_sigma_xy_m") != nullptr);
}

TEST(ImprovedProposal, beats_the_odometry_proposal_with_the_same_particles) {
  // Mean over seeds: one run of 8 particles swings by a factor of two with the seed.
  const test::SimRun run = test::make_loop();
  DpSlamStats odo_stats;
  DpSlamStats imp_stats;
  double odo = 0.0;
  double imp = 0.0;
  for (std::uint64_t seed = 1U; seed <= 4U; ++seed) {
    odo += 0.25 * test::mean_error(run_loop(test::sim_options(8), seed, run, &odo_stats), run.truth);
    imp += 0.25 * test::mean_error(run_loop(improved_options(8), seed, run, &imp_stats), run.truth);
  }
  std::printf("\n  loop, 8 particles, seeds 1-4: odometry proposal %.3f m (%llu resamplings in seed 4), improved "
              "%.3f m (%llu)\n",
              odo, static_cast<unsigned long long>(odo_stats.resamplings), imp,
              static_cast<unsigned long long>(imp_stats.resamplings));
  CHECK(imp < odo);
  CHECK(imp < 0.08);
  CHECK(imp_stats.proposal_matched > imp_stats.processed);  // most particle-steps matched
  LONGS_EQUAL(0, odo_stats.proposal_matched);
  LONGS_EQUAL(0, odo_stats.proposal_evaluations);
}

TEST(ImprovedProposal, same_seed_gives_bit_identical_trajectories) {
  const test::SimRun run = test::make_loop();
  const std::vector<Pose2> a = run_loop(improved_options(6), 77, run);
  const std::vector<Pose2> b = run_loop(improved_options(6), 77, run);
  LONGS_EQUAL(a.size(), b.size());
  CHECK(std::memcmp(a.data(), b.data(), a.size() * sizeof(Pose2)) == 0);
}

TEST(ImprovedProposal, neighbourhood_weighting_also_tracks_the_loop) {
  const test::SimRun run = test::make_loop();
  DpSlamOptions o = improved_options(6);
  o.proposal_weight = DpSlamOptions::ProposalWeight::kNeighbourhood;
  const double err = test::mean_error(run_loop(o, 3, run), run.truth);
  CHECK(err < 0.1);
}

TEST(ImprovedProposal, failed_matches_fall_back_to_odometry_and_are_counted) {
  const test::SimRun run = test::make_loop();
  DpSlamOptions o = improved_options(4);
  o.match.min_beams = 1000U;  // the 181-beam scan never has enough at stride 4
  DpSlamStats s;
  run_loop(o, 1, run, &s);
  CHECK(s.processed > 50U);
  LONGS_EQUAL(0, s.proposal_matched);
  LONGS_EQUAL(4U * (s.processed - 1U), s.proposal_fallback_few_beams);
  o = improved_options(4);
  o.match.min_mean_log_likelihood = 0.0;  // no match is ever good enough
  run_loop(o, 1, run, &s);
  LONGS_EQUAL(0, s.proposal_matched);
  CHECK(s.proposal_fallback_low_score > 0U);
}

TEST(ImprovedProposal, along_a_plain_corridor_the_travel_is_the_odometrys_not_shortened) {
  // 12 m straight down plain_corridor(), 0.1 m per step, odometry with unbiased noise, a
  // laser with 1 cm range noise.
  // The map cannot tell how far the robot went; matching against it must not pull each
  // step towards the previous scan (a systematic shortening of every corridor).
  test::SimRun run;
  Rng rng(5);
  Pose2 odom{};
  for (int i = 0; i <= 120; ++i) {
    run.truth.push_back(Pose2{0.1 * i, 0.0, 0.0});
    if (i > 0) odom = odom.compose(Pose2{0.1 + rng.gaussian(0.003), rng.gaussian(0.002), rng.gaussian(0.002)});
    run.odom.push_back(odom);
  }
  // A pool that holds the corridor's map: what is measured is the matching, not a pool
  // running short (sim_options() sizes it for the room).
  DpSlamOptions o = improved_options(10);
  o.map_observations_base = 1000000U;
  for (std::uint64_t seed : {1U, 2U, 3U}) {
    DpSlamStats stats;
    const std::vector<Pose2> est = run_loop(o, seed, run, &stats, plain_corridor(), 0.01);
    LONGS_EQUAL(0, stats.map_writes_shortened);
    const double travel = est.back().x_m - est.front().x_m;
    std::printf("\n  seed %llu: truth 12.000 m, odometry %.3f m, estimate %.3f m",
                static_cast<unsigned long long>(seed), run.odom.back().x_m, travel);
    // Within 4 % of the odometry's travel; the likelihood alone comes out 30 % short.
    DOUBLES_EQUAL(run.odom.back().x_m, travel, 0.48);
  }
  std::printf("\n");
}
