// World and route: the paper's loop lengths, the route inside the corridors, and the
// world file format's errors.
#include <CppUTest/TestHarness.h>

#include <cmath>
#include <string>

#include "sdpslam/sim/world.h"
#include "shared_data.h"

using namespace sdpslam::sim;

TEST_GROUP(SimWorld){};

TEST(SimWorld, builtin_inner_loop_centre_line_is_28_m) {
  const Route r = builtin_route();
  DOUBLES_EQUAL(28.0, route_length_m(r, 0, kBuiltinInnerLoopEndWaypoint), 1e-12);
  DOUBLES_EQUAL(kBuiltinInnerLoopLength_m, route_length_m(r, 0, kBuiltinInnerLoopEndWaypoint), 1e-12);
}

TEST(SimWorld, builtin_outer_loop_centre_line_is_80_m) {
  const Route r = builtin_route();
  DOUBLES_EQUAL(80.0, route_length_m(r, kBuiltinInnerLoopEndWaypoint, r.waypoints.size() - 1), 1e-12);
  DOUBLES_EQUAL(kBuiltinRouteLength_m, route_length_m(r), 1e-12);
}

TEST(SimWorld, builtin_route_loops_close_on_the_start_point) {
  const Route r = builtin_route();
  const Point2 s = r.waypoints.front();
  DOUBLES_EQUAL(s.x_m, r.waypoints[kBuiltinInnerLoopEndWaypoint].x_m, 0.0);
  DOUBLES_EQUAL(s.y_m, r.waypoints[kBuiltinInnerLoopEndWaypoint].y_m, 0.0);
  DOUBLES_EQUAL(s.x_m, r.waypoints.back().x_m, 0.0);
  DOUBLES_EQUAL(s.y_m, r.waypoints.back().y_m, 0.0);
}

TEST(SimWorld, builtin_route_stays_in_the_corridors_clear_of_every_wall) {
  // Corridors are 1.8 m wide; pilasters narrow them by 0.15 m: >= 0.75 m clearance on
  // the centre-line everywhere.
  const World w = builtin_world();
  const Route r = builtin_route();
  double min_clearance = 1e9;
  for (std::size_t i = 0; i + 1 < r.waypoints.size(); ++i) {
    const Point2 a = r.waypoints[i];
    const Point2 b = r.waypoints[i + 1];
    for (int k = 0; k <= 400; ++k) {
      const double u = k / 400.0;
      min_clearance = std::fmin(min_clearance,
                                distance_to_nearest_wall_m(w, a.x_m + u * (b.x_m - a.x_m), a.y_m + u * (b.y_m - a.y_m)));
    }
  }
  CHECK(min_clearance >= 0.75 - 1e-9);
  CHECK(min_clearance <= 0.9 + 1e-9);
}

TEST(SimWorld, builtin_world_has_structure_beyond_plain_corridors) {
  // Four plain rectangles-with-an-L would be 4 + 4 + 6 = 14 walls; alcoves, rooms,
  // pilasters and a pillar add many more.
  CHECK(builtin_world().segments.size() > 100U);
}

TEST(SimWorld, world_text_round_trips_to_identical_doubles) {
  const World w = builtin_world();
  World back;
  std::string error;
  CHECK_TRUE(parse_world(format_world(w), "builtin", &back, &error));
  LONGS_EQUAL(w.segments.size(), back.segments.size());
  for (std::size_t i = 0; i < w.segments.size(); ++i) {
    CHECK(w.segments[i].a.x_m == back.segments[i].a.x_m);
    CHECK(w.segments[i].a.y_m == back.segments[i].a.y_m);
    CHECK(w.segments[i].b.x_m == back.segments[i].b.x_m);
    CHECK(w.segments[i].b.y_m == back.segments[i].b.y_m);
  }
}

TEST(SimWorld, world_parser_accepts_comments_blank_lines_and_trailing_comments) {
  World w;
  std::string error;
  CHECK_TRUE(parse_world("# walls\n\n0 0 1 0   # floor\n  +1 0 1 -2.5e0\n", "w.txt", &w, &error));
  LONGS_EQUAL(2, w.segments.size());
  DOUBLES_EQUAL(-2.5, w.segments[1].b.y_m, 0.0);
}

TEST(SimWorld, world_parse_error_names_file_and_line_of_a_short_line) {
  World w;
  std::string error;
  CHECK_FALSE(parse_world("0 0 1 0\n# c\n1 0 1\n2 2 3 3\n", "walls.txt", &w, &error));
  STRCMP_EQUAL("walls.txt:3: expected 4 numbers (x1 y1 x2 y2), got 3", error.c_str());
  LONGS_EQUAL(1, w.segments.size());  // the good line before the error is kept
}

TEST(SimWorld, world_parse_error_names_the_bad_token) {
  World w;
  std::string error;
  CHECK_FALSE(parse_world("0 0 1 0\n0 0 1 x1\n", "walls.txt", &w, &error));
  STRCMP_EQUAL("walls.txt:2: 'x1' is not a finite number", error.c_str());
}

TEST(SimWorld, world_parser_refuses_non_finite_numbers) {
  World w;
  std::string error;
  CHECK_FALSE(parse_world("0 0 inf 0\n", "w", &w, &error));
  STRCMP_EQUAL("w:1: 'inf' is not a finite number", error.c_str());
}

TEST(SimWorld, world_parser_refuses_zero_length_segment) {
  World w;
  std::string error;
  CHECK_FALSE(parse_world("0 0 1 0\n2 2 2 2\n", "w", &w, &error));
  STRCMP_EQUAL("w:2: segment has zero length", error.c_str());
}

TEST(SimWorld, world_parser_refuses_a_world_without_walls) {
  World w;
  std::string error;
  CHECK_FALSE(parse_world("# nothing\n\n", "empty.txt", &w, &error));
  STRCMP_EQUAL("empty.txt: no wall segments", error.c_str());
}

TEST(SimWorld, missing_world_file_error_names_the_path) {
  World w;
  std::string error;
  CHECK_FALSE(load_world_file("/nonexistent/dir/world.txt", &w, &error));
  STRCMP_EQUAL("/nonexistent/dir/world.txt: cannot open for reading", error.c_str());
}

TEST(SimWorld, route_parser_refuses_a_repeated_waypoint_naming_the_line) {
  Route r;
  std::string error;
  CHECK_FALSE(parse_route("0 0\n1 0\n1 0\n", "route.txt", &r, &error));
  STRCMP_EQUAL("route.txt:3: waypoint repeats the previous one", error.c_str());
}

TEST(SimWorld, route_parser_refuses_a_single_waypoint) {
  Route r;
  std::string error;
  CHECK_FALSE(parse_route("0 0\n", "route.txt", &r, &error));
  STRCMP_EQUAL("route.txt: a route needs at least 2 waypoints", error.c_str());
}

// Legs of 2e308 m summed to an infinite route length, which `sdpslam simulate` converts
// to an integer (undefined behaviour); walls that far apart gave the ray caster an
// infinite extent.
TEST(SimWorld, coordinates_beyond_1000_km_are_refused) {
  Route r;
  std::string error;
  CHECK_FALSE(parse_route("-1e308 0\n1e308 0\n", "route.txt", &r, &error));
  STRCMP_EQUAL("route.txt:1: '-1e308' lies beyond the largest coordinate, 1e6 m", error.c_str());
  CHECK_TRUE_TEXT(parse_route("-1e6 0\n1e6 0\n-1e6 0\n", "route.txt", &r, &error), error.c_str());
  CHECK_TRUE(std::isfinite(route_length_m(r)));
  World w;
  CHECK_FALSE(parse_world("0 0 1 0\n1e300 0 1e300 1\n", "walls.txt", &w, &error));
  STRCMP_EQUAL("walls.txt:2: '1e300' lies beyond the largest coordinate, 1e6 m", error.c_str());
  LONGS_EQUAL(1, w.segments.size());
}

TEST(SimWorld, distance_to_nearest_wall_measures_to_the_segment_not_the_line) {
  World w;
  w.segments.push_back(Segment{{0.0, 0.0}, {1.0, 0.0}});
  DOUBLES_EQUAL(2.0, distance_to_nearest_wall_m(w, 0.5, 2.0), 1e-12);
  DOUBLES_EQUAL(5.0, distance_to_nearest_wall_m(w, 4.0, 4.0), 1e-12);  // to the end point (1, 0)
}
