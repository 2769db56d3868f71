#pragma once
// The core's random numbers: xoshiro256** (Blackman & Vigna, "Scrambled linear
// pseudorandom number generators", 2018) seeded through splitmix64, as its authors
// recommend. Same seed -> same sequence on every platform: no std:: distributions
// (their output is implementation-defined), and the Gaussian uses det_math's log/sqrt.
// Cost: a few ns per draw; no heap; 40 bytes of state.
#include <cstdint>

#include "sdpslam/core/state_io.h"

namespace sdpslam {

// splitmix64 (Steele, Lea & Flood 2014): expands one 64-bit seed into a stream.
inline std::uint64_t splitmix64_next(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

class Rng {
 public:
  explicit Rng(std::uint64_t seed = 0U) { reseed(seed); }

  void reseed(std::uint64_t seed);
  // Uniform 64-bit word.
  std::uint64_t next_u64();
  // Uniform double in [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>(next_u64() >> 11) * (1.0 / 9007199254740992.0); }
  // Uniform integer in [0, n) (n >= 1) by Lemire's multiply-shift (bias < n / 2^64).
  std::uint32_t below(std::uint32_t n) {
    return static_cast<std::uint32_t>(((next_u64() >> 32) * static_cast<std::uint64_t>(n)) >> 32);
  }
  // Standard normal draw (Marsaglia polar method; the spare value is cached).
  double gaussian();
  // N(0, sigma^2); sigma <= 0 gives exactly 0 without consuming randomness.
  double gaussian(double sigma) { return sigma > 0.0 ? sigma * gaussian() : 0.0; }

  // The generator's state, for snapshots (core/state_io.h).
  void transfer_state(StateIo& io) {
    io.value(s_);
    io.value(spare_);
    io.value(has_spare_);
  }

 private:
  std::uint64_t s_[4] = {};
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace sdpslam
