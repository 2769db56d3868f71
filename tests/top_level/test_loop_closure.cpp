// LoopClosure (core/loops/loop_closure.h) through its own API, on submaps given by a fake
// owner (LoopSubmaps): a room seen by two submaps whose frames the chain placed metres
// apart. The wide search finds the revisit and records it, verified, and the pose graph
// then moves the drifted frame onto it; a revisit beyond the chain's drift is refused;
// one that needs more than half the search window is searched again around its peak,
// and kept only if no alias shows there; the top level's matches are
// refined and kept one per pair of levels, the best residual winning, but never over a
// verified peak they disagree with; a full store makes
// room with a record whose levels are gone; overlapping submaps beyond the candidate cap
// are counted; the newest level is searched first; nothing is searched without a window.
#include <cmath>
#include <cstdio>
#include <vector>

#include "CppUTest/TestHarness.h"
#include "sdpslam/core/box2.h"
#include "loops/loop_closure.h"
#include "sdpslam/core/sdp_profile.h"

using namespace sdpslam;

namespace {

// Wall points of a room 9 m × 6 m with a pillar and an alcove (no symmetry a search
// could confuse), every 0.1 m × `stride`, in the room's frame.
std::vector<Point2> room(std::size_t stride = 2) {
  std::vector<Point2> p;
  auto wall = [&](double x0, double y0, double x1, double y1) {
    const double len = std::hypot(x1 - x0, y1 - y0);
    const int n = static_cast<int>(len / 0.1);
    for (int k = 0; k <= n; ++k) {
      const double t = n > 0 ? static_cast<double>(k) / n : 0.0;
      p.push_back(Point2{x0 + t * (x1 - x0), y0 + t * (y1 - y0)});
    }
  };
  wall(0.0, 0.0, 9.0, 0.0);
  wall(9.0, 0.0, 9.0, 6.0);
  wall(9.0, 6.0, 4.0, 6.0);
  wall(4.0, 6.0, 4.0, 7.5);  // alcove
  wall(4.0, 7.5, 2.0, 7.5);
  wall(2.0, 7.5, 2.0, 6.0);
  wall(2.0, 6.0, 0.0, 6.0);
  wall(0.0, 6.0, 0.0, 0.0);
  wall(6.0, 2.0, 7.0, 2.0);  // pillar
  wall(7.0, 2.0, 7.0, 3.0);
  wall(7.0, 3.0, 6.0, 3.0);
  wall(6.0, 3.0, 6.0, 2.0);
  // At most loop_points (300) per submap.
  std::vector<Point2> thin;
  for (std::size_t k = 0; k < p.size(); k += stride) thin.push_back(p[k]);
  return thin;
}

// A corridor far from the room: 20 m of two parallel walls, 2 m apart.
std::vector<Point2> corridor(double x0_m) {
  std::vector<Point2> p;
  for (int k = 0; k <= 100; ++k) {
    p.push_back(Point2{x0_m + 0.2 * k, 40.0});
    p.push_back(Point2{x0_m + 0.2 * k, 42.0});
  }
  return p;
}

// The owner: levels 0 .. n-1, all held and live; each with its frame (as the chain
// placed it), its obstacle points and its box. The first `arrived` of them exist so far
// (segmentation adds levels one at a time).
struct Owner final : LoopSubmaps {
  struct Level {
    Pose2 frame;
    std::vector<Point2> points;
  };
  std::vector<Level> levels;
  std::uint32_t first_held = 0U;
  std::size_t arrived = SIZE_MAX;
  int verified = 0;
  bool node_index(std::uint32_t level, std::uint32_t* index) const override {
    if (level < first_held || level >= level_end()) return false;
    *index = level - first_held;
    return true;
  }
  std::uint32_t node_count() const override { return level_end() - first_held; }
  std::uint32_t first_held_level() const override { return first_held; }
  std::uint32_t first_live_level() const override { return first_held; }
  std::uint32_t level_end() const override {
    return static_cast<std::uint32_t>(arrived < levels.size() ? arrived : levels.size());
  }
  bool placement(std::uint32_t level, Pose2* frame, double box[4], std::uint32_t* count) const override {
    std::uint32_t index = 0U;
    if (!node_index(level, &index)) return false;
    const Level& l = levels[level];
    *frame = l.frame;
    box_init(box);
    for (const Point2& q : l.points) box_add(box, q.x_m, q.y_m);
    *count = static_cast<std::uint32_t>(l.points.size());
    return true;
  }
  void obstacles(std::uint32_t level, Point2* out) const override {
    for (std::size_t k = 0; k < levels[level].points.size(); ++k) out[k] = levels[level].points[k];
  }
  void on_verified_loop() override { ++verified; }
};

SdpOptions accurate() {
  DpSlamOptions bottom;
  SdpOptions top;
  apply_profile(SdpProfile::kAccurate, &bottom, &top);
  return top;
}

struct Rig {
  alignas(std::max_align_t) unsigned char buffer[8U << 20];
  Arena arena{buffer, sizeof buffer};
  Icp2d icp;
  Owner owner;
  LoopClosureStats stats;
  LoopClosure loops;
  SdpOptions options = accurate();
  bool init() {
    LoopSearchGeometry g;
    g.resolution_m = 0.1;
    g.grid_side = 260U;
    const std::uint32_t nodes = 16U;
    if (LoopClosure::required_bytes(options, nodes, g) > arena.available_bytes()) return false;
    return loops.init(options, nodes, g, &icp, &owner, &stats, arena);
  }
  // Search steps (one per processed scan).
  bool ran = false;
  void run(int steps) {
    ran = true;
    for (int k = 0; k < steps; ++k) loops.search_step();
  }
  // Levels 0 .. count-1 arrive one at a time, as segmentation adds them, and the search
  // runs after each until it has nothing left to do (bounded).
  void arrive_one_at_a_time(std::size_t count) {
    for (std::size_t shown = 1U; shown <= count; ++shown) {
      owner.arrived = shown;
      run(2000);
    }
  }
  // Runs the search until it has nothing left to do; on its first run the levels arrive
  // one at a time.
  void search_all() {
    if (!ran) arrive_one_at_a_time(owner.levels.size() - 1U);
    owner.arrived = SIZE_MAX;
    run(2000);
  }
};

// Points given in frame `from`, expressed in frame `to` (both in one parent frame).
std::vector<Point2> seen_from(const std::vector<Point2>& points, const Pose2& from, const Pose2& to) {
  std::vector<Point2> out;
  const Pose2 t = between(to, from);
  for (const Point2& q : points) {
    double x = 0.0, y = 0.0;
    t.transform_point(q.x_m, q.y_m, x, y);
    out.push_back(Point2{x, y});
  }
  return out;
}

double distance_m(const Pose2& a, const Pose2& b) { return std::hypot(a.x_m - b.x_m, a.y_m - b.y_m); }
double angle_rad(const Pose2& a, const Pose2& b) { return std::fabs(normalize_angle_rad(a.heading_rad - b.heading_rad)); }

// A record the wide search made between these levels, on the true relative frame.
void check_searched_record(const LoopClosure::Record& r, std::uint32_t older, std::uint32_t newer, const Pose2& truth) {
  CHECK_EQUAL(older, r.older_level);
  CHECK_EQUAL(newer, r.newer_level);
  CHECK_TRUE(r.searched);
  CHECK_TRUE(distance_m(r.z, truth) < 0.05);
  CHECK_TRUE(angle_rad(r.z, truth) < 0.01);
}

}  // namespace

TEST_GROUP(LoopClosure) {
  Rig* rig = nullptr;
  void setup() override { rig = new Rig(); }
  void teardown() override { delete rig; }
};

// Level 2 revisits level 0's room; the chain placed it 2 m and 0.1 rad from where it is.
TEST(LoopClosure, the_wide_search_finds_a_revisit_the_chain_placed_metres_off_and_the_graph_follows) {
  const Pose2 truth2{3.0, -1.0, 0.4};  // level 2's frame in level 0's (the room's)
  const Pose2 believed2 = truth2.compose(Pose2{2.0, 0.0, 0.1});
  Owner& o = rig->owner;
  o.levels.push_back({Pose2{}, room()});
  o.levels.push_back({Pose2{1.5, 20.0, 0.2}, corridor(0.0)});
  o.levels.push_back({believed2, seen_from(room(), Pose2{}, truth2)});  // the room in level 2's frame
  CHECK_TRUE(rig->init());
  rig->search_all();
  CHECK_EQUAL(1U, rig->loops.record_count());
  check_searched_record(rig->loops.record(0), 0U, 2U, truth2);
  CHECK_EQUAL(1, o.verified);
  CHECK_TRUE(rig->stats.loop_searches >= 1U);
  CHECK_EQUAL(1U, rig->stats.loop_search_closed);
  // The graph: the chain as the owner has it, then the loop.
  FrameGraph& g = rig->loops.begin_adjustment();
  const FrameInfo seg = FrameInfo::from_sigma(rig->options.segment_sigma_xy_m, rig->options.segment_sigma_theta_rad);
  for (std::size_t k = 0; k < o.levels.size(); ++k) {
    const Pose2 t = k > 0 ? between(o.levels[k - 1].frame, o.levels[k].frame) : Pose2{};
    CHECK_TRUE(g.add_node(o.levels[k].frame, t, seg));
  }
  CHECK_TRUE(rig->loops.finish_adjustment());
  CHECK_EQUAL(1U, rig->stats.loop_constraints_used);
  CHECK_EQUAL(1U, rig->stats.frame_adjustments);
  // Verified, so without a kernel: the loop moves level 2 most of the way from the
  // chain's 2 m (least squares leaves the chain's own information a share).
  const double after = distance_m(g.frame(2), truth2);
  std::printf("\n  level 2 after the solve: %.3f m from its true frame (chain: 2 m)\n", after);
  CHECK_TRUE(after < 0.3);
  DOUBLES_EQUAL(0.0, distance_m(g.frame(0), Pose2{}), 0.0);
}

// Level 3 revisits level 0's room, but the chain put it 5 m off: more than
// loop_search_drift_m × √hops (2 m × √3). The peak is refused, not recorded.
TEST(LoopClosure, a_revisit_beyond_the_chain_drift_is_refused) {
  const Pose2 truth3{2.0, 1.0, -0.3};
  Owner& o = rig->owner;
  o.levels.push_back({Pose2{}, room()});
  o.levels.push_back({Pose2{0.0, 60.0, 0.0}, corridor(30.0)});
  o.levels.push_back({Pose2{0.0, 30.0, 0.0}, corridor(0.0)});
  o.levels.push_back({truth3.compose(Pose2{5.0, 0.0, 0.05}), seen_from(room(), Pose2{}, truth3)});
  CHECK_TRUE(rig->init());
  rig->search_all();
  CHECK_EQUAL(1U, rig->stats.loop_search_far);
  CHECK_EQUAL(0U, rig->stats.loop_search_closed);
  CHECK_EQUAL(0U, rig->loops.record_count());
  CHECK_EQUAL(0, o.verified);
}

// Level 3 revisits level 0's room, the chain 5 m off (credible with loop_search_drift_m
// = 3 m: 5.2 m over √3 hops), more than half the 6 m window from where the chain puts
// it. The window centred on the chain's guess proves the peak unique only on its side;
// the pair is searched again centred on the peak, where it is unique too: recorded.
// Then level 0 holds a second copy of the room 5.5 m beside the first (an alias the
// first window could not see, but a window around the peak does): ambiguous, dropped.
TEST(LoopClosure, a_large_correction_is_searched_again_around_its_peak) {
  const Pose2 truth3{2.0, 1.0, -0.3};
  const Pose2 believed3 = truth3.compose(Pose2{5.0, 0.0, 0.05});
  auto build = [&](bool alias) {
    Owner& o = rig->owner;
    std::vector<Point2> older = room(alias ? 4U : 2U);
    if (alias) {
      const std::vector<Point2> copy = seen_from(older, Pose2{-5.5, 0.0, 0.0}, Pose2{});
      older.insert(older.end(), copy.begin(), copy.end());
    }
    o.levels.push_back({Pose2{}, older});
    o.levels.push_back({Pose2{0.0, 60.0, 0.0}, corridor(30.0)});
    o.levels.push_back({Pose2{0.0, 30.0, 0.0}, corridor(0.0)});
    o.levels.push_back({believed3, seen_from(room(), Pose2{}, truth3)});
    rig->options.loop_search_drift_m = 3.0;
    CHECK_TRUE(rig->init());
    rig->search_all();
  };
  build(false);
  CHECK_EQUAL(0U, rig->stats.loop_search_far);
  CHECK_EQUAL(1U, rig->stats.loop_search_recentred);
  CHECK_EQUAL(1U, rig->stats.loop_search_recentred_closed);
  CHECK_EQUAL(0U, rig->stats.loop_search_closed);  // each search has one outcome: recentred
  CHECK_EQUAL(1U, rig->loops.record_count());
  CHECK_EQUAL(1, rig->owner.verified);
  check_searched_record(rig->loops.record(0), 0U, 3U, truth3);

  delete rig;
  rig = new Rig();
  build(true);
  CHECK_EQUAL(1U, rig->stats.loop_search_recentred);
  CHECK_EQUAL(0U, rig->stats.loop_search_recentred_closed);
  CHECK_EQUAL(0U, rig->stats.loop_search_closed);
  CHECK_EQUAL(0U, rig->loops.record_count());
  CHECK_EQUAL(0, rig->owner.verified);
}

// The chain drifted 9 m between levels 0 and 3 and 4 (loop_search_drift_m = 6 m: up to
// 10.4 m over √3 hops), beyond the 6 m window. Without growth the search sees no room
// (weak), with loop_search_max_window_m the window grows to the drift bound and finds
// it; a peak that far is searched again around itself before it is kept.
TEST(LoopClosure, the_window_grows_to_the_chains_drift_bound) {
  const Pose2 truth3{2.0, 1.0, -0.3};
  const Pose2 truth4{1.0, 2.0, 0.2};
  const Pose2 off{9.0, 0.0, 0.05};
  const Pose2 believed3 = truth3.compose(off);
  auto build = [&](double max_window_m) {
    Owner& o = rig->owner;
    o.levels.push_back({Pose2{}, room()});
    o.levels.push_back({Pose2{0.0, 60.0, 0.0}, corridor(30.0)});
    o.levels.push_back({Pose2{0.0, 30.0, 0.0}, corridor(0.0)});
    o.levels.push_back({believed3, seen_from(room(), Pose2{}, truth3)});
    o.levels.push_back({believed3.compose(between(truth3, truth4)), seen_from(room(), Pose2{}, truth4)});
    rig->options.loop_search_drift_m = 6.0;
    rig->options.loop_search_max_window_m = max_window_m;
    CHECK_TRUE(rig->init());
    rig->search_all();
  };
  build(0.0);
  CHECK_EQUAL(0U, rig->stats.loop_search_recentred);
  CHECK_EQUAL(0U, rig->loops.record_count());
  CHECK_TRUE(rig->stats.loop_search_weak >= 2U);  // levels 3 and 4 against level 0
  delete rig;
  rig = new Rig();
  build(16.0);
  // Level 3's peak, searched again around itself. (Level 4 is then two hops from level 0
  // (that record, then the chain): its drift bound and window 8.5 m. This owner does not move
  // its frames after a verified loop, so it stays 9 m off and out of the window.)
  CHECK_EQUAL(1U, rig->stats.loop_search_recentred);
  CHECK_EQUAL(1U, rig->stats.loop_search_recentred_closed);
  CHECK_EQUAL(1U, rig->loops.record_count());
  const LoopClosure::Record& r = rig->loops.record(0);
  CHECK_EQUAL(0U, r.older_level);
  CHECK_EQUAL(3U, r.newer_level);
  CHECK_TRUE(distance_m(r.z, truth3) < 0.05);
}

// The chain put level 3 15.3 m from where it revisits level 0's room, farther than the
// room's box grown by loop_search_window_m (6 m) reaches, but within the drift bound
// (loop_search_drift_m = 9 m: 15.6 m over √3 hops) the pair's window grows to. The
// pair is a candidate because its own window is what grows the box: found (and, being
// more than half a window away, searched again around its peak before it is kept).
TEST(LoopClosure, a_submap_beyond_the_base_window_but_within_the_drift_bound_is_a_candidate) {
  const Pose2 truth3{2.0, 1.0, -0.3};
  Owner& o = rig->owner;
  o.levels.push_back({Pose2{}, room()});
  o.levels.push_back({Pose2{0.0, 60.0, 0.0}, corridor(30.0)});
  o.levels.push_back({Pose2{0.0, 30.0, 0.0}, corridor(0.0)});
  o.levels.push_back({truth3.compose(Pose2{15.3, 0.0, 0.05}), seen_from(room(), Pose2{}, truth3)});
  rig->options.loop_search_drift_m = 9.0;
  rig->options.loop_search_max_window_m = 16.0;
  CHECK_TRUE(rig->init());
  rig->search_all();
  CHECK_EQUAL(1U, rig->stats.loop_search_recentred_closed);
  CHECK_EQUAL(1U, rig->loops.record_count());
  check_searched_record(rig->loops.record(0), 0U, 3U, truth3);
}

// Four levels see the same room. Level 2 has one older candidate (level 0); level 3 has
// two (levels 0 and 1; the adjacent level 2 is never one). With loop_search_candidates =
// 1, level 3's second candidate is left unsearched and counted; with 2 every pair is
// searched and nothing is counted. Either way each overlapping pair is searched or
// counted, never silently skipped.
TEST(LoopClosure, overlapping_submaps_beyond_the_candidate_cap_are_counted) {
  auto build = [&](std::uint32_t cap) {
    Owner& o = rig->owner;
    for (int k = 0; k < 4; ++k) o.levels.push_back({Pose2{}, room()});
    rig->options.loop_search_candidates = cap;
    CHECK_TRUE(rig->init());
    rig->search_all();
  };
  build(1U);
  CHECK_EQUAL(2U, rig->stats.loop_searches);
  CHECK_EQUAL(1U, rig->stats.loop_search_candidates_dropped);
  CHECK_EQUAL(2U, rig->stats.loop_search_closed);
  delete rig;
  rig = new Rig();
  build(2U);
  CHECK_EQUAL(3U, rig->stats.loop_searches);
  CHECK_EQUAL(0U, rig->stats.loop_search_candidates_dropped);
  CHECK_EQUAL(3U, rig->stats.loop_search_closed);
  CHECK_EQUAL(0U, rig->stats.loop_search_levels_skipped);
}

namespace {
bool has_record(const LoopClosure& loops, std::uint32_t older, std::uint32_t newer) {
  for (std::uint32_t k = 0; k < loops.record_count(); ++k) {
    if (loops.record(k).older_level == older && loops.record(k).newer_level == newer) return true;
  }
  return false;
}
}  // namespace

// Newest level first. Seven levels see the same room. Level 3's search has started (its
// first candidate, level 0) when level 4 arrives: level 3's second candidate (level 1) is
// dropped, and level 4 is searched against all of its own. Then levels 5 and 6 arrive
// together, before the search had a turn: level 5 is passed over (counted) and level 6
// is searched.
TEST(LoopClosure, the_search_takes_the_newest_level_first) {
  Owner& o = rig->owner;
  for (int k = 0; k < 7; ++k) o.levels.push_back({Pose2{}, room()});
  CHECK_TRUE(rig->init());
  rig->arrive_one_at_a_time(3U);
  o.arrived = 4U;
  rig->run(1);  // level 3's first search starts
  CHECK_EQUAL(2U, rig->stats.loop_searches);  // level 2 against level 0, level 3 against level 0
  o.arrived = 5U;
  rig->run(2000);
  CHECK_EQUAL(1U, rig->stats.loop_search_candidates_dropped);
  CHECK_TRUE(has_record(rig->loops, 0U, 3U));
  CHECK_FALSE(has_record(rig->loops, 1U, 3U));
  for (std::uint32_t older = 0U; older <= 2U; ++older) CHECK_TRUE(has_record(rig->loops, older, 4U));
  CHECK_EQUAL(0U, rig->stats.loop_search_levels_skipped);
  o.arrived = 7U;
  rig->run(2000);
  CHECK_EQUAL(1U, rig->stats.loop_search_levels_skipped);
  for (std::uint32_t older = 0U; older <= 4U; ++older) {
    CHECK_FALSE(has_record(rig->loops, older, 5U));
    CHECK_TRUE(has_record(rig->loops, older, 6U));
  }
  CHECK_EQUAL(1U, rig->stats.loop_search_candidates_dropped);
}

// The top level's skeleton match, refined on obstacle points: one record per pair of
// levels, the lower residual wins; a match that moves the submap farther than
// loop_max_correction_m from its guess is not kept.
TEST(LoopClosure, refined_matches_are_kept_one_per_pair_of_levels) {
  Owner& o = rig->owner;
  for (int k = 0; k < 4; ++k) o.levels.push_back({Pose2{}, room()});
  CHECK_TRUE(rig->init());
  const std::vector<Point2> a = room();
  std::vector<Point2> b;
  const Pose2 z{0.3, -0.2, 0.05};
  for (const Point2& q : a) {
    double x = 0.0, y = 0.0;
    z.inverse().transform_point(q.x_m, q.y_m, x, y);
    b.push_back(Point2{x, y});
  }
  const auto n = static_cast<std::uint32_t>(a.size());
  rig->loops.refine(0U, a.data(), n, 2U, b.data(), n, z, z);
  CHECK_EQUAL(1U, rig->loops.record_count());
  CHECK_FALSE(rig->loops.record(0).searched);
  const double first_error = rig->loops.record(0).error_m;
  // The same pair with noisier points: the better record stays.
  std::vector<Point2> noisy = b;
  for (std::size_t k = 0; k < noisy.size(); ++k) noisy[k].x_m += (k % 2 == 0 ? 0.04 : -0.04);
  rig->loops.refine(0U, a.data(), n, 2U, noisy.data(), n, z, z);
  CHECK_EQUAL(1U, rig->loops.record_count());
  DOUBLES_EQUAL(first_error, rig->loops.record(0).error_m, 0.0);
  // A guess 2 m from the match: beyond loop_max_correction_m (1 m).
  rig->loops.refine(1U, a.data(), n, 3U, b.data(), n, z.compose(Pose2{2.0, 0.0, 0.0}), z);
  CHECK_EQUAL(1U, rig->loops.record_count());
  CHECK_EQUAL(3U, rig->stats.loop_refinements);
  // Too few points: not even tried.
  rig->loops.refine(1U, a.data(), 10U, 3U, b.data(), n, z, z);
  CHECK_EQUAL(3U, rig->stats.loop_refinements);
}

// A pair the wide search verified keeps its verified estimate against a top-level ICP
// match of the same pair that lies farther than a coarse block of the search's grid from
// it (a rival optimum, as a match that slid along a corridor is), however low that
// match's residual; an ICP match within the block is the same loop refined and replaces
// it, still verified. The other way round, a verified peak replaces a rival ICP record
// whatever the residuals.
TEST(LoopClosure, a_verified_loop_is_not_displaced_by_a_rival_icp_match) {
  const Pose2 truth2{3.0, -1.0, 0.4};
  const Pose2 rival2 = truth2.compose(Pose2{1.0, 0.0, 0.0});
  const std::vector<Point2> a = room();
  const auto n = static_cast<std::uint32_t>(a.size());
  const std::vector<Point2> exact = seen_from(a, Pose2{}, truth2);
  std::vector<Point2> jittered = exact;  // a residual of about 3 cm
  for (std::size_t k = 0; k < jittered.size(); ++k) jittered[k].x_m += (k % 2 == 0 ? 0.03 : -0.03);
  const std::vector<Point2> slid = seen_from(a, Pose2{}, rival2);  // fits perfectly at rival2
  auto build = [&] {
    Owner& o = rig->owner;
    o.levels.push_back({Pose2{}, a});
    o.levels.push_back({Pose2{1.5, 20.0, 0.2}, corridor(0.0)});
    o.levels.push_back({truth2.compose(Pose2{2.0, 0.0, 0.1}), jittered});
    CHECK_TRUE(rig->init());
  };
  build();
  rig->search_all();
  CHECK_EQUAL(1U, rig->loops.record_count());
  check_searched_record(rig->loops.record(0), 0U, 2U, truth2);
  const double verified_error = rig->loops.record(0).error_m;
  CHECK_TRUE(verified_error > 0.01);
  // The rival: 1 m from the verified peak, residual near 0. Refused and counted.
  rig->loops.refine(0U, a.data(), n, 2U, slid.data(), n, rival2, rival2);
  CHECK_EQUAL(1U, rig->loops.record_count());
  check_searched_record(rig->loops.record(0), 0U, 2U, truth2);
  DOUBLES_EQUAL(verified_error, rig->loops.record(0).error_m, 0.0);
  CHECK_EQUAL(1U, rig->stats.loop_rivals_refused);
  // The same loop, refined on better points: it replaces the record and stays verified.
  rig->loops.refine(0U, a.data(), n, 2U, exact.data(), n, truth2, truth2);
  CHECK_EQUAL(1U, rig->loops.record_count());
  check_searched_record(rig->loops.record(0), 0U, 2U, truth2);
  CHECK_TRUE(rig->loops.record(0).error_m < verified_error);
  CHECK_EQUAL(1U, rig->stats.loop_rivals_refused);

  // The rival recorded while the pair's search runs (in slices over scans): the
  // verified peak replaces it when the search ends.
  delete rig;
  rig = new Rig();
  rig->options.loop_search_reads_per_scan = 10000U;
  build();
  for (int k = 0; k < 10 && rig->stats.loop_searches == 0U; ++k) rig->run(1);  // the pair's search starts
  CHECK_EQUAL(1U, rig->stats.loop_searches);
  CHECK_EQUAL(0U, rig->stats.loop_search_closed);
  rig->loops.refine(0U, a.data(), n, 2U, slid.data(), n, rival2, rival2);
  CHECK_EQUAL(1U, rig->loops.record_count());
  CHECK_FALSE(rig->loops.record(0).searched);
  CHECK_TRUE(rig->loops.record(0).error_m < verified_error);
  rig->search_all();
  CHECK_EQUAL(1U, rig->loops.record_count());
  check_searched_record(rig->loops.record(0), 0U, 2U, truth2);
  CHECK_EQUAL(0U, rig->stats.loop_rivals_refused);
}

TEST(LoopClosure, a_full_store_makes_room_with_a_record_whose_levels_are_gone) {
  rig->options.max_loop_constraints = 2U;
  Owner& o = rig->owner;
  for (int k = 0; k < 6; ++k) o.levels.push_back({Pose2{}, room()});
  CHECK_TRUE(rig->init());
  const std::vector<Point2> a = room();
  const auto n = static_cast<std::uint32_t>(a.size());
  rig->loops.refine(0U, a.data(), n, 2U, a.data(), n, Pose2{}, Pose2{});
  rig->loops.refine(1U, a.data(), n, 3U, a.data(), n, Pose2{}, Pose2{});
  CHECK_EQUAL(2U, rig->loops.record_count());
  o.first_held = 1U;  // level 0 is forgotten: its record can never be used again
  rig->loops.refine(2U, a.data(), n, 4U, a.data(), n, Pose2{}, Pose2{});
  CHECK_EQUAL(2U, rig->loops.record_count());
  CHECK_EQUAL(0U, rig->stats.loop_records_dropped);
  bool has_24 = false, has_02 = false;
  for (std::uint32_t k = 0; k < 2U; ++k) {
    has_24 = has_24 || (rig->loops.record(k).older_level == 2U && rig->loops.record(k).newer_level == 4U);
    has_02 = has_02 || rig->loops.record(k).older_level == 0U;
  }
  CHECK_TRUE(has_24);
  CHECK_FALSE(has_02);
  // Full of live records, all as good as a new one: the new one is dropped and counted.
  rig->loops.refine(3U, a.data(), n, 5U, a.data(), n, Pose2{}, Pose2{});
  CHECK_EQUAL(1U, rig->stats.loop_records_dropped);
}

TEST(LoopClosure, nothing_is_searched_without_a_window_and_an_empty_graph_is_not_solved) {
  rig->options.loop_search_window_m = 0.0;
  Owner& o = rig->owner;
  for (int k = 0; k < 3; ++k) o.levels.push_back({Pose2{}, room()});
  CHECK_TRUE(rig->init());
  rig->search_all();
  CHECK_EQUAL(0U, rig->stats.loop_searches);
  FrameGraph& g = rig->loops.begin_adjustment();
  CHECK_TRUE(g.add_node(Pose2{}, Pose2{}, FrameInfo::from_sigma(0.1, 0.02)));
  CHECK_TRUE(g.add_node(Pose2{1.0, 0.0, 0.0}, Pose2{1.0, 0.0, 0.0}, FrameInfo::from_sigma(0.1, 0.02)));
  CHECK_FALSE(rig->loops.finish_adjustment());
  CHECK_EQUAL(0U, rig->stats.frame_adjustments);
  SdpOptions off = accurate();
  off.loop_closure = false;
  CHECK_EQUAL(0U, LoopClosure::required_bytes(off, 16U, LoopSearchGeometry{}));
}
