// OdometryRing: interpolation of the odometry pose at a scan's stamp.
#include <CppUTest/TestHarness.h>

#include <cmath>

#include "sdpslam/daemon/odometry_ring.h"

using sdpslam::Pose2;
using sdpslam::daemon::OdometryRing;
using Lookup = sdpslam::daemon::OdometryRing::Lookup;

TEST_GROUP(OdometryRing){};

TEST(OdometryRing, stamp_equal_to_a_sample_gives_that_sample_exactly) {
  OdometryRing r;
  r.push(100, Pose2{1.0, 2.0, 0.3});
  r.push(200, Pose2{1.5, 2.5, 0.4});
  Pose2 p;
  CHECK(r.interpolate(200, 1000, &p) == Lookup::kOk);
  DOUBLES_EQUAL(1.5, p.x_m, 0.0);
  DOUBLES_EQUAL(0.4, p.heading_rad, 0.0);
}

TEST(OdometryRing, straight_motion_is_interpolated_linearly) {
  OdometryRing r;
  r.push(1000, Pose2{0.0, 0.0, 0.0});
  r.push(2000, Pose2{1.0, 0.0, 0.0});
  Pose2 p;
  CHECK(r.interpolate(1250, 5000, &p) == Lookup::kOk);
  DOUBLES_EQUAL(0.25, p.x_m, 1e-12);
  DOUBLES_EQUAL(0.0, p.y_m, 1e-12);
}

TEST(OdometryRing, turning_motion_follows_the_constant_curvature_arc) {
  // Quarter circle of radius 1 to the left: the midpoint is on the circle at 45 degrees.
  OdometryRing r;
  const double pi = 3.14159265358979323846;
  r.push(0, Pose2{0.0, 0.0, 0.0});
  r.push(100, Pose2{1.0, 1.0, pi / 2.0});
  Pose2 p;
  CHECK(r.interpolate(50, 1000, &p) == Lookup::kOk);
  DOUBLES_EQUAL(std::sin(pi / 4.0), p.x_m, 1e-9);
  DOUBLES_EQUAL(1.0 - std::cos(pi / 4.0), p.y_m, 1e-9);
  DOUBLES_EQUAL(pi / 4.0, p.heading_rad, 1e-12);
}

TEST(OdometryRing, scan_newer_than_newest_sample_must_wait) {
  OdometryRing r;
  Pose2 p;
  CHECK(r.interpolate(10, 1000, &p) == Lookup::kNotYet);  // empty
  r.push(100, Pose2{});
  CHECK(r.interpolate(101, 1000, &p) == Lookup::kNotYet);
}

TEST(OdometryRing, scan_older_than_the_ring_is_too_old) {
  OdometryRing r;
  r.push(100, Pose2{});
  r.push(200, Pose2{});
  Pose2 p;
  CHECK(r.interpolate(99, 1000, &p) == Lookup::kTooOld);
}

TEST(OdometryRing, no_interpolation_across_a_break) {
  OdometryRing r;
  r.push(100, Pose2{0.0, 0.0, 0.0});
  r.mark_break();
  r.push(300, Pose2{5.0, 0.0, 0.0});
  Pose2 p;
  CHECK(r.interpolate(200, 1000, &p) == Lookup::kGap);
  CHECK(r.interpolate(300, 1000, &p) == Lookup::kOk);  // the sample itself is fine
  LONGS_EQUAL(1, r.break_count());
}

TEST(OdometryRing, samples_further_apart_than_the_gap_limit_are_not_interpolated) {
  OdometryRing r;
  r.push(0, Pose2{});
  r.push(1000, Pose2{1.0, 0.0, 0.0});
  Pose2 p;
  CHECK(r.interpolate(500, 999, &p) == Lookup::kGap);
  CHECK(r.interpolate(500, 1000, &p) == Lookup::kOk);
}

TEST(OdometryRing, non_increasing_stamp_is_refused_and_counted) {
  OdometryRing r;
  CHECK_TRUE(r.push(100, Pose2{}));
  CHECK_FALSE(r.push(100, Pose2{}));
  CHECK_FALSE(r.push(50, Pose2{}));
  LONGS_EQUAL(2, r.refused_count());
  LONGS_EQUAL(1, r.size());
}

TEST(OdometryRing, full_ring_overwrites_the_oldest_sample) {
  OdometryRing r;
  for (std::size_t i = 0; i < OdometryRing::kCapacity + 10U; ++i) {
    r.push(static_cast<std::int64_t>(i) * 10, Pose2{static_cast<double>(i), 0.0, 0.0});
  }
  LONGS_EQUAL(OdometryRing::kCapacity, r.size());
  LONGS_EQUAL(100, r.oldest_stamp_us());
  Pose2 p;
  CHECK(r.interpolate(95, 1000, &p) == Lookup::kTooOld);
  CHECK(r.interpolate(105, 1000, &p) == Lookup::kOk);
  DOUBLES_EQUAL(10.5, p.x_m, 1e-12);
}
