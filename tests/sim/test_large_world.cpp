// The large built-in world: its size, a route that stays clear of the walls, the hall,
// a closed building, the featureless stretches, and the preset driving it; and the
// table of built-in worlds.
#include <CppUTest/TestHarness.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "sdpslam/sim/builtin_worlds.h"
#include "sdpslam/sim/ray_caster.h"
#include "sdpslam/sim/simulator.h"
#include "sdpslam/sim/world.h"
#include "sim_test_util.h"

using namespace sdpslam;
using namespace sdpslam::sim;
using sdpslam::test::RecordingSink;

namespace {
constexpr double kPi = 3.14159265358979323846;

// Calls `visit(x, y)` on every waypoint and every `step_m` along every leg.
template <typename Visit>
void along_route(const Route& r, double step_m, Visit visit) {
  for (std::size_t i = 0; i + 1 < r.waypoints.size(); ++i) {
    const Point2 a = r.waypoints[i];
    const Point2 b = r.waypoints[i + 1];
    const double len = std::hypot(b.x_m - a.x_m, b.y_m - a.y_m);
    const int n = static_cast<int>(std::floor(len / step_m));
    for (int k = 0; k <= n; ++k) {
      const double u = k * step_m / len;
      visit(a.x_m + u * (b.x_m - a.x_m), a.y_m + u * (b.y_m - a.y_m));
    }
  }
  visit(r.waypoints.back().x_m, r.waypoints.back().y_m);
}

// Longest run (m) of the centre-line a -> b, sampled every 0.25 m, where the walls on
// both sides stand exactly half a corridor away: nothing to match along the corridor.
double longest_plain_run_m(const RayCaster& caster, Point2 a, Point2 b) {
  const double len = std::hypot(b.x_m - a.x_m, b.y_m - a.y_m);
  const double heading = std::atan2(b.y_m - a.y_m, b.x_m - a.x_m);
  const double half = 0.5 * kLargeCorridorWidth_m;
  constexpr double kStep_m = 0.25;
  double longest = 0.0;
  double run = -kStep_m;
  for (double s = 0.0; s <= len; s += kStep_m) {
    const double x = a.x_m + (b.x_m - a.x_m) * s / len;
    const double y = a.y_m + (b.y_m - a.y_m) * s / len;
    const bool plain = std::fabs(caster.cast(x, y, heading + 0.5 * kPi, 50.0) - half) < 1e-9 &&
                       std::fabs(caster.cast(x, y, heading - 0.5 * kPi, 50.0) - half) < 1e-9;
    run = plain ? run + kStep_m : -kStep_m;
    longest = std::max(longest, run);
  }
  return longest;
}
}  // namespace

TEST_GROUP(SimLargeWorld){};

TEST(SimLargeWorld, building_spans_at_least_200_m_by_120_m) {
  double min_x = 1e9, max_x = -1e9, min_y = 1e9, max_y = -1e9;
  for (const Segment& s : large_world().segments) {
    for (const Point2& p : {s.a, s.b}) {
      min_x = std::min(min_x, p.x_m);
      max_x = std::max(max_x, p.x_m);
      min_y = std::min(min_y, p.y_m);
      max_y = std::max(max_y, p.y_m);
    }
  }
  CHECK(max_x - min_x >= 200.0);
  CHECK(max_y - min_y >= 120.0);
}

TEST(SimLargeWorld, route_is_2260_m_long_and_ends_on_its_start) {
  const Route r = large_route();
  DOUBLES_EQUAL(kLargeRouteLength_m, route_length_m(r), 1e-9);
  CHECK(route_length_m(r) >= 1500.0);
  DOUBLES_EQUAL(r.waypoints.front().x_m, r.waypoints.back().x_m, 0.0);
  DOUBLES_EQUAL(r.waypoints.front().y_m, r.waypoints.back().y_m, 0.0);
}

TEST(SimLargeWorld, nested_loops_have_their_lengths_and_close_on_the_start) {
  const Route r = large_route();
  const Point2 s = r.waypoints.front();
  for (const std::size_t end : {kLargeLoop1EndWaypoint, kLargeLoop2EndWaypoint, kLargeLoop3EndWaypoint}) {
    DOUBLES_EQUAL(s.x_m, r.waypoints[end].x_m, 0.0);
    DOUBLES_EQUAL(s.y_m, r.waypoints[end].y_m, 0.0);
  }
  DOUBLES_EQUAL(kLargeLoop1Length_m, route_length_m(r, 0, kLargeLoop1EndWaypoint), 1e-9);
  DOUBLES_EQUAL(kLargeLoop2Length_m, route_length_m(r, kLargeLoop1EndWaypoint, kLargeLoop2EndWaypoint), 1e-9);
  DOUBLES_EQUAL(kLargeLoop3Length_m, route_length_m(r, kLargeLoop2EndWaypoint, kLargeLoop3EndWaypoint), 1e-9);
  DOUBLES_EQUAL(kLargeHallLegLength_m, route_length_m(r, kLargeLoop3EndWaypoint, r.waypoints.size() - 1), 1e-9);
}

TEST(SimLargeWorld, route_keeps_1_2_m_from_every_wall) {
  // 1.5 m half corridor less 0.15 m pilasters: 1.35 m at the narrowest.
  const World w = large_world();
  double min_clearance = 1e9;
  along_route(large_route(), 0.5, [&](double x, double y) {
    min_clearance = std::min(min_clearance, distance_to_nearest_wall_m(w, x, y));
  });
  CHECK(min_clearance >= 1.2);
}

TEST(SimLargeWorld, route_crosses_an_open_hall_in_both_directions) {
  const World w = large_world();
  const Route r = large_route();
  double max_clearance = 0.0;
  along_route(r, 0.5, [&](double x, double y) {
    max_clearance = std::max(max_clearance, distance_to_nearest_wall_m(w, x, y));
  });
  CHECK(max_clearance >= 8.0);
  int eastwards = 0;
  int westwards = 0;
  for (std::size_t i = 0; i + 1 < r.waypoints.size(); ++i) {
    const Point2 a = r.waypoints[i];
    const Point2 b = r.waypoints[i + 1];
    const bool through_hall = a.y_m == b.y_m && a.y_m > kLargeHallMinY_m && a.y_m < kLargeHallMaxY_m &&
                              std::min(a.x_m, b.x_m) <= kLargeHallMinX_m && std::max(a.x_m, b.x_m) >= kLargeHallMaxX_m;
    if (through_hall && b.x_m > a.x_m) ++eastwards;
    if (through_hall && b.x_m < a.x_m) ++westwards;
  }
  CHECK(eastwards >= 1);
  CHECK(westwards >= 1);
}

TEST(SimLargeWorld, building_is_closed_every_ray_from_the_route_hits_a_wall) {
  const RayCaster caster(large_world());
  int escaped = 0;
  along_route(large_route(), 20.0, [&](double x, double y) {
    for (int k = 0; k < 360; ++k) {
      if (!(caster.cast(x, y, k * kPi / 180.0, 1e4) <= 250.0)) ++escaped;
    }
  });
  LONGS_EQUAL(0, escaped);
}

TEST(SimLargeWorld, four_corridor_stretches_of_40_to_60_m_have_plain_walls_on_both_sides) {
  const RayCaster caster(large_world());
  const Point2 stretches[][2] = {{{0.0, 60.0}, {100.0, 60.0}},
                                 {{0.0, 120.0}, {100.0, 120.0}},
                                 {{200.0, 60.0}, {200.0, 120.0}},
                                 {{100.0, 0.0}, {200.0, 0.0}}};
  for (const auto& s : stretches) {
    const double run = longest_plain_run_m(caster, s[0], s[1]);
    CHECK(run >= 40.0);
    CHECK(run <= 60.0);
  }
}

TEST(SimLargeWorld, no_other_corridor_runs_plain_for_40_m) {
  const RayCaster caster(large_world());
  const Point2 corridors[][2] = {{{0.0, 0.0}, {100.0, 0.0}},     {{0.0, 0.0}, {0.0, 60.0}},
                                 {{0.0, 60.0}, {0.0, 120.0}},     {{100.0, 0.0}, {100.0, 60.0}},
                                 {{100.0, 60.0}, {100.0, 120.0}}, {{100.0, 120.0}, {200.0, 120.0}},
                                 {{200.0, 0.0}, {200.0, 60.0}},   {{100.0, 60.0}, {200.0, 60.0}}};
  for (const auto& c : corridors) CHECK(longest_plain_run_m(caster, c[0], c[1]) < 40.0);
}

TEST(SimLargeWorld, layout_is_the_same_on_every_call) {
  const World a = large_world();
  const World b = large_world();
  LONGS_EQUAL(a.segments.size(), b.segments.size());
  for (std::size_t i = 0; i < a.segments.size(); ++i) {
    CHECK(a.segments[i].a.x_m == b.segments[i].a.x_m && a.segments[i].a.y_m == b.segments[i].a.y_m);
    CHECK(a.segments[i].b.x_m == b.segments[i].b.x_m && a.segments[i].b.y_m == b.segments[i].b.y_m);
  }
}

TEST(SimLargeWorld, preset_robot_drives_the_first_corner_without_touching_a_wall) {
  // 75 simulated seconds: 50 m east at 1 m/s, the left turn at (100,0), then north.
  SimulationOptions o = large_world_options(SimulationOptions{});
  o.max_duration_s = 75.0;
  RecordingSink sink;
  SimulationSummary summary;
  std::string error;
  CHECK_TRUE_TEXT(run_simulation(large_world(), large_route(), o, &sink, &summary, &error), error.c_str());
  CHECK_FALSE(summary.reached_goal);
  CHECK(summary.min_wall_clearance_m >= 0.8);
  CHECK(summary.distance_m >= 60.0);
  DOUBLES_EQUAL(100.0, summary.final_true.x_m, 0.3);
  CHECK(summary.final_true.y_m >= 5.0);
  double max_off = 0.0;
  for (const Pose2& p : sink.truth) {
    // Distance to the first two legs, (50,0) -> (100,0) -> (100,60).
    const double to_east_leg = std::hypot(std::max(0.0, p.x_m - 100.0), p.y_m);
    const double to_north_leg = std::hypot(p.x_m - 100.0, std::min(0.0, p.y_m));
    max_off = std::max(max_off, std::min(to_east_leg, to_north_leg));
  }
  CHECK(max_off <= 0.7);
}

TEST_GROUP(SimBuiltinWorlds){};

TEST(SimBuiltinWorlds, worlds_are_found_by_exact_name_paper_first) {
  STRCMP_EQUAL("paper", builtin_worlds()[0].name);
  const BuiltinWorld* paper = find_builtin_world("paper");
  const BuiltinWorld* large = find_builtin_world("large");
  CHECK(paper != nullptr);
  CHECK(large != nullptr);
  LONGS_EQUAL(builtin_world().segments.size(), paper->world().segments.size());
  LONGS_EQUAL(large_world().segments.size(), large->world().segments.size());
  DOUBLES_EQUAL(kLargeRouteLength_m, route_length_m(large->route()), 1e-9);
  POINTERS_EQUAL(nullptr, find_builtin_world("Large"));
  POINTERS_EQUAL(nullptr, find_builtin_world(""));
  POINTERS_EQUAL(nullptr, find_builtin_world("world.txt"));
}

TEST(SimBuiltinWorlds, paper_preset_changes_nothing) {
  SimulationOptions base;
  base.seed = 7;
  base.laser.beam_count = 90;
  const SimulationOptions o = find_builtin_world("paper")->preset(base);
  LONGS_EQUAL(7, o.seed);
  LONGS_EQUAL(90, o.laser.beam_count);
  DOUBLES_EQUAL(base.robot.max_speed_mps, o.robot.max_speed_mps, 0.0);
}

TEST(SimBuiltinWorlds, large_preset_sets_laser_speed_and_drift_and_keeps_the_rest) {
  SimulationOptions base;
  base.seed = 7;
  base.odometry.trans_m_per_sqrt_m = 0.05;
  const SimulationOptions o = large_world_options(base);
  if (capacity::kMaxBeams >= 541U) LONGS_EQUAL(541, o.laser.beam_count);  // 0.5 deg steps
  CHECK(o.laser.beam_count <= capacity::kMaxBeams);
  LONGS_EQUAL(1, o.laser.beam_count % 2U);
  DOUBLES_EQUAL(270.0, o.laser.fov_deg, 0.0);
  DOUBLES_EQUAL(30.0, o.laser.max_range_m, 0.0);
  LONGS_EQUAL(10, o.laser.rate_hz);
  DOUBLES_EQUAL(1.0, o.robot.max_speed_mps, 0.0);
  DOUBLES_EQUAL(0.0001, o.odometry.wheel_radius_mismatch, 0.0);
  LONGS_EQUAL(7, o.seed);
  DOUBLES_EQUAL(0.05, o.odometry.trans_m_per_sqrt_m, 0.0);
  DOUBLES_EQUAL(OdometryNoise{}.scale_error, o.odometry.scale_error, 0.0);
  std::string error;
  CHECK_TRUE_TEXT(validate_simulation_options(o, &error), error.c_str());
}
