// The simulated laser: geometry, noise-free readings, no-return and spurious readings.
#include <CppUTest/TestHarness.h>

#include <cmath>
#include <string>

#include "sdpslam/sim/laser_model.h"
#include "sdpslam/sim/simulator.h"

using namespace sdpslam;
using namespace sdpslam::sim;

namespace {
constexpr double kPi = 3.14159265358979323846;
World box_world() {
  World w;
  w.segments = {{{0, 0}, {4, 0}}, {{4, 0}, {4, 2}}, {{4, 2}, {0, 2}}, {{0, 2}, {0, 0}}};
  return w;
}
LaserOptions noise_free() {
  LaserOptions o;
  o.range_noise_std_m = 0.0;
  o.spurious_max_prob = 0.0;
  return o;
}
}  // namespace

TEST_GROUP(SimLaser){};

TEST(SimLaser, default_geometry_is_181_beams_over_180_deg_from_minus_90_max_8_m) {
  const RayCaster rc(box_world());
  LaserSimulator laser(rc, LaserOptions{}, 1);
  RangeScan scan;
  laser.scan(Pose2{1.0, 1.0, 0.0}, &scan);
  LONGS_EQUAL(181, scan.beam_count);
  DOUBLES_EQUAL(-kPi / 2.0, scan.geometry.angle_min_rad, 1e-6);
  DOUBLES_EQUAL(kPi / 180.0, scan.geometry.angle_increment_rad, 1e-7);
  DOUBLES_EQUAL(8.0, scan.geometry.range_max_m, 0.0);
}

TEST(SimLaser, noise_free_beams_read_the_true_distances_in_the_laser_frame) {
  const RayCaster rc(box_world());
  LaserSimulator laser(rc, noise_free(), 1);
  RangeScan scan;
  laser.scan(Pose2{1.0, 0.5, kPi / 2.0}, &scan);  // facing north
  DOUBLES_EQUAL(3.0, scan.ranges_m[0], 1e-6);      // -90 deg: east wall x = 4
  DOUBLES_EQUAL(1.5, scan.ranges_m[90], 1e-6);     //   0 deg: north wall y = 2
  DOUBLES_EQUAL(1.0, scan.ranges_m[180], 1e-6);    // +90 deg: west wall x = 0
}

TEST(SimLaser, wall_beyond_max_range_reads_exactly_max_range_which_is_no_return) {
  LaserOptions o = noise_free();
  o.max_range_m = 2.0;
  const RayCaster rc(box_world());
  LaserSimulator laser(rc, o, 1);
  RangeScan scan;
  laser.scan(Pose2{1.0, 0.5, kPi / 2.0}, &scan);
  DOUBLES_EQUAL(2.0, scan.ranges_m[0], 0.0);  // the wall at 3 m is out of range
  CHECK(scan.classify(0) == RangeScan::Beam::kNoReturn);
  CHECK(scan.classify(90) == RangeScan::Beam::kReturn);
}

TEST(SimLaser, spurious_probability_one_reads_max_range_on_every_beam) {
  LaserOptions o = noise_free();
  o.spurious_max_prob = 1.0;
  const RayCaster rc(box_world());
  LaserSimulator laser(rc, o, 1);
  RangeScan scan;
  laser.scan(Pose2{1.0, 1.0, 0.0}, &scan);
  for (std::uint32_t i = 0; i < scan.beam_count; ++i) CHECK(scan.classify(i) == RangeScan::Beam::kNoReturn);
}

TEST(SimLaser, range_noise_has_the_configured_spread) {
  LaserOptions o = noise_free();
  o.range_noise_std_m = 0.05;
  o.beam_count = 1001;
  o.fov_deg = 10.0;  // all beams on the east wall, about 3 m away
  const RayCaster rc(box_world());
  LaserSimulator laser(rc, o, 3);
  RangeScan scan;
  double sum2 = 0.0;
  int n = 0;
  for (int rep = 0; rep < 4; ++rep) {
    laser.scan(Pose2{1.0, 1.0, 0.0}, &scan);
    const double inc = 10.0 * kPi / 180.0 / 1000.0;
    for (std::uint32_t i = 0; i < scan.beam_count; ++i) {
      const double a = -5.0 * kPi / 180.0 + i * inc;
      const double truth = 3.0 / std::cos(a);
      sum2 += (scan.ranges_m[i] - truth) * (scan.ranges_m[i] - truth);
      ++n;
    }
  }
  DOUBLES_EQUAL(0.05, std::sqrt(sum2 / n), 0.003);
}

TEST(SimLaser, options_with_more_beams_than_the_core_capacity_are_refused) {
  SimulationOptions o;
  o.laser.beam_count = capacity::kMaxBeams + 1U;
  std::string error;
  CHECK_FALSE(validate_simulation_options(o, &error));
  CHECK(error.find("beam count") != std::string::npos);
}

TEST(SimLaser, laser_rate_not_dividing_the_physics_rate_is_refused) {
  SimulationOptions o;
  o.laser.rate_hz = 30;
  std::string error;
  CHECK_FALSE(validate_simulation_options(o, &error));
  STRCMP_EQUAL("invalid simulation option: laser rate must divide the physics rate 100 Hz (got 30)", error.c_str());
}

TEST(SimLaser, default_options_are_valid) {
  std::string error;
  CHECK_TRUE(validate_simulation_options(SimulationOptions{}, &error));
}
