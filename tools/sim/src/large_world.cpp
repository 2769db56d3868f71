// The large built-in world and its route (layout in world.h).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "sdpslam/sim/world.h"
#include "wall_builder.h"

namespace sdpslam::sim {
namespace {

using detail::Notch;
using detail::WallBuilder;

constexpr double kHalf_m = 0.5 * kLargeCorridorWidth_m;

// Axis-aligned regions of the plan where no wall carries a feature.
struct Box {
  double min_x_m;
  double min_y_m;
  double max_x_m;
  double max_y_m;
};

// Keep-out around every junction, so that features never crowd a crossing or a corner
// (and rooms of two walls meeting at a block's corner cannot overlap).
constexpr double kJunctionQuiet_m = 12.0;
constexpr double kJunctionX_m[] = {0.0, 100.0, 200.0};
constexpr double kJunctionY_m[] = {0.0, 60.0, 120.0};

// The hall with a margin, and the featureless stretches, both sides of the corridor.
constexpr Box kQuiet[] = {
    {kLargeHallMinX_m - 12.0, kLargeHallMinY_m - 12.0, kLargeHallMaxX_m + 12.0, kLargeHallMaxY_m + 12.0},
    {12.0, 55.0, 50.0, 65.0},     // y = 60, west half: plain from the T-junction at x = 0
    {25.0, 115.0, 68.0, 125.0},   // y = 120, north-west
    {195.0, 60.0, 205.0, 120.0},  // x = 200, between the hall corridor and the north-east corner
    {112.0, -5.0, 142.0, 5.0},    // y = 0, east of the cross corridor
};

bool overlaps(const Box& box, Point2 p, Point2 q) {
  return std::max(p.x_m, q.x_m) >= box.min_x_m && std::min(p.x_m, q.x_m) <= box.max_x_m &&
         std::max(p.y_m, q.y_m) >= box.min_y_m && std::min(p.y_m, q.y_m) <= box.max_y_m;
}

bool quiet(Point2 p, Point2 q) {
  for (const double x : kJunctionX_m) {
    for (const double y : kJunctionY_m) {
      const Box j{x - kJunctionQuiet_m, y - kJunctionQuiet_m, x + kJunctionQuiet_m, y + kJunctionQuiet_m};
      if (overlaps(j, p, q)) return true;
    }
  }
  for (const Box& b : kQuiet) {
    if (overlaps(b, p, q)) return true;
  }
  return false;
}

// Knuth's MMIX linear congruential generator with a fixed seed: the layout is drawn
// once, the same on every platform and for every simulation seed.
class LayoutDraw {
 public:
  // Uniform integer in [lo, hi].
  int uniform(int lo, int hi) {
    state_ = state_ * 6364136223846793005ULL + 1442695040888963407ULL;
    return lo + static_cast<int>((state_ >> 33) % static_cast<std::uint64_t>(hi - lo + 1));
  }

 private:
  std::uint64_t state_ = 0x5d9a7e3c1b2f4a60ULL;
};

// Feature sizes and positions along a wall are whole multiples of 5 cm ("ticks").
constexpr double kTick_m = 0.05;
double ticks_m(int ticks) { return ticks / 20.0; }

// Features along the wall a -> b at irregular spacing (gaps of 2.5-12 m), skipping the
// quiet regions; `fixed` (the hall) is merged in. Every step draws five numbers whatever
// it places. Pilasters 0.3-0.6 m wide; door recesses 0.9-1.2 m wide, 0.2-0.4 m deep;
// alcoves 1.5-3 m wide, 0.6-1.5 m deep; rooms 3-6 m wide and 2.5-5 m deep behind a 1 m
// door in a 0.2 m wall.
std::vector<Notch> features(Point2 a, Point2 b, const std::vector<Notch>& fixed, LayoutDraw* draw) {
  const double len = std::hypot(b.x_m - a.x_m, b.y_m - a.y_m);
  const double ux = (b.x_m - a.x_m) / len;
  const double uy = (b.y_m - a.y_m) / len;
  auto at = [&](int ticks) { return Point2{a.x_m + ux * ticks_m(ticks), a.y_m + uy * ticks_m(ticks)}; };
  std::vector<Notch> out = fixed;
  int s = 0;
  for (;;) {
    const int gap = draw->uniform(50, 240);
    const int kind = draw->uniform(0, 99);
    const int size = draw->uniform(0, 6);  // width / room width step
    const int depth = draw->uniform(0, 10);
    const int room = 2 * draw->uniform(30, 60);
    const int lo = s + gap;
    Notch n{ticks_m(lo), 0.0, 0.0};
    int extent = 0;
    if (kind < 30) {  // pilaster
      extent = 6 + size;
      n.depth_m = -3 * kTick_m;
    } else if (kind < 55) {  // door recess
      extent = 18 + size;
      n.depth_m = ticks_m(4 + (4 * depth) / 10);
    } else if (kind < 75) {  // alcove
      extent = 30 + 5 * size;
      n.depth_m = ticks_m(12 + (18 * depth) / 10);
    } else {  // room behind a door
      extent = room;
      n.offset_m = ticks_m(lo + (room - 20) / 2);
      n.width_m = ticks_m(20);
      n.jamb_m = ticks_m(4);
      n.depth_m = ticks_m(50 + 5 * depth);
      n.room_width_m = ticks_m(room);
    }
    if (n.room_width_m == 0.0) n.width_m = ticks_m(extent);
    const int hi = lo + extent;
    if (ticks_m(hi) > len) break;
    if (!quiet(at(lo), at(hi))) out.push_back(n);
    s = hi;
  }
  std::sort(out.begin(), out.end(), [](const Notch& p, const Notch& q) { return p.offset_m < q.offset_m; });
  return out;
}

// A wall from a to b with its drawn features.
void featured_wall(WallBuilder* builder, LayoutDraw* draw, Point2 a, Point2 b, double nx, double ny,
                   const std::vector<Notch>& fixed = {}) {
  builder->wall(a, b, nx, ny, features(a, b, fixed, draw));
}

// A solid block [x0, x1] x [y0, y1] between corridors, walled anticlockwise (solid inside).
// `hall_bottom` / `hall_top`: the hall's recess into the block's bottom / top wall.
void block(WallBuilder* builder, LayoutDraw* draw, double x0, double y0, double x1, double y1,
           const std::vector<Notch>& hall_bottom, const std::vector<Notch>& hall_top) {
  featured_wall(builder, draw, {x0, y0}, {x1, y0}, 0.0, 1.0, hall_bottom);
  featured_wall(builder, draw, {x1, y0}, {x1, y1}, -1.0, 0.0);
  featured_wall(builder, draw, {x1, y1}, {x0, y1}, 0.0, -1.0, hall_top);
  featured_wall(builder, draw, {x0, y1}, {x0, y0}, 1.0, 0.0);
}

}  // namespace

World large_world() {
  World w;
  WallBuilder b(&w);
  LayoutDraw draw;
  const double east = kLargeRingWidth_m;  // ring centre-lines: x = 0, east; y = 0, north
  const double north = kLargeRingHeight_m;
  const double mid_x = 0.5 * east;  // cross corridors
  const double mid_y = 0.5 * north;
  // Outer wall, anticlockwise, solid outside: its rooms open off the ring.
  featured_wall(&b, &draw, {-kHalf_m, -kHalf_m}, {east + kHalf_m, -kHalf_m}, 0.0, -1.0);
  featured_wall(&b, &draw, {east + kHalf_m, -kHalf_m}, {east + kHalf_m, north + kHalf_m}, 1.0, 0.0);
  featured_wall(&b, &draw, {east + kHalf_m, north + kHalf_m}, {-kHalf_m, north + kHalf_m}, 0.0, 1.0);
  featured_wall(&b, &draw, {-kHalf_m, north + kHalf_m}, {-kHalf_m, -kHalf_m}, -1.0, 0.0);
  // The hall: a recess 8.5 m deep into the south-east block's top wall (which runs
  // from x = east - 1.5 westwards) and into the north-east block's bottom wall (eastwards
  // from x = mid_x + 1.5).
  const double hall_w = kLargeHallMaxX_m - kLargeHallMinX_m;
  const Notch hall_south{east - kHalf_m - kLargeHallMaxX_m, hall_w, (mid_y - kHalf_m) - kLargeHallMinY_m};
  const Notch hall_north{kLargeHallMinX_m - (mid_x + kHalf_m), hall_w, kLargeHallMaxY_m - (mid_y + kHalf_m)};
  block(&b, &draw, kHalf_m, kHalf_m, mid_x - kHalf_m, mid_y - kHalf_m, {}, {});                // south-west
  block(&b, &draw, mid_x + kHalf_m, kHalf_m, east - kHalf_m, mid_y - kHalf_m, {}, {hall_south});  // south-east
  block(&b, &draw, kHalf_m, mid_y + kHalf_m, mid_x - kHalf_m, north - kHalf_m, {}, {});            // north-west
  block(&b, &draw, mid_x + kHalf_m, mid_y + kHalf_m, east - kHalf_m, north - kHalf_m, {hall_north}, {});  // north-east
  // Pillars in the hall, 3.7 m or more off the corridor's centre-line and clear of its
  // middle (the centre-line keeps 8.5 m of clearance at x = 150).
  constexpr double kPillarHalf_m = 0.3;
  b.pillar(138.5, 55.0, kPillarHalf_m);
  b.pillar(142.5, 65.5, kPillarHalf_m);
  b.pillar(158.0, 64.0, kPillarHalf_m);
  b.pillar(161.5, 55.5, kPillarHalf_m);
  return w;
}

Route large_route() {
  Route r;
  r.waypoints = {
      {50.0, 0.0},  {100.0, 0.0},  {100.0, 60.0}, {0.0, 60.0},   {0.0, 0.0},   {50.0, 0.0},   // loop 1, 320 m
      {100.0, 0.0}, {100.0, 120.0}, {0.0, 120.0}, {0.0, 0.0},    {50.0, 0.0},                 // loop 2, 440 m
      {200.0, 0.0}, {200.0, 120.0}, {0.0, 120.0}, {0.0, 0.0},    {50.0, 0.0},                 // loop 3, 640 m
      {100.0, 0.0}, {100.0, 60.0},  {200.0, 60.0}, {200.0, 120.0}, {100.0, 120.0}, {100.0, 60.0},  // loop 4
      {100.0, 0.0}, {200.0, 0.0},   {200.0, 60.0}, {100.0, 60.0},  {100.0, 0.0},  {50.0, 0.0}};   // loop 5, home
  return r;
}

}  // namespace sdpslam::sim
