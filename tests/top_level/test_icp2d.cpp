// 2D point-to-point ICP: recovery of known transforms, the mean nearest-neighbour error
// (the paper's "ICP nearest neighbour error"), overlap and input failures, and the
// direction information of a pairing (corridor vs room).
#include <CppUTest/TestHarness.h>

#include <cmath>
#include <cstring>
#include <initializer_list>
#include <limits>

#include "sdpslam/core/top/icp2d.h"
#include "top_level_fixtures.h"

using sdpslam::Icp2d;
using sdpslam::Icp2dOptions;
using sdpslam::Icp2dResult;
using sdpslam::Point2;
using sdpslam::Pose2;
namespace cap = sdpslam::capacity;

namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

Icp2d g_icp;  // ~90 KiB: static storage, as the header asks
Point2 g_target[cap::kMaxIcpPoints + 1];
Point2 g_source[cap::kMaxIcpPoints + 1];

// Target: the scene sampled every 2 cm. Source: the same scene sampled independently
// (every 7 cm, as two submaps' skeletons are), placed so that truth ⊕ source lies on the
// target (ICP should return truth). Returns the source count; *target_count gets the
// target count. Identical samplings are avoided on purpose: point-to-point ICP can
// stick in a pairing shifted by one sample when both sets share the same samples.
std::size_t make_pair_sets(const Pose2& truth, std::size_t* target_count) {
  *target_count = sdpslam::test::structured_scene(g_target, cap::kMaxIcpPoints, 0.02);
  static Point2 scene[cap::kMaxIcpPoints];
  const std::size_t m = sdpslam::test::structured_scene(scene, cap::kMaxIcpPoints, 0.07);
  sdpslam::test::transform_points(truth.inverse(), scene, g_source, m);
  return m;
}

void check_pose_near(const Pose2& expected, const Pose2& actual, double tol_m, double tol_rad) {
  DOUBLES_EQUAL(expected.x_m, actual.x_m, tol_m);
  DOUBLES_EQUAL(expected.y_m, actual.y_m, tol_m);
  DOUBLES_EQUAL(0.0, sdpslam::normalize_angle_rad(expected.heading_rad - actual.heading_rad), tol_rad);
}

Icp2dOptions wide_options() {
  Icp2dOptions o;
  o.max_correspondence_m = 1.0;
  o.max_iterations = 100U;
  return o;
}

}  // namespace

TEST_GROUP(Icp2d){};

TEST(Icp2d, recovers_known_rotation_and_translation_of_l_shape_and_corridor) {
  const Pose2 truth{0.30, -0.20, 8.0 * kDeg};
  std::size_t nt = 0U;
  const std::size_t n = make_pair_sets(truth, &nt);
  const Icp2dResult r = g_icp.match(g_target, nt, g_source, n, Pose2{}, wide_options());
  CHECK_TRUE(r.usable());
  CHECK_TRUE(r.converged);
  check_pose_near(truth, r.transform, 0.01, 0.2 * kDeg);
  CHECK(r.mean_nn_error_m < 0.006);  // at most half the 2 cm target spacing, on average less
  LONGS_EQUAL(n, r.matched_pairs);
}

TEST(Icp2d, recovers_negative_rotation_from_an_initial_guess) {
  const Pose2 truth{-1.2, 0.9, -25.0 * kDeg};
  std::size_t nt = 0U;
  const std::size_t n = make_pair_sets(truth, &nt);
  const Pose2 guess{-1.0, 0.7, -20.0 * kDeg};  // odometry-like prior, off by ~0.3 m / 5°
  const Icp2dResult r = g_icp.match(g_target, nt, g_source, n, guess, wide_options());
  CHECK_TRUE(r.converged);
  check_pose_near(truth, r.transform, 0.01, 0.2 * kDeg);
}

TEST(Icp2d, identical_sets_have_zero_mean_nn_error_and_identity_transform) {
  const std::size_t n = sdpslam::test::structured_scene(g_target, cap::kMaxIcpPoints, 0.05);
  const Icp2dResult r = g_icp.match(g_target, n, g_target, n, Pose2{}, Icp2dOptions{});
  CHECK_TRUE(r.status == Icp2dResult::Status::kConverged);
  DOUBLES_EQUAL(0.0, r.mean_nn_error_m, 1e-12);
  DOUBLES_EQUAL(0.0, r.rms_nn_error_m, 1e-12);
  check_pose_near(Pose2{}, r.transform, 1e-12, 1e-12);
  DOUBLES_EQUAL(1.0, r.overlap_fraction, 0.0);
  LONGS_EQUAL(1, r.iterations);
}

TEST(Icp2d, mean_nn_error_of_noisy_copy_is_about_the_noise_level) {
  const double sigma_m = 0.02;
  const Pose2 truth{0.10, 0.05, 3.0 * kDeg};
  std::size_t nt = 0U;
  const std::size_t n = make_pair_sets(truth, &nt);  // dense target: NN error ~ noise
  sdpslam::test::SplitMix64 rng(7U);
  for (std::size_t i = 0; i < n; ++i) {
    g_source[i].x_m += sigma_m * rng.normal();
    g_source[i].y_m += sigma_m * rng.normal();
  }
  const Icp2dResult r = g_icp.match(g_target, nt, g_source, n, Pose2{}, wide_options());
  CHECK_TRUE(r.usable());
  // Against a dense wall only the across-wall component counts: E|N(0, σ)| = 0.8 σ.
  CHECK(r.mean_nn_error_m > 0.5 * sigma_m);
  CHECK(r.mean_nn_error_m < 1.2 * sigma_m);
  check_pose_near(truth, r.transform, 0.01, 0.3 * kDeg);
}

TEST(Icp2d, mean_nn_error_grows_with_the_noise_level) {
  const Pose2 truth{0.0, 0.0, 0.0};
  double previous = -1.0;
  for (double sigma_m : {0.0, 0.01, 0.03, 0.06}) {
    std::size_t nt = 0U;
    const std::size_t n = make_pair_sets(truth, &nt);
    sdpslam::test::SplitMix64 rng(11U);
    for (std::size_t i = 0; i < n; ++i) {
      g_source[i].x_m += sigma_m * rng.normal();
      g_source[i].y_m += sigma_m * rng.normal();
    }
    const Icp2dResult r = g_icp.match(g_target, nt, g_source, n, Pose2{}, wide_options());
    CHECK_TRUE(r.usable());
    CHECK(r.mean_nn_error_m > previous);
    previous = r.mean_nn_error_m;
  }
}

TEST(Icp2d, partial_overlap_recovers_transform_and_reports_overlap_fraction) {
  const Pose2 truth{0.25, 0.15, -6.0 * kDeg};
  std::size_t nt = 0U;
  const std::size_t n = make_pair_sets(truth, &nt);
  // The last 30 % of the source is replaced by a wall 20 m away that the target lacks.
  const std::size_t keep = n * 7U / 10U;
  const std::size_t total = sdpslam::test::add_segment(g_source, keep, n, 20.0, 20.0, 20.0, 40.0, 0.05);
  LONGS_EQUAL(n, total);
  const Icp2dResult r = g_icp.match(g_target, nt, g_source, total, Pose2{}, wide_options());
  CHECK_TRUE(r.converged);
  check_pose_near(truth, r.transform, 0.01, 0.2 * kDeg);
  LONGS_EQUAL(keep, r.matched_pairs);
  DOUBLES_EQUAL(static_cast<double>(keep) / static_cast<double>(total), r.overlap_fraction, 1e-12);
  CHECK(r.mean_nn_error_m < 0.006);
}

TEST(Icp2d, disjoint_sets_are_insufficient_overlap_not_a_good_match) {
  const std::size_t n = sdpslam::test::structured_scene(g_target, cap::kMaxIcpPoints, 0.05);
  sdpslam::test::transform_points(Pose2{50.0, 0.0, 0.0}, g_target, g_source, n);
  const Icp2dResult r = g_icp.match(g_target, n, g_source, n, Pose2{}, wide_options());
  CHECK_TRUE(r.status == Icp2dResult::Status::kInsufficientOverlap);
  CHECK_FALSE(r.usable());
  CHECK_FALSE(r.converged);
  CHECK_TRUE(std::isinf(r.mean_nn_error_m));
  LONGS_EQUAL(0, r.matched_pairs);
}

TEST(Icp2d, too_few_points_is_refused) {
  const std::size_t n = sdpslam::test::structured_scene(g_target, cap::kMaxIcpPoints, 0.05);
  Icp2dOptions o;
  o.min_pairs = 10U;
  const std::uint32_t failed_before = g_icp.failed_match_count();
  const Icp2dResult r = g_icp.match(g_target, n, g_target, 9U, Pose2{}, o);
  CHECK_TRUE(r.status == Icp2dResult::Status::kTooFewPoints);
  CHECK_TRUE(std::isinf(r.mean_nn_error_m));
  LONGS_EQUAL(failed_before + 1U, g_icp.failed_match_count());
  const Icp2dResult empty = g_icp.match(g_target, 0U, g_target, n, Pose2{}, o);
  CHECK_TRUE(empty.status == Icp2dResult::Status::kTooFewPoints);
}

TEST(Icp2d, more_points_than_capacity_is_refused) {
  for (std::size_t i = 0; i <= cap::kMaxIcpPoints; ++i) g_source[i] = Point2{0.01 * static_cast<double>(i), 0.0};
  const Icp2dResult r = g_icp.match(g_source, cap::kMaxIcpPoints + 1U, g_source, 100U, Pose2{}, Icp2dOptions{});
  CHECK_TRUE(r.status == Icp2dResult::Status::kTooManyPoints);
  const Icp2dResult full = g_icp.match(g_source, cap::kMaxIcpPoints, g_source, cap::kMaxIcpPoints, Pose2{}, Icp2dOptions{});
  CHECK_TRUE(full.usable());
  LONGS_EQUAL(cap::kMaxIcpPoints, full.matched_pairs);
}

TEST(Icp2d, non_finite_coordinates_and_null_arrays_are_invalid_input) {
  const std::size_t n = sdpslam::test::structured_scene(g_target, cap::kMaxIcpPoints, 0.05);
  std::memcpy(g_source, g_target, n * sizeof(Point2));
  g_source[3].y_m = std::numeric_limits<double>::quiet_NaN();
  CHECK_TRUE(g_icp.match(g_target, n, g_source, n, Pose2{}, Icp2dOptions{}).status ==
             Icp2dResult::Status::kInvalidInput);
  g_source[3].y_m = 2.0e6;  // beyond the documented coordinate range
  CHECK_TRUE(g_icp.match(g_target, n, g_source, n, Pose2{}, Icp2dOptions{}).status ==
             Icp2dResult::Status::kInvalidInput);
  CHECK_TRUE(g_icp.match(nullptr, n, g_target, n, Pose2{}, Icp2dOptions{}).status ==
             Icp2dResult::Status::kInvalidInput);
}

TEST(Icp2d, out_of_range_options_are_refused) {
  const std::size_t n = sdpslam::test::structured_scene(g_target, cap::kMaxIcpPoints, 0.05);
  Icp2dOptions o;
  o.min_pairs = 1U;
  CHECK_FALSE(o.valid());
  CHECK_TRUE(g_icp.match(g_target, n, g_target, n, Pose2{}, o).status == Icp2dResult::Status::kInvalidOptions);
  o = Icp2dOptions{};
  o.shrink_factor = 0.0;
  CHECK_FALSE(o.valid());
  o = Icp2dOptions{};
  o.min_correspondence_m = 2.0 * o.max_correspondence_m;
  CHECK_FALSE(o.valid());
  o = Icp2dOptions{};
  o.nn_cell_m = 1e-4;  // hash cells that small would overflow their indices
  CHECK_FALSE(o.valid());
  o = Icp2dOptions{};
  o.max_correspondence_m = 200.0;  // 2000 rings of 0.1 m cells: unbounded search cost
  CHECK_FALSE(o.valid());
  CHECK_TRUE(Icp2dOptions{}.valid());
}

TEST(Icp2d, pairs_beyond_max_correspondence_are_rejected) {
  // A wall, and a source made of the same wall plus 20 points 0.3 m off it.
  std::size_t n = sdpslam::test::add_segment(g_target, 0U, cap::kMaxIcpPoints, 0.0, 0.0, 4.0, 0.0, 0.05);
  n = sdpslam::test::add_segment(g_target, n, cap::kMaxIcpPoints, 0.0, 0.0, 0.0, 2.0, 0.05);
  std::memcpy(g_source, g_target, n * sizeof(Point2));
  const std::size_t total = sdpslam::test::add_segment(g_source, n, n + 20U, 1.0, 0.3, 2.0, 0.3, 0.05);
  LONGS_EQUAL(n + 20U, total);
  Icp2dOptions gate;
  gate.max_correspondence_m = 0.2;
  gate.min_correspondence_m = 0.2;
  const Icp2dResult r = g_icp.match(g_target, n, g_source, total, Pose2{}, gate);
  CHECK_TRUE(r.converged);
  LONGS_EQUAL(n, r.matched_pairs);
  DOUBLES_EQUAL(0.0, r.mean_nn_error_m, 1e-12);
  check_pose_near(Pose2{}, r.transform, 1e-12, 1e-12);
  // With a 0.5 m gate the off-wall points pair too and show up in the error.
  gate.max_correspondence_m = 0.5;
  const Icp2dResult loose = g_icp.match(g_target, n, g_source, total, Pose2{}, gate);
  LONGS_EQUAL(total, loose.matched_pairs);
  CHECK(loose.mean_nn_error_m > 0.01);
}

TEST(Icp2d, shrinking_gate_still_converges_to_the_truth) {
  const Pose2 truth{0.2, 0.1, 5.0 * kDeg};
  std::size_t nt = 0U;
  const std::size_t n = make_pair_sets(truth, &nt);
  Icp2dOptions o = wide_options();
  o.shrink_factor = 0.8;
  o.min_correspondence_m = 0.1;
  const Icp2dResult r = g_icp.match(g_target, nt, g_source, n, Pose2{}, o);
  CHECK_TRUE(r.converged);
  check_pose_near(truth, r.transform, 0.01, 0.2 * kDeg);
}

TEST(Icp2d, one_iteration_budget_reports_max_iterations_with_a_usable_estimate) {
  const Pose2 truth{0.3, -0.2, 8.0 * kDeg};
  std::size_t nt = 0U;
  const std::size_t n = make_pair_sets(truth, &nt);
  Icp2dOptions o = wide_options();
  o.max_iterations = 1U;
  const Icp2dResult r = g_icp.match(g_target, nt, g_source, n, Pose2{}, o);
  CHECK_TRUE(r.status == Icp2dResult::Status::kMaxIterations);
  CHECK_TRUE(r.usable());
  CHECK_FALSE(r.converged);
  LONGS_EQUAL(1, r.iterations);
  CHECK(std::isfinite(r.mean_nn_error_m));
}

TEST(Icp2d, nearest_neighbour_error_equals_brute_force_for_any_cell_size) {
  // Random clouds: the grid-hash ring search must find exactly the brute-force nearest
  // neighbour within the gate, whatever the cell size.
  sdpslam::test::SplitMix64 rng(42U);
  const std::size_t n = 600U;
  for (std::size_t i = 0; i < n; ++i) {
    g_target[i] = Point2{8.0 * rng.uniform() - 4.0, 6.0 * rng.uniform() - 3.0};
    g_source[i] = Point2{8.0 * rng.uniform() - 4.0, 6.0 * rng.uniform() - 3.0};
  }
  for (double cell_m : {0.01, 0.07, 0.3, 1.0, 5.0}) {
    Icp2dOptions o;
    o.max_iterations = 1U;
    o.max_correspondence_m = 0.25;
    o.min_correspondence_m = 0.25;
    o.nn_cell_m = cell_m;
    const Icp2dResult r = g_icp.match(g_target, n, g_source, n, Pose2{}, o);
    CHECK_TRUE(r.usable());
    const double c = std::cos(r.transform.heading_rad);
    const double s = std::sin(r.transform.heading_rad);
    double sum = 0.0;
    std::uint32_t matched = 0U;
    for (std::size_t i = 0; i < n; ++i) {
      const double px = r.transform.x_m + c * g_source[i].x_m - s * g_source[i].y_m;
      const double py = r.transform.y_m + s * g_source[i].x_m + c * g_source[i].y_m;
      double best = std::numeric_limits<double>::infinity();
      for (std::size_t j = 0; j < n; ++j) {
        best = std::fmin(best, std::hypot(g_target[j].x_m - px, g_target[j].y_m - py));
      }
      if (best <= 0.25) {
        sum += best;
        ++matched;
      }
    }
    LONGS_EQUAL(matched, r.matched_pairs);
    DOUBLES_EQUAL(sum / matched, r.mean_nn_error_m, 1e-9);
  }
}

TEST(Icp2d, same_input_gives_bit_identical_results_across_objects) {
  const Pose2 truth{0.3, -0.2, 8.0 * kDeg};
  std::size_t nt = 0U;
  const std::size_t n = make_pair_sets(truth, &nt);
  static Icp2d other;
  const Icp2dResult a = g_icp.match(g_target, nt, g_source, n, Pose2{}, wide_options());
  const Icp2dResult b = other.match(g_target, nt, g_source, n, Pose2{}, wide_options());
  CHECK_EQUAL(0, std::memcmp(&a.transform, &b.transform, sizeof(Pose2)));
  CHECK_EQUAL(0, std::memcmp(&a.mean_nn_error_m, &b.mean_nn_error_m, sizeof(double)));
  LONGS_EQUAL(a.iterations, b.iterations);
  LONGS_EQUAL(a.matched_pairs, b.matched_pairs);
}

// ---- direction information (Icp2d::direction_information) --------------------------

namespace {

// Two parallel walls 2 m apart along `heading`, 6 m long, sampled every spacing_m.
std::size_t corridor(Point2* out, double heading_rad, double spacing_m, double offset_m) {
  const double c = std::cos(heading_rad), s = std::sin(heading_rad);
  std::size_t n = 0U;
  for (double side : {-1.0, 1.0}) {
    for (double a = offset_m; a <= 6.0; a += spacing_m) out[n++] = Point2{c * a - s * side, s * a + c * side};
  }
  return n;
}

}  // namespace

TEST(Icp2d, a_corridor_match_is_fixed_across_the_corridor_only) {
  const double heading = 30.0 * kDeg;
  const std::size_t nt = corridor(g_target, heading, 0.05, 0.0);
  const std::size_t ns = corridor(g_source, heading, 0.07, 0.03);
  Icp2dOptions o;
  o.max_correspondence_m = 0.3;
  sdpslam::Icp2dInformation m;
  CHECK_TRUE(g_icp.direction_information(g_target, nt, g_source, ns, Pose2{}, o, 0.4, &m));
  LONGS_EQUAL(ns, m.pairs);
  LONGS_EQUAL(ns, m.line_pairs);
  // Every normal is (−sin 30°, cos 30°): M = n nᵀ.
  const double nx = -std::sin(heading), ny = std::cos(heading);
  DOUBLES_EQUAL(nx * nx, m.xx, 1e-9);
  DOUBLES_EQUAL(nx * ny, m.xy, 1e-9);
  DOUBLES_EQUAL(ny * ny, m.yy, 1e-9);
  DOUBLES_EQUAL(1.0, m.xx + m.yy, 1e-12);
}

TEST(Icp2d, a_closed_room_is_fixed_in_every_direction) {
  // A 4 m × 3 m room: two walls of each direction, corners neither.
  auto room = [](Point2* out, double first_m, double spacing_m) {
    std::size_t n = 0U;
    for (double x = first_m; x < 4.0; x += spacing_m) {
      out[n++] = Point2{x, 0.0};
      out[n++] = Point2{x, 3.0};
    }
    for (double y = first_m; y < 3.0; y += spacing_m) {
      out[n++] = Point2{0.0, y};
      out[n++] = Point2{4.0, y};
    }
    return n;
  };
  const std::size_t nt = room(g_target, 0.0, 0.05);
  const std::size_t ns = room(g_source, 0.03, 0.11);
  Icp2dOptions o;
  o.max_correspondence_m = 0.3;
  sdpslam::Icp2dInformation m;
  CHECK_TRUE(g_icp.direction_information(g_target, nt, g_source, ns, Pose2{}, o, 0.4, &m));
  LONGS_EQUAL(ns, m.pairs);
  CHECK_TRUE(m.line_pairs < ns);  // the points near the corners are not on one line
  // Walls along x fix y (weight 2 × 4 m), walls along y fix x (2 × 3 m): both directions.
  CHECK_TRUE(m.xx > 0.35 && m.xx < 0.5);
  CHECK_TRUE(m.yy > 0.5 && m.yy < 0.65);
  DOUBLES_EQUAL(0.0, m.xy, 1e-9);
  DOUBLES_EQUAL(1.0, m.xx + m.yy, 1e-12);
}

TEST(Icp2d, direction_information_refuses_what_it_cannot_measure) {
  const std::size_t nt = corridor(g_target, 0.0, 0.05, 0.0);
  const std::size_t ns = corridor(g_source, 0.0, 0.07, 0.03);
  Icp2dOptions o;
  o.max_correspondence_m = 0.3;
  sdpslam::Icp2dInformation m;
  m.xx = 7.0;
  CHECK_FALSE(g_icp.direction_information(g_target, nt, g_source, ns, Pose2{}, o, 0.0, &m));   // no radius
  CHECK_FALSE(g_icp.direction_information(g_target, nt, g_source, ns, Pose2{}, o, 20.0, &m));  // > 100 cells
  CHECK_FALSE(g_icp.direction_information(g_target, nt, g_source, ns, Pose2{}, o, 0.4, nullptr));
  CHECK_FALSE(g_icp.direction_information(nullptr, nt, g_source, ns, Pose2{}, o, 0.4, &m));
  // Far apart: no pair.
  CHECK_FALSE(g_icp.direction_information(g_target, nt, g_source, ns, Pose2{50.0, 0.0, 0.0}, o, 0.4, &m));
  DOUBLES_EQUAL(7.0, m.xx, 0.0);  // untouched
  // Lone target points (no neighbour within the radius) fix every direction: ½ I.
  CHECK_TRUE(g_icp.direction_information(g_target, nt, g_source, ns, Pose2{}, o, 0.01, &m));
  LONGS_EQUAL(0, m.line_pairs);
  DOUBLES_EQUAL(0.5, m.xx, 0.0);
  DOUBLES_EQUAL(0.5, m.yy, 0.0);
}
