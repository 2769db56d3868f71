#pragma once
// The simulator's own random numbers, so that a seed gives bit-identical output on every
// standard library: splitmix64 (Steele, Lea, Flood 2014) to expand a seed, xoshiro256**
// (Blackman & Vigna 2018) as the generator, Box–Muller for Gaussians. No std::
// distributions are used: their output is implementation-defined.
#include <cmath>
#include <cstdint>

namespace sdpslam::sim {

// One step of splitmix64: advances *state and returns the next output.
inline std::uint64_t splitmix64(std::uint64_t* state) {
  std::uint64_t z = (*state += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30U)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27U)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31U);
}

class Rng {
 public:
  // `stream` separates independent consumers (odometry, laser) of one user seed, so that
  // changing the laser's settings does not change the odometry's noise.
  explicit Rng(std::uint64_t seed, std::uint64_t stream = 0) {
    std::uint64_t sm = seed ^ (stream * 0xD1B54A32D192ED03ULL);
    for (std::uint64_t& w : s_) w = splitmix64(&sm);
  }

  std::uint64_t next_u64() {
    const std::uint64_t result = rotl(s_[1] * 5U, 7) * 9U;
    const std::uint64_t t = s_[1] << 17U;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return result;
  }

  // Uniform in [0, 1), 53 random bits.
  double uniform() { return static_cast<double>(next_u64() >> 11U) * 0x1.0p-53; }

  // Standard normal by Box–Muller; both outputs of a pair are used.
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
  static std::uint64_t rotl(std::uint64_t x, int k) {
    return (x << static_cast<unsigned>(k)) | (x >> static_cast<unsigned>(64 - k));
  }
  std::uint64_t s_[4] = {};
  double spare_ = 0.0;
  bool have_spare_ = false;
};

}  // namespace sdpslam::sim
