// Odometry motion model: decomposition round trip, unbiased samples whose spread
// follows the alpha parameters, and the Gaussian prior that approximates their density.
#include <CppUTest/TestHarness.h>

#include <cmath>

#include "sdpslam/core/bottom/motion_model.h"

using namespace sdpslam;

TEST_GROUP(MotionModel){};

TEST(MotionModel, decomposition_reproduces_the_displacement) {
  for (const Pose2& d : {Pose2{1.0, 0.2, 0.3}, Pose2{-0.5, 0.1, -0.2}, Pose2{0.0, 0.0, 1.0}, Pose2{0.0, -0.4, 0.0}}) {
    const Pose2 start{2.0, -1.0, 0.7};
    const Pose2 got = apply_odometry(start, decompose_odometry(d));
    const Pose2 want = start.compose(d);
    DOUBLES_EQUAL(want.x_m, got.x_m, 1e-12);
    DOUBLES_EQUAL(want.y_m, got.y_m, 1e-12);
    DOUBLES_EQUAL(want.heading_rad, got.heading_rad, 1e-12);
  }
}

TEST(MotionModel, backward_motion_keeps_the_first_turn_small) {
  const OdometryDelta d = decompose_odometry(Pose2{-1.0, 0.0, 0.0});
  DOUBLES_EQUAL(0.0, d.rot1_rad, 1e-12);
  DOUBLES_EQUAL(-1.0, d.trans_m, 1e-12);
}

TEST(MotionModel, samples_are_centred_on_the_odometry_with_the_model_spread) {
  MotionModelOptions o;
  o.alpha_rot_from_rot = 0.0;
  o.alpha_rot_from_trans = 0.01;   // sigma_rot = 0.1 * trans
  o.alpha_trans_from_trans = 0.04; // sigma_trans = 0.2 * trans
  o.alpha_trans_from_rot = 0.0;
  o.min_sigma_rot_rad = 0.0;
  o.min_sigma_trans_m = 0.0;
  const MotionModel m(o);
  Rng rng(1);
  const Pose2 delta{1.0, 0.0, 0.0};
  const int n = 50000;
  double sx = 0, sy = 0, sh = 0, sxx = 0, shh = 0;
  for (int i = 0; i < n; ++i) {
    const Pose2 p = m.sample(Pose2{}, delta, rng);
    sx += p.x_m;
    sy += p.y_m;
    sh += p.heading_rad;
    sxx += p.x_m * p.x_m;
    shh += p.heading_rad * p.heading_rad;
  }
  const double mx = sx / n, mh = sh / n;
  DOUBLES_EQUAL(1.0, mx, 0.01);
  DOUBLES_EQUAL(0.0, sy / n, 0.01);
  DOUBLES_EQUAL(0.0, mh, 0.005);
  // x ≈ trans·cos(rot1): its spread is the translational sigma (0.2).
  DOUBLES_EQUAL(0.2, std::sqrt(sxx / n - mx * mx), 0.01);
  // heading = rot1 + rot2, two independent 0.1 rad draws: sigma = 0.1·√2.
  DOUBLES_EQUAL(0.1 * std::sqrt(2.0), std::sqrt(shh / n - mh * mh), 0.005);
}

TEST(MotionModel, floors_spread_a_robot_that_did_not_move) {
  MotionModelOptions o;
  o.min_sigma_trans_m = 0.01;
  o.min_sigma_rot_rad = 0.01;
  const MotionModel m(o);
  Rng rng(2);
  double s = 0.0;
  for (int i = 0; i < 1000; ++i) s += std::fabs(m.sample(Pose2{}, Pose2{}, rng).heading_rad);
  CHECK(s / 1000.0 > 0.005);
}

TEST(MotionModel, same_seed_same_samples) {
  const MotionModel m{MotionModelOptions{}};
  Rng a(5), b(5);
  for (int i = 0; i < 100; ++i) {
    const Pose2 p = m.sample(Pose2{}, Pose2{0.3, 0.0, 0.1}, a);
    const Pose2 q = m.sample(Pose2{}, Pose2{0.3, 0.0, 0.1}, b);
    CHECK(p.x_m == q.x_m && p.y_m == q.y_m && p.heading_rad == q.heading_rad);
  }
}

// MotionPrior is the density of sample()'s position along the direction of travel: the
// squared Mahalanobis distance −2·log_density of samples is χ² with 1 degree of freedom
// (mean 1); a move across the path or a turn costs nothing.
TEST(MotionModel, the_prior_is_the_density_of_the_samples_along_the_path) {
  MotionModelOptions o;
  o.alpha_rot_from_rot = 0.02;
  o.alpha_rot_from_trans = 0.002;
  o.alpha_trans_from_trans = 0.01;
  o.alpha_trans_from_rot = 0.001;
  o.min_sigma_trans_m = 0.002;
  o.min_sigma_rot_rad = 0.002;
  const MotionModel m(o);
  const Pose2 start{3.0, -2.0, 2.5};
  for (const Pose2& delta : {Pose2{0.3, 0.05, 0.2}, Pose2{-0.25, 0.02, -0.1}, Pose2{0.4, 0.0, 0.0}}) {
    const MotionPrior prior = m.prior(start, delta);
    const Pose2 want = start.compose(delta);
    DOUBLES_EQUAL(want.x_m, prior.predicted.x_m, 1e-12);
    DOUBLES_EQUAL(want.y_m, prior.predicted.y_m, 1e-12);
    DOUBLES_EQUAL(0.0, prior.log_density(prior.predicted), 0.0);
    const Pose2 across{prior.predicted.x_m - 0.1 * prior.along_sin, prior.predicted.y_m + 0.1 * prior.along_cos, 1.0};
    DOUBLES_EQUAL(0.0, prior.log_density(across), 1e-12);
    Rng rng(11);
    const int n = 40000;
    double chi2 = 0.0;
    for (int i = 0; i < n; ++i) chi2 += -2.0 * prior.log_density(m.sample(start, delta, rng));
    DOUBLES_EQUAL(1.0, chi2 / n, 0.03);
  }
}

TEST(MotionModel, the_prior_of_a_robot_that_did_not_move_is_tight_and_finite) {
  const MotionModel m{MotionModelOptions{}};
  const MotionPrior prior = m.prior(Pose2{1.0, 1.0, 0.3}, Pose2{});
  // A centimetre ahead is far for a robot that stood still (floor 5 mm): log density −2.
  DOUBLES_EQUAL(-2.0, prior.log_density(Pose2{1.0 + 0.01 * std::cos(0.3), 1.0 + 0.01 * std::sin(0.3), 0.3}), 1e-9);
  // With every noise parameter zero the model is exact, the information finite.
  MotionModelOptions zero;
  zero.alpha_rot_from_rot = zero.alpha_rot_from_trans = zero.alpha_trans_from_trans = zero.alpha_trans_from_rot = 0.0;
  zero.min_sigma_trans_m = zero.min_sigma_rot_rad = 0.0;
  const MotionPrior exact = MotionModel(zero).prior(Pose2{}, Pose2{0.5, 0.0, 0.0});
  CHECK(std::isfinite(exact.log_density(Pose2{0.6, 0.1, 0.1})));
  CHECK(exact.log_density(Pose2{0.6, 0.1, 0.1}) < -1e6);
}
