#pragma once
// Building walls of the built-in worlds (internal to sdpslam_sim): a straight wall with
// recesses and bumps along it, and square pillars. Each wall is one connected polyline,
// so a world made of closed chains of walls lets no ray out.
#include <cmath>
#include <vector>

#include "sdpslam/sim/world.h"

namespace sdpslam::sim::detail {

// A recess into the wall's solid side (depth > 0: alcove or side room) or a bump into
// the corridor (depth < 0: pilaster), `offset_m` along the wall from its start.
// With room_width_m > width_m the recess is a room behind a door: a doorway width_m wide
// through a wall jamb_m thick, opening onto a room room_width_m wide (centred on the
// doorway) and depth_m deep behind the wall.
struct Notch {
  double offset_m;
  double width_m;
  double depth_m;
  double room_width_m = 0.0;
  double jamb_m = 0.0;
};

class WallBuilder {
 public:
  explicit WallBuilder(World* world) : world_(world) {}

  // An axis-aligned wall from a to b; (nx, ny) is the unit normal pointing into the
  // solid side. Notches must be in increasing offset order, must not overlap (a room
  // counts with its full width) and must lie inside the wall.
  void wall(Point2 a, Point2 b, double nx, double ny, const std::vector<Notch>& notches) {
    const double len = std::hypot(b.x_m - a.x_m, b.y_m - a.y_m);
    const double ux = (b.x_m - a.x_m) / len;
    const double uy = (b.y_m - a.y_m) / len;
    Point2 prev = a;
    auto at = [&](double s, double d) { return Point2{a.x_m + ux * s + nx * d, a.y_m + uy * s + ny * d}; };
    for (const Notch& n : notches) {
      if (n.room_width_m > n.width_m) {
        const double lo = n.offset_m + 0.5 * (n.width_m - n.room_width_m);
        const double hi = lo + n.room_width_m;
        const double back = n.jamb_m + n.depth_m;
        const Point2 chain[8] = {at(n.offset_m, 0.0), at(n.offset_m, n.jamb_m), at(lo, n.jamb_m), at(lo, back),
                                 at(hi, back),         at(hi, n.jamb_m),         at(n.offset_m + n.width_m, n.jamb_m),
                                 at(n.offset_m + n.width_m, 0.0)};
        for (const Point2& p : chain) {
          add(prev, p);
          prev = p;
        }
        continue;
      }
      const Point2 p0 = at(n.offset_m, 0.0);
      const Point2 p1 = at(n.offset_m, n.depth_m);
      const Point2 p2 = at(n.offset_m + n.width_m, n.depth_m);
      const Point2 p3 = at(n.offset_m + n.width_m, 0.0);
      add(prev, p0);
      add(p0, p1);
      add(p1, p2);
      add(p2, p3);
      prev = p3;
    }
    add(prev, b);
  }

  void pillar(double cx_m, double cy_m, double half_m) {
    const Point2 p[4] = {{cx_m - half_m, cy_m - half_m}, {cx_m + half_m, cy_m - half_m},
                         {cx_m + half_m, cy_m + half_m}, {cx_m - half_m, cy_m + half_m}};
    for (int i = 0; i < 4; ++i) add(p[i], p[(i + 1) % 4]);
  }

 private:
  void add(Point2 a, Point2 b) {
    if (a.x_m == b.x_m && a.y_m == b.y_m) return;
    world_->segments.push_back(Segment{a, b});
  }
  World* world_;
};

}  // namespace sdpslam::sim::detail
