#pragma once
// The simulated 2D world: walls as line segments, and the route the robot drives.
//
// World text format (one wall per line): `x1 y1 x2 y2` in metres, whitespace separated;
// `#` starts a comment (whole line or trailing); blank lines are ignored.
// Route text format (one waypoint per line): `x y` in metres, same comment rules.
//
// The built-in world reproduces the simulated environment of the SDP-SLAM paper (§IV,
// Fig. 4a): "an inner loop (loop 1) and an outer loop (loop 2) with lengths of 28 m and
// 80 m", nested, corridor-like. Corridor centre-lines:
//   - outer loop: rectangle (0,0)-(24,16), centre-line length 2*(24+16) = 80 m exactly;
//   - inner loop: rectangle (0,0)-(8,6),  centre-line length 2*(8+6)   = 28 m exactly.
// The inner loop sits in the outer loop's south-west corner and shares its corridors
// x in [0,8] on y=0 and y in [0,6] on x=0; two T-junctions, at (8,0) and (0,6), join them.
// Corridors are 1.8 m wide. The walls carry alcoves, side rooms, pilasters (0.15 m deep)
// and a pillar, so that scan matching sees features along the long corridors.
// The built-in route starts at (4,0) heading east (+x), drives the inner loop (28 m),
// passes the start and drives the outer loop (80 m) back to the start: 108 m in total.
#include <cstddef>
#include <string>
#include <vector>

namespace sdpslam::sim {

struct Point2 {
  double x_m = 0.0;
  double y_m = 0.0;
};

struct Segment {
  Point2 a;
  Point2 b;
};

struct World {
  std::vector<Segment> segments;
};

// A polyline of waypoints the robot follows in order.
struct Route {
  std::vector<Point2> waypoints;
};

inline constexpr double kBuiltinInnerLoopLength_m = 28.0;
inline constexpr double kBuiltinOuterLoopLength_m = 80.0;
inline constexpr double kBuiltinRouteLength_m = 108.0;
inline constexpr double kBuiltinCorridorWidth_m = 1.8;
// Waypoint index where the inner loop ends and the outer loop begins (the start point).
inline constexpr std::size_t kBuiltinInnerLoopEndWaypoint = 5;

// The paper's nested-loop world and route described above.
World builtin_world();
Route builtin_route();
// Heading of the route's first leg (radians); the robot starts on waypoint 0 facing it.
double route_start_heading_rad(const Route& route);

// Sum of the polyline's leg lengths between waypoints [first, last] (indices, inclusive).
double route_length_m(const Route& route, std::size_t first, std::size_t last);
double route_length_m(const Route& route);

// Parses world text. `source_name` prefixes errors ("world.txt:12: expected 4 numbers,
// got 3"). Returns false iff a line is malformed (not exactly four finite numbers), a
// segment has zero length, or there is no segment at all; `world` then holds the
// segments of the lines before the first error.
bool parse_world(const std::string& text, const std::string& source_name, World* world, std::string* error);
// Reads and parses a world file; false (with `error` naming the path) iff unreadable or
// malformed.
bool load_world_file(const std::string& path, World* world, std::string* error);
// The world as text that parse_world() reads back to the identical doubles (shortest
// round-trip formatting).
std::string format_world(const World& world);

// Route text: like the world, two numbers per line, at least two waypoints, consecutive
// waypoints distinct.
bool parse_route(const std::string& text, const std::string& source_name, Route* route, std::string* error);
bool load_route_file(const std::string& path, Route* route, std::string* error);

// Shortest distance from a point to any wall (infinity for an empty world). O(segments).
double distance_to_nearest_wall_m(const World& world, double x_m, double y_m);

}  // namespace sdpslam::sim
