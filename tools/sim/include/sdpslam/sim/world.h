#pragma once
// The simulated 2D world: walls as line segments, and the route the robot drives.
//
// World text format (one wall per line): `x1 y1 x2 y2` in metres, whitespace separated;
// `#` starts a comment (whole line or trailing); blank lines are ignored.
// Route text format (one waypoint per line): `x y` in metres, same comment rules.
//
// The paper world (builtin_world(), builtin_route()) reproduces the simulated environment
// of the SDP-SLAM paper (§IV, Fig. 4a): "an inner loop (loop 1) and an outer loop (loop 2)
// with lengths of 28 m and 80 m", nested, corridor-like. Corridor centre-lines:
//   - outer loop: rectangle (0,0)-(24,16), centre-line length 2*(24+16) = 80 m exactly;
//   - inner loop: rectangle (0,0)-(8,6),  centre-line length 2*(8+6)   = 28 m exactly.
// The inner loop sits in the outer loop's south-west corner and shares its corridors
// x in [0,8] on y=0 and y in [0,6] on x=0; two T-junctions, at (8,0) and (0,6), join them.
// Corridors are 1.8 m wide. The walls carry alcoves, side rooms, pilasters (0.15 m deep)
// and a pillar, so that scan matching sees features along the long corridors.
// The paper route starts at (4,0) heading east (+x), drives the inner loop (28 m),
// passes the start and drives the outer loop (80 m) back to the start: 108 m in total.
//
// The large built-in world (large_world(), large_route()) is an accuracy benchmark for
// big buildings: long corridors, loops of hundreds of metres, stretches where scan
// matching is degenerate. Corridors are 3 m wide (walls 1.5 m either side of the
// centre-line) on the centre-lines
//   - outer ring: rectangle (0,0)-(200,120);
//   - cross corridor x = 100, y in [0,120]; cross corridor y = 60, x in [0,200];
// so the building is 203 m x 123 m of four solid blocks of 97 m x 57 m, with open
// four-way crossings at (100,60) and T-junctions where the cross corridors meet the ring.
// On its way east of x = 100 the y = 60 corridor crosses an open hall of 30 m x 20 m
// (x in [135,165], y in [50,70]) holding four 0.6 m square pillars at least 3 m off the
// centre-line. Along the walls, at irregular spacing drawn once from a fixed-seed
// generator (the same world whatever the run's seed): pilasters (0.15 m), door recesses,
// alcoves and side rooms behind doors. On purpose four stretches of 43-57 m have plain
// walls on both sides, where a scan constrains nothing along the corridor: y = 60 for
// x in [1.5,50.4] (from the T-junction at x = 0), y = 120 for x in [17.85,69.65],
// x = 200 for y in [61.5,118.5] (the whole leg), y = 0 for x in [101.5,144.4]. No
// feature lies within 12 m of a junction or of the hall.
// The large route starts at (50,0) heading east, on exact centre-lines, and ends there:
//   loop 1 around the south-west block (0..100 x 0..60), 320 m;
//   loop 2 around the west half (0..100 x 0..120), 440 m;
//   loop 3 around the whole ring, 640 m;
//   then a figure of eight: east through the hall, around the north-east block (loop 4,
//   320 m, closing at (100,60)), south, around the south-east block crossing the hall
//   westwards (loop 5, 320 m, closing at (100,0)) and back to the start: 860 m;
// 2260 m in all, every loop revisiting corridors driven before.
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

inline constexpr double kLargeCorridorWidth_m = 3.0;
inline constexpr double kLargeRingWidth_m = 200.0;   // outer ring centre-line, x extent
inline constexpr double kLargeRingHeight_m = 120.0;  // outer ring centre-line, y extent
inline constexpr double kLargeLoop1Length_m = 320.0;
inline constexpr double kLargeLoop2Length_m = 440.0;
inline constexpr double kLargeLoop3Length_m = 640.0;
inline constexpr double kLargeHallLegLength_m = 860.0;  // loops 4 and 5 and the way back
inline constexpr double kLargeRouteLength_m = 2260.0;
// Waypoint indices where loops 1, 2 and 3 end (each on the start point).
inline constexpr std::size_t kLargeLoop1EndWaypoint = 5;
inline constexpr std::size_t kLargeLoop2EndWaypoint = 10;
inline constexpr std::size_t kLargeLoop3EndWaypoint = 15;
// The hall the y = 60 corridor crosses.
inline constexpr double kLargeHallMinX_m = 135.0;
inline constexpr double kLargeHallMaxX_m = 165.0;
inline constexpr double kLargeHallMinY_m = 50.0;
inline constexpr double kLargeHallMaxY_m = 70.0;

// The large world and route described above.
World large_world();
Route large_route();

// Heading of the route's first leg (radians); the robot starts on waypoint 0 facing it.
double route_start_heading_rad(const Route& route);

// Sum of the polyline's leg lengths between waypoints [first, last] (indices, inclusive).
double route_length_m(const Route& route, std::size_t first, std::size_t last);
double route_length_m(const Route& route);

// World and route coordinates lie within ±kMaxCoordinate_m (1000 km): within it every
// length, extent and sum of legs the simulator forms is a finite number; the text of a
// number beyond it (1e308, or a typo's 1e30) is refused.
inline constexpr double kMaxCoordinate_m = 1e6;

// Parses world text. `source_name` prefixes errors ("world.txt:12: expected 4 numbers,
// got 3"). Returns false iff a line is malformed (not exactly four finite numbers within
// ±kMaxCoordinate_m), a segment has zero length, or there is no segment at all; `world`
// then holds the segments of the lines before the first error.
bool parse_world(const std::string& text, const std::string& source_name, World* world, std::string* error);
// Reads and parses a world file; false (with `error` naming the path) iff unreadable or
// malformed.
bool load_world_file(const std::string& path, World* world, std::string* error);
// The world as text that parse_world() reads back to the identical doubles (shortest
// round-trip formatting).
std::string format_world(const World& world);

// Route text: like the world, two numbers per line (within ±kMaxCoordinate_m), at least
// two waypoints, consecutive waypoints distinct.
bool parse_route(const std::string& text, const std::string& source_name, Route* route, std::string* error);
bool load_route_file(const std::string& path, Route* route, std::string* error);

// Shortest distance from a point to any wall (infinity for an empty world). O(segments).
double distance_to_nearest_wall_m(const World& world, double x_m, double y_m);

}  // namespace sdpslam::sim
