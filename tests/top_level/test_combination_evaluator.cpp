// A combination's ICP error (paper Algorithm 1 line 11) through its own API: which
// pairs are matched, the error of a gross misalignment, permanent submaps, the memo.
#include <CppUTest/TestHarness.h>

#include <cstdint>

#include "sdpslam/core/arena.h"
#include "sdpslam/core/box2.h"
#include "top/combination_evaluator.h"
#include "top/submap_store.h"
#include "top_level_fixtures.h"

using sdpslam::Arena;
using sdpslam::CombinationEvaluator;
using sdpslam::CombinationOptions;
using sdpslam::CombinationResult;
using sdpslam::Point2;
using sdpslam::Pose2;
using sdpslam::Submap;
using sdpslam::SubmapStore;
using sdpslam::SubmapStoreOptions;

namespace {

alignas(16) unsigned char g_buffer[512U * 1024U];
sdpslam::Icp2d g_icp;
CombinationResult g_result;

constexpr std::uint32_t kPoints = 160U;

struct Rig {
  Arena arena{g_buffer, sizeof g_buffer};
  SubmapStore store;
  CombinationEvaluator evaluator;
  explicit Rig(std::uint32_t max_pairs = 6U) {
    SubmapStoreOptions so;
    so.max_levels = 4U;
    so.nodes = 2U;
    so.skeleton_points = kPoints;
    so.max_permanent = 4U;
    CHECK_TRUE(store.init(so, arena));
    CombinationOptions co;
    co.max_pairs = max_pairs;
    co.min_overlap_m2 = 0.5;
    CHECK_TRUE(evaluator.init(co, &g_icp, arena));
  }
  // Level `level`'s submap `node`: the structured scene, moved by `shift` in its own
  // frame, its box the points' bounds.
  void put(std::uint32_t level, std::uint32_t node, const Pose2& shift = Pose2{}) {
    Point2 scene[kPoints];
    const std::size_t n = sdpslam::test::structured_scene(scene, kPoints, 0.1);
    Submap& sm = store.submap(level, node);
    sm = Submap{};
    sm.skeleton_done = true;
    sm.point_count = static_cast<std::uint32_t>(n);
    sdpslam::test::transform_points(shift, scene, store.points(level, node), n);
    sdpslam::box_init(sm.box);
    for (std::size_t i = 0; i < n; ++i) sdpslam::box_add(sm.box, store.points(level, node)[i].x_m, store.points(level, node)[i].y_m);
    store.level(level).count = 2U;
  }
};

}  // namespace

TEST_GROUP(CombinationEvaluator){};

TEST(CombinationEvaluator, non_adjacent_overlapping_submaps_are_matched_and_memoised) {
  Rig rig;
  for (std::uint32_t level = 0; level < 3U; ++level) rig.put(level, 0U);
  const std::uint32_t chain[3] = {0U, 0U, 0U};
  const Pose2 frames[3] = {};
  rig.evaluator.evaluate(rig.store, 0U, chain, frames, 3U, &g_result);
  CHECK_TRUE(g_result.measured);
  CHECK(g_result.error_m < 1e-6);
  LONGS_EQUAL(0U, g_result.lo_level);
  LONGS_EQUAL(2U, g_result.hi_level);
  LONGS_EQUAL(1U, g_result.icp_matches);  // (0, 2) only: 0-1 and 1-2 are adjacent
  LONGS_EQUAL(1U, g_result.match_count);
  CHECK_FALSE(g_result.matches[0].older_permanent);
  LONGS_EQUAL(0U, g_result.matches[0].older);
  LONGS_EQUAL(2U, g_result.matches[0].newer);
  const double first_error = g_result.error_m;
  // The same pair placed the same way again: from the memo, no fresh match.
  rig.evaluator.evaluate(rig.store, 0U, chain, frames, 3U, &g_result);
  LONGS_EQUAL(1U, g_result.memo_hits);
  LONGS_EQUAL(0U, g_result.icp_matches);
  LONGS_EQUAL(0U, g_result.match_count);
  DOUBLES_EQUAL(first_error, g_result.error_m, 0.0);
  // Placed differently: matched afresh from the chain's guess, at a higher error.
  const Pose2 moved[3] = {Pose2{}, Pose2{}, Pose2{0.1, -0.05, 0.02}};
  rig.evaluator.evaluate(rig.store, 0U, chain, moved, 3U, &g_result);
  LONGS_EQUAL(1U, g_result.icp_matches);
  const Pose2& guess = g_result.matches[0].guess;
  DOUBLES_EQUAL(0.1, guess.x_m, 1e-12);
  DOUBLES_EQUAL(-0.05, guess.y_m, 1e-12);
  DOUBLES_EQUAL(0.02, guess.heading_rad, 1e-12);
  CHECK(g_result.error_m > first_error + 0.01);
}

TEST(CombinationEvaluator, a_chain_of_adjacent_submaps_is_not_measured) {
  Rig rig;
  rig.put(0U, 0U);
  rig.put(1U, 0U);
  const std::uint32_t chain[2] = {0U, 0U};
  const Pose2 frames[2] = {};
  rig.evaluator.evaluate(rig.store, 0U, chain, frames, 2U, &g_result);
  CHECK_FALSE(g_result.measured);
  LONGS_EQUAL(0U, g_result.icp_matches);
  LONGS_EQUAL(0U, g_result.match_count);
}

TEST(CombinationEvaluator, overlapping_boxes_without_correspondences_count_the_rejection_distance) {
  Rig rig;
  rig.put(0U, 0U);
  rig.put(1U, 0U);
  rig.put(2U, 0U, Pose2{0.0, 10.0, 0.0});
  // Its box claims the place of level 0's: a gross misalignment, not "no overlap".
  for (int i = 0; i < 4; ++i) rig.store.submap(2U, 0U).box[i] = rig.store.submap(0U, 0U).box[i];
  const std::uint32_t chain[3] = {0U, 0U, 0U};
  const Pose2 frames[3] = {};
  rig.evaluator.evaluate(rig.store, 0U, chain, frames, 3U, &g_result);
  CHECK_TRUE(g_result.measured);
  LONGS_EQUAL(1U, g_result.icp_failures);
  LONGS_EQUAL(0U, g_result.match_count);
  DOUBLES_EQUAL(rig.evaluator.options().icp.max_correspondence_m, g_result.error_m, 1e-12);
}

TEST(CombinationEvaluator, a_permanent_submap_is_matched_as_the_older_one) {
  Rig rig;
  rig.put(0U, 1U);
  bool forgot = false;
  const std::uint32_t slot = rig.store.make_permanent(0U, 1U, &forgot);
  rig.store.permanent(slot).frame_in_global = Pose2{};
  for (std::uint32_t level = 1U; level < 4U; ++level) rig.put(level, 0U);
  const std::uint32_t chain[3] = {0U, 0U, 0U};
  const Pose2 frames[3] = {};
  rig.evaluator.evaluate(rig.store, 1U, chain, frames, 3U, &g_result);
  // Pairs: (permanent 0, level 2), (permanent 0, level 3), (level 1, level 3).
  LONGS_EQUAL(3U, g_result.match_count);
  std::uint32_t permanent = 0U;
  for (std::uint32_t k = 0; k < g_result.match_count; ++k) {
    if (!g_result.matches[k].older_permanent) continue;
    ++permanent;
    LONGS_EQUAL(0U, g_result.matches[k].older_level);
    LONGS_EQUAL(slot, g_result.matches[k].older);
  }
  LONGS_EQUAL(2U, permanent);
  // The PGS edges measured: the live levels only.
  LONGS_EQUAL(1U, g_result.lo_level);
  LONGS_EQUAL(3U, g_result.hi_level);
}

TEST(CombinationEvaluator, only_the_largest_overlaps_are_matched) {
  Rig rig(1U);
  rig.put(0U, 1U);
  bool forgot = false;
  rig.store.permanent(rig.store.make_permanent(0U, 1U, &forgot)).frame_in_global = Pose2{};
  for (std::uint32_t level = 1U; level < 4U; ++level) rig.put(level, 0U);
  const std::uint32_t chain[3] = {0U, 0U, 0U};
  const Pose2 frames[3] = {Pose2{}, Pose2{}, Pose2{1.0, 0.5, 0.0}};  // level 3 overlaps less
  rig.evaluator.evaluate(rig.store, 1U, chain, frames, 3U, &g_result);
  LONGS_EQUAL(1U, g_result.match_count);
  CHECK_TRUE(g_result.matches[0].older_permanent);
  LONGS_EQUAL(1U, g_result.matches[0].newer);  // level 2, wholly over the permanent one
}

TEST(CombinationEvaluator, init_refuses_invalid_options) {
  Arena arena(g_buffer, sizeof g_buffer);
  CombinationEvaluator evaluator;
  CombinationOptions o;
  o.max_pairs = 0U;
  CHECK_FALSE(evaluator.init(o, &g_icp, arena));
  o.max_pairs = CombinationOptions::kMaxPairs + 1U;
  CHECK_FALSE(evaluator.init(o, &g_icp, arena));
  o.max_pairs = 6U;
  CHECK_FALSE(evaluator.init(o, nullptr, arena));
  Arena small(g_buffer, CombinationEvaluator::required_bytes() - 1U);
  CHECK_FALSE(evaluator.init(o, &g_icp, small));
  CHECK_TRUE(evaluator.init(o, &g_icp, arena));
  CHECK(CombinationOptions::from(sdpslam::SdpOptions{}).valid());
}
