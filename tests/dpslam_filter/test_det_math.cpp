// det_math: agreement with libm to ~1e-15 (relative or absolute near zero), special
// values, and the angle wrapper the pose code relies on.
#include <CppUTest/TestHarness.h>

#include <cmath>
#include <limits>

#include "sdpslam/core/det_math.h"
#include "sdpslam/core/pose2.h"

namespace det = sdpslam::det;

namespace {
double rel_err(double got, double want) {
  const double scale = std::fabs(want) > 1.0 ? std::fabs(want) : 1.0;
  return std::fabs(got - want) / scale;
}
}  // namespace

TEST_GROUP(DetMath){};

TEST(DetMath, sin_and_cos_match_libm_over_a_wide_range) {
  double worst = 0.0;
  for (int i = -200000; i <= 200000; ++i) {
    const double x = i * 0.000731 * 3.0;  // about -440..440 rad, irregular steps
    const double es = rel_err(det::sin(x), std::sin(x));
    const double ec = rel_err(det::cos(x), std::cos(x));
    worst = std::fmax(worst, std::fmax(es, ec));
  }
  CHECK(worst < 2e-15);
}

TEST(DetMath, sin_and_cos_of_large_arguments_stay_bounded_and_close) {
  for (double x : {1.0e5, -7.5e5, 1.0e6, 3.0e7}) {
    CHECK(std::fabs(det::sin(x) - std::sin(x)) < 1e-8);
    CHECK(std::fabs(det::cos(x) - std::cos(x)) < 1e-8);
  }
}

TEST(DetMath, atan2_matches_libm_in_every_quadrant) {
  double worst = 0.0;
  for (int i = -300; i <= 300; ++i) {
    for (int j = -300; j <= 300; ++j) {
      const double y = i * 0.37, x = j * 0.53;
      worst = std::fmax(worst, std::fabs(det::atan2(y, x) - std::atan2(y, x)));
    }
  }
  CHECK(worst < 1e-15);
  DOUBLES_EQUAL(M_PI / 2.0, det::atan2(1.0, 0.0), 0.0);
  DOUBLES_EQUAL(-M_PI / 2.0, det::atan2(-2.0, 0.0), 0.0);
  DOUBLES_EQUAL(M_PI, det::atan2(0.0, -1.0), 0.0);
  DOUBLES_EQUAL(0.0, det::atan2(0.0, 0.0), 0.0);
}

TEST(DetMath, exp_matches_libm_to_an_ulp_or_two) {
  double worst = 0.0;
  for (int i = -70000; i <= 70000; ++i) {
    const double x = i * 0.0101;
    worst = std::fmax(worst, std::fabs(det::exp(x) - std::exp(x)) / std::exp(x));
  }
  CHECK(worst < 5e-16);
  DOUBLES_EQUAL(0.0, det::exp(-800.0), 0.0);
  CHECK(std::isinf(det::exp(800.0)));
  DOUBLES_EQUAL(1.0, det::exp(0.0), 0.0);
}

TEST(DetMath, log_matches_libm_including_subnormals) {
  double worst = 0.0;
  for (int i = 1; i <= 200000; ++i) {
    const double x = i * 0.00137;
    worst = std::fmax(worst, rel_err(det::log(x), std::log(x)));
  }
  for (double x : {1e-300, 4.9e-324, 1e-310, 1e300, 0.7071, 1.4142}) worst = std::fmax(worst, rel_err(det::log(x), std::log(x)));
  CHECK(worst < 1e-15);
  CHECK(std::isinf(det::log(0.0)) && det::log(0.0) < 0.0);
  CHECK(std::isnan(det::log(-1.0)));
  DOUBLES_EQUAL(0.0, det::log(1.0), 0.0);
}

TEST(DetMath, nan_and_infinity_propagate) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  CHECK(std::isnan(det::sin(nan)) && std::isnan(det::cos(inf)) && std::isnan(det::exp(nan)));
  CHECK(std::isnan(det::atan2(nan, 1.0)));
}

TEST(DetMath, wrap_angle_lands_in_minus_pi_exclusive_to_pi_inclusive) {
  for (int i = -5000; i <= 5000; ++i) {
    const double a = i * 0.0123;
    const double w = det::wrap_angle(a);
    CHECK(w > -M_PI && w <= M_PI);
    DOUBLES_EQUAL(0.0, std::remainder(a - w, 2.0 * M_PI), 1e-12);
  }
  DOUBLES_EQUAL(M_PI, det::wrap_angle(-M_PI), 0.0);
  DOUBLES_EQUAL(M_PI, det::wrap_angle(M_PI), 0.0);
}

TEST(DetMath, pose_composition_with_its_inverse_is_identity) {
  const sdpslam::Pose2 a{3.2, -1.5, 2.9};
  const sdpslam::Pose2 b{0.4, 0.7, -3.0};
  const sdpslam::Pose2 c = sdpslam::between(a, a.compose(b));
  DOUBLES_EQUAL(b.x_m, c.x_m, 1e-12);
  DOUBLES_EQUAL(b.y_m, c.y_m, 1e-12);
  DOUBLES_EQUAL(b.heading_rad, c.heading_rad, 1e-12);
}
