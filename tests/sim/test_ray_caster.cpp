// Ray casting against hand-computed hits, and the grid against brute force.
#include <CppUTest/TestHarness.h>

#include <cmath>

#include "sdpslam/sim/ray_caster.h"
#include "sdpslam/sim/rng.h"

using namespace sdpslam::sim;

namespace {
constexpr double kPi = 3.14159265358979323846;

World box_world() {
  // A 4 m x 2 m box: x in [0, 4], y in [0, 2].
  World w;
  w.segments = {{{0, 0}, {4, 0}}, {{4, 0}, {4, 2}}, {{4, 2}, {0, 2}}, {{0, 2}, {0, 0}}};
  return w;
}
}  // namespace

TEST_GROUP(SimRayCaster){};

TEST(SimRayCaster, beam_perpendicular_to_a_wall_hits_at_the_exact_distance) {
  const RayCaster rc(box_world());
  DOUBLES_EQUAL(3.0, rc.cast(1.0, 1.0, 0.0), 0.0);                   // east wall, x = 4
  DOUBLES_EQUAL(1.0, rc.cast(1.0, 1.0, kPi), 1e-15);                 // west wall, x = 0
  DOUBLES_EQUAL(1.0, rc.cast(1.0, 1.0, kPi / 2.0), 1e-15);           // north wall
  DOUBLES_EQUAL(0.25, rc.cast(1.0, 0.25, -kPi / 2.0), 1e-15);        // south wall
}

TEST(SimRayCaster, oblique_beam_hits_at_the_hand_computed_distance) {
  const RayCaster rc(box_world());
  // From (1, 1) at 30 deg the north wall (y = 2) is 1 / sin(30 deg) = 2 m away.
  DOUBLES_EQUAL(2.0, rc.cast(1.0, 1.0, kPi / 6.0), 1e-12);
}

TEST(SimRayCaster, beam_into_a_corner_hits_the_corner) {
  const RayCaster rc(box_world());
  // From (2, 0.5) towards the corner (4, 2): 3-4-5 triangle scaled by 0.5 → 2.5 m.
  DOUBLES_EQUAL(2.5, rc.cast(2.0, 0.5, std::atan2(1.5, 2.0)), 1e-12);
}

TEST(SimRayCaster, beam_through_a_free_segment_end_point_still_hits) {
  World w;
  w.segments = {{{2.0, -1.0}, {2.0, 0.0}}};  // ends exactly on the ray y = 0
  const RayCaster rc(w);
  DOUBLES_EQUAL(2.0, rc.cast(0.0, 0.0, 0.0), 0.0);
}

TEST(SimRayCaster, beam_that_misses_every_wall_returns_infinity) {
  World w;
  w.segments = {{{2.0, 1.0}, {2.0, 3.0}}};
  const RayCaster rc(w);
  CHECK(std::isinf(rc.cast(0.0, 0.0, 0.0)));
  CHECK(std::isinf(rc.cast(0.0, 0.0, kPi)));  // wall behind the ray origin's direction
}

TEST(SimRayCaster, wall_beyond_max_range_is_a_miss) {
  const RayCaster rc(box_world());
  CHECK(std::isinf(rc.cast(1.0, 1.0, 0.0, 2.999)));
  DOUBLES_EQUAL(3.0, rc.cast(1.0, 1.0, 0.0, 3.0), 0.0);
}

TEST(SimRayCaster, beam_parallel_to_a_wall_does_not_hit_it) {
  World w;
  w.segments = {{{1.0, 0.0}, {3.0, 0.0}}};
  const RayCaster rc(w);
  CHECK(std::isinf(rc.cast(0.0, 0.0, 0.0)));
}

TEST(SimRayCaster, ray_from_outside_the_grid_enters_and_hits) {
  const RayCaster rc(box_world());
  DOUBLES_EQUAL(10.0, rc.cast(-10.0, 1.0, 0.0), 1e-12);  // hits the west wall from outside
  CHECK(std::isinf(rc.cast(-10.0, 5.0, 0.0)));           // passes above the box
}

TEST(SimRayCaster, empty_world_never_hits) {
  const RayCaster rc(World{});
  CHECK(std::isinf(rc.cast(0.0, 0.0, 0.3)));
}

TEST(SimRayCaster, grid_agrees_with_brute_force_on_the_builtin_world) {
  const RayCaster rc(builtin_world());
  CHECK(rc.grid_width() > 1U);
  CHECK(rc.grid_height() > 1U);
  Rng rng(12345);
  int hits = 0;
  for (int i = 0; i < 20000; ++i) {
    const double x = -2.0 + 28.0 * rng.uniform();
    const double y = -5.0 + 26.0 * rng.uniform();
    const double a = 2.0 * kPi * rng.uniform();
    const double max_range = i % 2 == 0 ? 8.0 : 1e9;
    const double g = rc.cast(x, y, a, max_range);
    const double b = rc.cast_brute_force(x, y, a, max_range);
    if (std::isinf(b)) {
      CHECK(std::isinf(g));
    } else {
      ++hits;
      DOUBLES_EQUAL(b, g, 0.0);
    }
  }
  CHECK(hits > 10000);
}

TEST(SimRayCaster, grid_agrees_with_brute_force_on_diagonal_walls_with_coarse_cells) {
  World w;
  Rng gen(7);
  for (int i = 0; i < 60; ++i) {
    const double x = 10.0 * gen.uniform(), y = 10.0 * gen.uniform();
    w.segments.push_back(Segment{{x, y}, {x + 3.0 * (gen.uniform() - 0.5), y + 3.0 * (gen.uniform() - 0.5)}});
  }
  const RayCaster rc(w, 0.7);
  Rng rng(99);
  for (int i = 0; i < 5000; ++i) {
    const double x = 10.0 * rng.uniform(), y = 10.0 * rng.uniform(), a = 2.0 * kPi * rng.uniform();
    const double g = rc.cast(x, y, a);
    const double b = rc.cast_brute_force(x, y, a);
    CHECK(std::isinf(b) ? std::isinf(g) : g == b);
  }
}
