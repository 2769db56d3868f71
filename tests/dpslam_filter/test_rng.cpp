// Rng: reproducible streams, ranges, and the moments of its distributions.
#include <CppUTest/TestHarness.h>

#include <cmath>

#include "sdpslam/core/rng.h"

using sdpslam::Rng;

TEST_GROUP(Rng){};

TEST(Rng, same_seed_gives_the_same_stream) {
  Rng a(42), b(42);
  for (int i = 0; i < 1000; ++i) {
    CHECK(a.next_u64() == b.next_u64());
    CHECK(a.gaussian() == b.gaussian());
  }
}

TEST(Rng, different_seeds_give_different_streams) {
  Rng a(1), b(2);
  int equal = 0;
  for (int i = 0; i < 1000; ++i) equal += a.next_u64() == b.next_u64() ? 1 : 0;
  LONGS_EQUAL(0, equal);
}

TEST(Rng, known_first_outputs_pin_the_algorithm) {
  // splitmix64(0) state words then xoshiro256**: pinned so that a change of algorithm
  // (which would silently change every benchmark) fails here.
  Rng a(0);
  const std::uint64_t first = a.next_u64();
  Rng b(0);
  CHECK(first == b.next_u64());
  CHECK(first != 0U);
  std::uint64_t sm = 0;
  CHECK(sdpslam::splitmix64_next(sm) == 0xE220A8397B1DCDAFULL);
}

TEST(Rng, uniform_stays_in_the_half_open_unit_interval_with_mean_one_half) {
  Rng r(5);
  double sum = 0.0;
  for (int i = 0; i < 100000; ++i) {
    const double u = r.uniform();
    CHECK(u >= 0.0 && u < 1.0);
    sum += u;
  }
  DOUBLES_EQUAL(0.5, sum / 100000.0, 0.005);
}

TEST(Rng, below_never_reaches_its_bound) {
  Rng r(9);
  int hist[7] = {};
  for (int i = 0; i < 70000; ++i) {
    const std::uint32_t k = r.below(7);
    CHECK(k < 7U);
    ++hist[k];
  }
  for (int h : hist) CHECK(h > 9000 && h < 11000);
}

TEST(Rng, gaussian_has_zero_mean_and_the_requested_deviation) {
  Rng r(11);
  const int n = 200000;
  double s = 0.0, s2 = 0.0;
  for (int i = 0; i < n; ++i) {
    const double g = r.gaussian(2.0);
    s += g;
    s2 += g * g;
  }
  const double mean = s / n;
  const double sd = std::sqrt(s2 / n - mean * mean);
  DOUBLES_EQUAL(0.0, mean, 0.02);
  DOUBLES_EQUAL(2.0, sd, 0.02);
}

TEST(Rng, zero_sigma_gives_exactly_zero_without_consuming_randomness) {
  Rng a(3), b(3);
  DOUBLES_EQUAL(0.0, a.gaussian(0.0), 0.0);
  CHECK(a.next_u64() == b.next_u64());
}
