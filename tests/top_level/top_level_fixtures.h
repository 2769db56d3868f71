#pragma once
// Synthetic inputs shared by the top-level tests and benchmark: point sets sampled along
// wall segments, occupancy patches with corridors, and a small deterministic RNG.
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "top/free_space_skeleton.h"
#include "sdpslam/core/top/icp2d.h"
#include "sdpslam/core/pose2.h"

namespace sdpslam::test {

// splitmix64 (Steele, Lea & Flood 2014): tiny, deterministic, good enough for tests.
struct SplitMix64 {
  std::uint64_t state;
  explicit SplitMix64(std::uint64_t seed) : state(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30U)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27U)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31U);
  }
  // Uniform in [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>(next() >> 11U) * (1.0 / 9007199254740992.0); }
  // Standard normal (Box-Muller); test-only, so libm is fine here.
  double normal() {
    const double u1 = 1.0 - uniform();
    const double u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
  }
};

// Appends points every spacing_m along the segment a→b (both ends included) to out,
// up to capacity; returns the new count.
inline std::size_t add_segment(Point2* out, std::size_t count, std::size_t capacity, double ax, double ay, double bx,
                               double by, double spacing_m) {
  const double len = std::sqrt((bx - ax) * (bx - ax) + (by - ay) * (by - ay));
  const auto steps = static_cast<std::size_t>(len / spacing_m);
  for (std::size_t i = 0; i <= steps && count < capacity; ++i) {
    const double t = steps == 0U ? 0.0 : static_cast<double>(i) / static_cast<double>(steps);
    out[count++] = Point2{ax + t * (bx - ax), ay + t * (by - ay)};
  }
  return count;
}

// An asymmetric room-and-corridor outline: an L of walls, a corridor with an end wall,
// and a short stub, so that every degree of freedom is constrained.
inline std::size_t structured_scene(Point2* out, std::size_t capacity, double spacing_m) {
  std::size_t n = 0U;
  n = add_segment(out, n, capacity, 0.0, 0.0, 4.0, 0.0, spacing_m);  // L, long arm
  n = add_segment(out, n, capacity, 0.0, 0.0, 0.0, 2.5, spacing_m);  // L, short arm
  n = add_segment(out, n, capacity, 1.0, 1.5, 3.0, 1.5, spacing_m);  // corridor wall
  n = add_segment(out, n, capacity, 1.0, 2.5, 3.0, 2.5, spacing_m);  // corridor wall
  n = add_segment(out, n, capacity, 3.0, 1.5, 3.0, 2.5, spacing_m);  // corridor end
  n = add_segment(out, n, capacity, 4.0, 0.0, 4.0, 0.7, spacing_m);  // stub
  return n;
}

// out[i] = pose ⊕ in[i].
inline void transform_points(const Pose2& pose, const Point2* in, Point2* out, std::size_t count) {
  for (std::size_t i = 0; i < count; ++i) pose.transform_point(in[i].x_m, in[i].y_m, out[i].x_m, out[i].y_m);
}

// Row-major occupancy patch filled with one state.
inline void fill(CellState* cells, std::uint32_t w, std::uint32_t h, CellState s) {
  for (std::size_t i = 0; i < static_cast<std::size_t>(w) * h; ++i) cells[i] = s;
}
// Sets the rectangle [x0, x1) × [y0, y1) (clipped) to s.
inline void rect(CellState* cells, std::uint32_t w, std::uint32_t h, std::int64_t x0, std::int64_t y0,
                 std::int64_t x1, std::int64_t y1, CellState s) {
  for (std::int64_t y = y0 < 0 ? 0 : y0; y < y1 && y < static_cast<std::int64_t>(h); ++y) {
    for (std::int64_t x = x0 < 0 ? 0 : x0; x < x1 && x < static_cast<std::int64_t>(w); ++x) {
      cells[static_cast<std::size_t>(y) * w + static_cast<std::size_t>(x)] = s;
    }
  }
}

}  // namespace sdpslam::test
