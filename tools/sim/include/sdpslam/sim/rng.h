#pragma once
// The simulator's random numbers: the core's generator (core/rng.h: xoshiro256**
// seeded through splitmix64), one independent stream per consumer, and Box–Muller for
// Gaussians. No std:: distributions are used: their output is implementation-defined.
#include <cmath>
#include <cstdint>

#include "sdpslam/core/rng.h"

namespace sdpslam::sim {

class Rng {
 public:
  // `stream` separates independent consumers (odometry, laser) of one user seed, so that
  // changing the laser's settings does not change the odometry's noise.
  explicit Rng(std::uint64_t seed, std::uint64_t stream = 0) : core_(seed ^ (stream * 0xD1B54A32D192ED03ULL)) {}

  std::uint64_t next_u64() { return core_.next_u64(); }
  // Uniform in [0, 1), 53 random bits.
  double uniform() { return core_.uniform(); }

  // Standard normal by Box–Muller; both outputs of a pair are used. (Not the core's polar
  // method: the simulated worlds' noise, and so every benchmark figure on them, is
  // defined by this sequence.)
  double gaussian() {
    if (have_spare_) {
      have_spare_ = false;
      return spare_;
    }
    const double u1 = 1.0 - uniform();  // (0, 1]: log is finite
    const double u2 = uniform();
    const double r = std::sqrt(-2.0 * std::log(u1));
    const double a = 6.283185307179586476925 * u2;
    spare_ = r * std::sin(a);
    have_spare_ = true;
    return r * std::cos(a);
  }

 private:
  sdpslam::Rng core_;
  double spare_ = 0.0;
  bool have_spare_ = false;
};

}  // namespace sdpslam::sim
