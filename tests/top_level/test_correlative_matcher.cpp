// CorrelativeMatcher (core/loops/correlative_matcher.h): the wide search behind loop closure.
// A scene displaced by metres (far outside ICP's basin) is found within a grid cell and
// a heading step; ICP from there lands on the truth; a corridor shifted along itself is
// ambiguous, unrelated shapes are weak; a partial overlap is judged on the points that
// overlap; bad input and a too-large grid are refused; the
// result is bit-identical across runs.
#include <cmath>
#include <cstring>
#include <vector>

#include "CppUTest/TestHarness.h"
#include "sdpslam/core/loops/correlative_matcher.h"
#include "top_level_fixtures.h"

using namespace sdpslam;

namespace {

alignas(std::max_align_t) unsigned char g_buffer[1U << 20U];

// A room of 8 m × 6 m with an inner wall, a doorway, a pillar and a stub: no symmetry.
std::vector<Point2> room(double spacing_m) {
  std::vector<Point2> v(4096);
  std::size_t n = 0U;
  n = test::add_segment(v.data(), n, v.size(), 0.0, 0.0, 8.0, 0.0, spacing_m);
  n = test::add_segment(v.data(), n, v.size(), 8.0, 0.0, 8.0, 6.0, spacing_m);
  n = test::add_segment(v.data(), n, v.size(), 8.0, 6.0, 2.0, 6.0, spacing_m);
  n = test::add_segment(v.data(), n, v.size(), 0.0, 6.0, 0.0, 0.0, spacing_m);
  n = test::add_segment(v.data(), n, v.size(), 3.0, 0.0, 3.0, 3.5, spacing_m);
  n = test::add_segment(v.data(), n, v.size(), 5.5, 4.0, 6.0, 4.0, spacing_m);
  n = test::add_segment(v.data(), n, v.size(), 6.0, 4.0, 6.0, 4.5, spacing_m);
  n = test::add_segment(v.data(), n, v.size(), 8.0, 2.0, 6.5, 2.0, spacing_m);
  v.resize(n);
  return v;
}

// Two parallel walls 2 m apart, 20 m long: any shift along them fits.
std::vector<Point2> corridor(double spacing_m) {
  std::vector<Point2> v(4096);
  std::size_t n = 0U;
  n = test::add_segment(v.data(), n, v.size(), 0.0, 0.0, 20.0, 0.0, spacing_m);
  n = test::add_segment(v.data(), n, v.size(), 0.0, 2.0, 20.0, 2.0, spacing_m);
  v.resize(n);
  return v;
}

// source = truth⁻¹ ⊕ target, with a deterministic ±jitter on every coordinate.
std::vector<Point2> displaced(const std::vector<Point2>& target, const Pose2& truth, double jitter_m) {
  std::vector<Point2> s(target.size());
  test::transform_points(truth.inverse(), target.data(), s.data(), target.size());
  for (std::size_t i = 0; i < s.size(); ++i) {
    s[i].x_m += jitter_m * (static_cast<double>((i * 7U) % 11U) / 5.0 - 1.0);
    s[i].y_m += jitter_m * (static_cast<double>((i * 5U) % 13U) / 6.0 - 1.0);
  }
  return s;
}

}  // namespace

TEST_GROUP(CorrelativeMatcher) {
  Arena* arena = nullptr;
  CorrelativeMatcher* matcher = nullptr;
  void setup() override {
    arena = new Arena(g_buffer, sizeof g_buffer);
    matcher = new CorrelativeMatcher();
    CHECK_TRUE(matcher->init(400U, 2048U, 64U, *arena));
  }
  void teardown() override {
    delete matcher;
    delete arena;
  }
};

TEST(CorrelativeMatcher, required_bytes_cover_init) {
  alignas(std::max_align_t) static unsigned char buf[600000];
  const std::size_t need = CorrelativeMatcher::required_bytes(300U, 500U, 31U);
  CHECK_TRUE(need <= sizeof buf);
  Arena a(buf, need);
  CorrelativeMatcher m;
  CHECK_TRUE(m.init(300U, 500U, 31U, a));
  Arena small(buf, need / 2U);
  CorrelativeMatcher m2;
  CHECK_FALSE(m2.init(300U, 500U, 31U, small));
  // A window wider than init's steps is refused, not overrun.
  CHECK_EQUAL(31U, CorrelativeMatcher::steps_for(6.0, 0.1, 4U));
  const std::vector<Point2> target = room(0.1);
  const auto n = static_cast<std::uint32_t>(target.size());
  CorrelativeOptions o;
  o.window_xy_m = 6.0;
  CHECK_TRUE(m.match(target.data(), n, target.data(), n, Pose2{}, o).found());
  o.window_xy_m = 6.5;
  CHECK_EQUAL(static_cast<int>(CorrelativeResult::Status::kTooLarge),
              static_cast<int>(m.match(target.data(), n, target.data(), n, Pose2{}, o).status));
}

TEST(CorrelativeMatcher, finds_a_displacement_of_metres_and_icp_polishes_it) {
  const std::vector<Point2> target = room(0.1);
  const Pose2 truth{2.1, -1.3, 0.2};  // far outside ICP's basin from the identity guess
  const std::vector<Point2> source = displaced(target, truth, 0.02);
  CorrelativeOptions o;
  o.window_xy_m = 3.0;
  o.window_theta_rad = 0.35;
  const CorrelativeResult r = matcher->match(target.data(), static_cast<std::uint32_t>(target.size()), source.data(),
                                             static_cast<std::uint32_t>(source.size()), Pose2{}, o);
  CHECK_TRUE(r.found());
  CHECK(r.score > 0.8);
  CHECK(r.second_score < o.max_ambiguity * r.score);
  DOUBLES_EQUAL(truth.x_m, r.transform.x_m, 0.15);
  DOUBLES_EQUAL(truth.y_m, r.transform.y_m, 0.15);
  DOUBLES_EQUAL(truth.heading_rad, r.transform.heading_rad, 0.02);
  // ICP alone from the guess does not get there; from the peak it does.
  Icp2d* icp = new Icp2d();
  Icp2dOptions io;
  io.max_correspondence_m = 0.3;
  io.nn_cell_m = 0.3;
  const Icp2dResult plain = icp->match(target.data(), target.size(), source.data(), source.size(), Pose2{}, io);
  CHECK_FALSE(plain.usable() && std::hypot(plain.transform.x_m - truth.x_m, plain.transform.y_m - truth.y_m) < 0.1);
  const Icp2dResult polished = icp->match(target.data(), target.size(), source.data(), source.size(), r.transform, io);
  CHECK_TRUE(polished.usable());
  DOUBLES_EQUAL(truth.x_m, polished.transform.x_m, 0.03);
  DOUBLES_EQUAL(truth.y_m, polished.transform.y_m, 0.03);
  DOUBLES_EQUAL(truth.heading_rad, polished.transform.heading_rad, 0.005);
  delete icp;
}

// Two submaps overlap in part: the source saw the room and, beyond it, a square the
// target never reached (as many points again, beyond the target's grid at every pose
// of the window). The pose
// is judged on the overlap, the room's points, and found as well as the room alone;
// with fewer overlapping points than min_overlap_points it is weak.
TEST(CorrelativeMatcher, a_source_that_saw_more_than_the_target_is_judged_on_the_overlap) {
  const std::vector<Point2> target = room(0.1);
  const Pose2 truth{1.2, -0.8, 0.1};
  std::vector<Point2> seen = target;
  // A 4 m square 4 m past the room's far wall, as many points as the room.
  const double side_m = 4.0;
  const std::size_t extra = target.size();
  for (std::size_t k = 0; k < extra; ++k) {
    const double t = 4.0 * side_m * static_cast<double>(k) / static_cast<double>(extra);
    const double a = t < side_m ? t : (t < 2.0 * side_m ? side_m : (t < 3.0 * side_m ? 3.0 * side_m - t : 0.0));
    const double b = t < side_m ? 0.0 : (t < 2.0 * side_m ? t - side_m : (t < 3.0 * side_m ? side_m : 4.0 * side_m - t));
    seen.push_back(Point2{12.0 + a, 1.0 + b});
  }
  const std::vector<Point2> source = displaced(seen, truth, 0.02);
  CorrelativeOptions o;
  o.window_xy_m = 2.0;
  o.window_theta_rad = 0.2;
  o.min_score = 0.6;  // more than the share of the source the room is (one half)
  o.min_overlap_points = static_cast<std::uint32_t>(target.size());
  const auto n_t = static_cast<std::uint32_t>(target.size());
  const auto n_s = static_cast<std::uint32_t>(source.size());
  CorrelativeResult r = matcher->match(target.data(), n_t, source.data(), n_s, Pose2{}, o);
  CHECK_TRUE(r.found());
  CHECK_EQUAL(target.size(), r.overlap_points);
  CHECK(r.score > 0.8);
  DOUBLES_EQUAL(truth.x_m, r.transform.x_m, 0.15);
  DOUBLES_EQUAL(truth.y_m, r.transform.y_m, 0.15);
  DOUBLES_EQUAL(truth.heading_rad, r.transform.heading_rad, 0.02);
  o.min_overlap_points = n_t + 1U;
  r = matcher->match(target.data(), n_t, source.data(), n_s, Pose2{}, o);
  CHECK_TRUE(r.status == CorrelativeResult::Status::kWeak);
}

TEST(CorrelativeMatcher, searches_around_the_guess) {
  const std::vector<Point2> target = room(0.1);
  const Pose2 truth{-6.0, 4.0, -1.2};
  const std::vector<Point2> source = displaced(target, truth, 0.0);
  // 1.8 m and 0.2 rad off; the window is about where the guess puts the source's
  // centroid, which is 3.45 m from where the truth puts it (the heading error swings it).
  const Pose2 guess{-4.5, 5.0, -1.0};
  CorrelativeOptions o;
  o.window_xy_m = 3.6;
  const CorrelativeResult r = matcher->match(target.data(), static_cast<std::uint32_t>(target.size()), source.data(),
                                             static_cast<std::uint32_t>(source.size()), guess, o);
  CHECK_TRUE(r.found());
  DOUBLES_EQUAL(truth.x_m, r.transform.x_m, 0.15);
  DOUBLES_EQUAL(truth.y_m, r.transform.y_m, 0.15);
  DOUBLES_EQUAL(truth.heading_rad, r.transform.heading_rad, 0.02);
}

TEST(CorrelativeMatcher, truth_outside_the_window_is_not_claimed) {
  const std::vector<Point2> target = room(0.1);
  const Pose2 truth{5.0, 0.0, 0.0};
  const std::vector<Point2> source = displaced(target, truth, 0.0);
  CorrelativeOptions o;
  o.window_xy_m = 1.0;
  o.min_score = 0.6;
  const CorrelativeResult r = matcher->match(target.data(), static_cast<std::uint32_t>(target.size()), source.data(),
                                             static_cast<std::uint32_t>(source.size()), Pose2{}, o);
  CHECK_FALSE(r.found());
  CHECK(r.score < 0.6);
}

TEST(CorrelativeMatcher, a_corridor_shifted_along_itself_is_ambiguous) {
  const std::vector<Point2> target = corridor(0.1);
  // The source sees 8 m of it; the truth is 1.5 m along.
  std::vector<Point2> part;
  for (const Point2& p : target) {
    if (p.x_m >= 6.0 && p.x_m <= 14.0) part.push_back(p);
  }
  const std::vector<Point2> source = displaced(part, Pose2{1.5, 0.0, 0.0}, 0.0);
  CorrelativeOptions o;
  o.window_xy_m = 3.0;
  const CorrelativeResult r = matcher->match(target.data(), static_cast<std::uint32_t>(target.size()), source.data(),
                                             static_cast<std::uint32_t>(source.size()), Pose2{}, o);
  CHECK_EQUAL(static_cast<int>(CorrelativeResult::Status::kAmbiguous), static_cast<int>(r.status));
  CHECK(r.score > 0.8);
  CHECK(r.second_score >= o.max_ambiguity * r.score);
}

TEST(CorrelativeMatcher, refuses_bad_input_and_counts_nothing_it_did_not_do) {
  const std::vector<Point2> target = room(0.1);
  const auto n = static_cast<std::uint32_t>(target.size());
  CorrelativeOptions o;
  CHECK_EQUAL(static_cast<int>(CorrelativeResult::Status::kTooFewPoints),
              static_cast<int>(matcher->match(target.data(), 2U, target.data(), n, Pose2{}, o).status));
  CHECK_EQUAL(static_cast<int>(CorrelativeResult::Status::kInvalidInput),
              static_cast<int>(matcher->match(nullptr, 10U, target.data(), n, Pose2{}, o).status));
  std::vector<Point2> bad = target;
  bad[3].x_m = std::nan("");
  CHECK_EQUAL(static_cast<int>(CorrelativeResult::Status::kInvalidInput),
              static_cast<int>(matcher->match(bad.data(), n, target.data(), n, Pose2{}, o).status));
  std::vector<Point2> many(3000U, Point2{1.0, 1.0});
  CHECK_EQUAL(static_cast<int>(CorrelativeResult::Status::kTooManyPoints),
              static_cast<int>(matcher->match(target.data(), n, many.data(), 3000U, Pose2{}, o).status));
  // 50 m of wall at 0.1 m cells needs a 500+ cell grid; init gave 400.
  std::vector<Point2> wide(600);
  const std::size_t nw = test::add_segment(wide.data(), 0U, wide.size(), 0.0, 0.0, 50.0, 0.0, 0.1);
  CorrelativeResult r = matcher->match(wide.data(), static_cast<std::uint32_t>(nw), target.data(), n, Pose2{}, o);
  CHECK_EQUAL(static_cast<int>(CorrelativeResult::Status::kTooLarge), static_cast<int>(r.status));
  CHECK_EQUAL(0U, r.poses_scored);
  CorrelativeOptions invalid;
  invalid.coarse_cells = 0U;
  CHECK_FALSE(invalid.valid());
  CHECK_EQUAL(static_cast<int>(CorrelativeResult::Status::kInvalidInput),
              static_cast<int>(matcher->match(target.data(), n, target.data(), n, Pose2{}, invalid).status));
  CorrelativeMatcher uninitialised;
  CHECK_EQUAL(static_cast<int>(CorrelativeResult::Status::kInvalidInput),
              static_cast<int>(uninitialised.match(target.data(), n, target.data(), n, Pose2{}, o).status));
}

TEST(CorrelativeMatcher, same_input_gives_the_same_bits) {
  const std::vector<Point2> target = room(0.1);
  const std::vector<Point2> source = displaced(target, Pose2{0.7, 1.9, -0.25}, 0.03);
  CorrelativeOptions o;
  const auto nt = static_cast<std::uint32_t>(target.size());
  const auto ns = static_cast<std::uint32_t>(source.size());
  const CorrelativeResult a = matcher->match(target.data(), nt, source.data(), ns, Pose2{0.1, 0.1, 0.0}, o);
  const CorrelativeResult b = matcher->match(target.data(), nt, source.data(), ns, Pose2{0.1, 0.1, 0.0}, o);
  CHECK_TRUE(a.found());
  CHECK_EQUAL(0, std::memcmp(&a.transform, &b.transform, sizeof a.transform));
  CHECK_EQUAL(0, std::memcmp(&a.score, &b.score, sizeof a.score));
  CHECK_EQUAL(a.poses_scored, b.poses_scored);
  // In slices of 3 headings: the same result.
  CHECK_TRUE(matcher->begin(target.data(), nt, source.data(), ns, Pose2{0.1, 0.1, 0.0}, o));
  CHECK_TRUE(matcher->active());
  CHECK(matcher->heading_cost() > 0U);
  int calls = 0;
  while (!matcher->advance(3U)) ++calls;
  CHECK(calls > 2);
  const CorrelativeResult c = matcher->finish();
  CHECK_FALSE(matcher->active());
  CHECK_EQUAL(static_cast<int>(a.status), static_cast<int>(c.status));
  CHECK_EQUAL(0, std::memcmp(&a.transform, &c.transform, sizeof a.transform));
  CHECK_EQUAL(0, std::memcmp(&a.score, &c.score, sizeof a.score));
  CHECK_EQUAL(0, std::memcmp(&a.second_score, &c.second_score, sizeof a.second_score));
  CHECK_EQUAL(a.poses_scored, c.poses_scored);
  // A refused begin leaves its verdict in result().
  CHECK_FALSE(matcher->begin(target.data(), 2U, source.data(), ns, Pose2{}, o));
  CHECK_EQUAL(static_cast<int>(CorrelativeResult::Status::kTooFewPoints), static_cast<int>(matcher->result().status));
  CHECK_FALSE(matcher->active());
}
