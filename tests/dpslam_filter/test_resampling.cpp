// Weight normalisation, N_eff, and low-variance resampling.
#include <CppUTest/TestHarness.h>

#include <cmath>
#include <limits>

#include "sdpslam/core/bottom/resampling.h"

using namespace sdpslam;

TEST_GROUP(Resampling){};

TEST(Resampling, log_weights_far_below_double_range_normalise_without_underflow) {
  const double lw[3] = {-100000.0, -100001.0, -100002.0};
  double w[3];
  CHECK_TRUE(normalize_log_weights(lw, 3, w));
  const double z = 1.0 + std::exp(-1.0) + std::exp(-2.0);
  DOUBLES_EQUAL(1.0 / z, w[0], 1e-15);
  DOUBLES_EQUAL(std::exp(-1.0) / z, w[1], 1e-15);
  DOUBLES_EQUAL(std::exp(-2.0) / z, w[2], 1e-15);
}

TEST(Resampling, minus_infinity_and_nan_get_zero_weight) {
  const double lw[3] = {-std::numeric_limits<double>::infinity(), 0.0, std::numeric_limits<double>::quiet_NaN()};
  double w[3];
  CHECK_TRUE(normalize_log_weights(lw, 3, w));
  DOUBLES_EQUAL(0.0, w[0], 0.0);
  DOUBLES_EQUAL(1.0, w[1], 0.0);
  DOUBLES_EQUAL(0.0, w[2], 0.0);
}

TEST(Resampling, all_unusable_weights_become_uniform_and_are_reported) {
  const double inf = std::numeric_limits<double>::infinity();
  const double lw[4] = {-inf, -inf, -inf, -inf};
  double w[4];
  CHECK_FALSE(normalize_log_weights(lw, 4, w));
  for (double v : w) DOUBLES_EQUAL(0.25, v, 0.0);
}

TEST(Resampling, effective_sample_size_is_n_for_uniform_and_one_for_a_single_winner) {
  const double u[4] = {0.25, 0.25, 0.25, 0.25};
  const double one[4] = {0.0, 1.0, 0.0, 0.0};
  DOUBLES_EQUAL(4.0, effective_sample_size(u, 4), 1e-12);
  DOUBLES_EQUAL(1.0, effective_sample_size(one, 4), 1e-12);
}

TEST(Resampling, low_variance_counts_are_floor_or_ceil_of_n_times_weight) {
  const std::size_t n = 100;
  double w[n];
  double sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) sum += (w[i] = static_cast<double>((i * 37) % 11 + 1));
  for (double& v : w) v /= sum;
  Rng rng(3);
  for (int trial = 0; trial < 50; ++trial) {
    std::uint32_t idx[n];
    low_variance_resample(w, n, rng, idx);
    std::uint32_t counts[n] = {};
    for (std::size_t m = 0; m < n; ++m) {
      if (m > 0) CHECK(idx[m] >= idx[m - 1]);
      ++counts[idx[m]];
    }
    for (std::size_t i = 0; i < n; ++i) {
      const double expect = static_cast<double>(n) * w[i];
      CHECK(counts[i] >= static_cast<std::uint32_t>(std::floor(expect)) &&
            counts[i] <= static_cast<std::uint32_t>(std::ceil(expect)));
    }
  }
}

TEST(Resampling, zero_weight_particles_are_never_drawn) {
  const double w[5] = {0.0, 0.5, 0.0, 0.5, 0.0};
  Rng rng(4);
  std::uint32_t idx[5];
  for (int t = 0; t < 100; ++t) {
    low_variance_resample(w, 5, rng, idx);
    for (std::uint32_t i : idx) CHECK(i == 1U || i == 3U);
  }
}
