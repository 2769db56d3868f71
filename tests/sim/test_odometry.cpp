// Wheel odometry noise: exact without noise, error growing with the noise, systematic
// drift of the stated size; and the drift figures of the default configuration.
#include <CppUTest/TestHarness.h>

#include <cmath>
#include <cstdio>

#include "sdpslam/sim/odometry_model.h"
#include "sdpslam/sim/simulator.h"
#include "sim_test_util.h"

using namespace sdpslam;
using namespace sdpslam::sim;
using sdpslam::test::RecordingSink;

namespace {
OdometryNoise no_noise() {
  OdometryNoise n;
  n.trans_m_per_sqrt_m = 0.0;
  n.rot_rad_per_sqrt_rad = 0.0;
  n.rot_rad_per_sqrt_m = 0.0;
  n.scale_error = 0.0;
  n.wheel_radius_mismatch = 0.0;
  return n;
}

SimulationSummary simulate_with(const OdometryNoise& noise, RecordingSink* sink, std::uint64_t seed = 1) {
  SimulationOptions o = test::cheap_laser_options();
  o.odometry = noise;
  o.seed = seed;
  SimulationSummary s;
  std::string error;
  CHECK_TRUE_TEXT(run_simulation(builtin_world(), builtin_route(), o, sink, &s, &error), error.c_str());
  return s;
}
}  // namespace

TEST_GROUP(SimOdometry){};

TEST(SimOdometry, noise_free_odometry_equals_ground_truth_bit_for_bit) {
  RecordingSink sink;
  const SimulationSummary s = simulate_with(no_noise(), &sink);
  CHECK(sink.truth.size() > 2000U);
  for (std::size_t i = 0; i < sink.truth.size(); ++i) {
    CHECK(sink.truth[i].x_m == sink.odom_at_scan[i].x_m);
    CHECK(sink.truth[i].y_m == sink.odom_at_scan[i].y_m);
    CHECK(sink.truth[i].heading_rad == sink.odom_at_scan[i].heading_rad);
  }
  DOUBLES_EQUAL(0.0, s.end_position_error_m, 0.0);
}

TEST(SimOdometry, single_step_without_noise_is_the_exact_arc) {
  WheelOdometry odo(Pose2{1.0, 1.0, 0.0}, no_noise(), 0.4, 5);
  odo.step(2.0, 0.0);
  DOUBLES_EQUAL(3.0, odo.pose().x_m, 0.0);
  DOUBLES_EQUAL(1.0, odo.pose().y_m, 0.0);
}

TEST(SimOdometry, wheel_radius_mismatch_turns_the_odometry_by_mismatch_over_wheel_base_per_metre) {
  OdometryNoise n = no_noise();
  n.wheel_radius_mismatch = 0.004;
  WheelOdometry odo(Pose2{}, n, 0.4, 5);
  for (int i = 0; i < 1000; ++i) odo.step(0.01, 0.0);  // 10 m straight
  DOUBLES_EQUAL(0.004 * 10.0 / 0.4, odo.pose().heading_rad, 1e-12);
}

TEST(SimOdometry, scale_error_stretches_the_distance) {
  OdometryNoise n = no_noise();
  n.scale_error = 0.01;
  WheelOdometry odo(Pose2{}, n, 0.4, 5);
  for (int i = 0; i < 100; ++i) odo.step(0.1, 0.0);
  DOUBLES_EQUAL(10.1, odo.pose().x_m, 1e-9);
}

TEST(SimOdometry, end_point_drift_grows_with_the_random_noise) {
  double previous = 0.0;
  for (double k : {0.005, 0.02, 0.08}) {
    OdometryNoise n = no_noise();
    n.trans_m_per_sqrt_m = k;
    n.rot_rad_per_sqrt_rad = k;
    n.rot_rad_per_sqrt_m = k / 4.0;
    RecordingSink sink;
    const SimulationSummary s = simulate_with(n, &sink);
    CHECK(s.end_position_error_m > previous);
    previous = s.end_position_error_m;
  }
  CHECK(previous > 1.0);  // 0.08: metres of error over 108 m
}

TEST(SimOdometry, random_translation_noise_has_the_stated_random_walk_spread) {
  // Along-track error after D metres has std trans * sqrt(D): 0.05 * sqrt(100) = 0.5 m.
  OdometryNoise n = no_noise();
  n.trans_m_per_sqrt_m = 0.05;
  double sum2 = 0.0;
  const int runs = 400;
  for (int r = 0; r < runs; ++r) {
    WheelOdometry odo(Pose2{}, n, 0.4, static_cast<std::uint64_t>(r) + 1U);
    for (int i = 0; i < 2000; ++i) odo.step(0.05, 0.0);  // 100 m straight
    sum2 += (odo.pose().x_m - 100.0) * (odo.pose().x_m - 100.0);
  }
  DOUBLES_EQUAL(0.5, std::sqrt(sum2 / runs), 0.05);
}

TEST(SimOdometry, default_noise_drift_figures_on_the_builtin_world) {
  // Prints the figures quoted for the benchmark; asserts only that the default noise
  // makes odometry clearly wrong but not absurd over the 108 m route.
  double sum_end = 0.0, sum_raw = 0.0, sum_aligned = 0.0;
  const int seeds = 5;
  for (int seed = 1; seed <= seeds; ++seed) {
    RecordingSink sink;
    const SimulationSummary s = simulate_with(OdometryNoise{}, &sink, static_cast<std::uint64_t>(seed));
    const double raw = test::unaligned_rmse_m(sink.odom_at_scan, sink.truth);
    const double aligned = test::aligned_rmse_m(sink.odom_at_scan, sink.truth);
    std::printf("\n  seed %d: end-point error %.3f m, %.2f deg; odometry RMSE %.3f m raw, %.3f m after SE(2) "
                "alignment; %.1f m in %.1f s",
                seed, s.end_position_error_m, s.end_heading_error_rad * 180.0 / 3.14159265358979323846, raw,
                aligned, s.distance_m, s.duration_s);
    CHECK(aligned <= raw + 1e-12);
    sum_end += s.end_position_error_m;
    sum_raw += raw;
    sum_aligned += aligned;
  }
  std::printf("\n  mean over %d seeds: end-point error %.3f m, RMSE %.3f m raw, %.3f m aligned\n", seeds,
              sum_end / seeds, sum_raw / seeds, sum_aligned / seeds);
  CHECK(sum_end / seeds > 0.3);
  CHECK(sum_end / seeds < 10.0);
}
