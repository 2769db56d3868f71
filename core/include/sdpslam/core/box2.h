#pragma once
// Axis-aligned boxes of submaps, as double[4] = {x0, y0, x1, y1} (m): the bounds of a
// submap's skeleton points in its frame, and those bounds placed in a parent frame.
// Used by the top level (which pairs of submaps overlap) and by loop closure (which
// older submaps a newer one may revisit).
#include "sdpslam/core/pose2.h"

namespace sdpslam {

// An empty box (box_valid() false until a point is added).
inline void box_init(double b[4]) {
  b[0] = 1.0e300;
  b[1] = 1.0e300;
  b[2] = -1.0e300;
  b[3] = -1.0e300;
}
inline void box_add(double b[4], double x, double y) {
  if (x < b[0]) b[0] = x;
  if (y < b[1]) b[1] = y;
  if (x > b[2]) b[2] = x;
  if (y > b[3]) b[3] = y;
}
inline bool box_valid(const double b[4]) { return b[0] <= b[2] && b[1] <= b[3]; }

// Axis-aligned bounds, in the parent frame, of box `b` given in `frame`.
inline void box_transform(const Pose2& frame, const double b[4], double out[4]) {
  box_init(out);
  const double xs[2] = {b[0], b[2]};
  const double ys[2] = {b[1], b[3]};
  for (double x : xs) {
    for (double y : ys) {
      double gx = 0.0;
      double gy = 0.0;
      frame.transform_point(x, y, gx, gy);
      box_add(out, gx, gy);
    }
  }
}

// Box `b` grown by `by_m` on every side, into `out` (which may be `b`).
inline void box_grow(const double b[4], double by_m, double out[4]) {
  out[0] = b[0] - by_m;
  out[1] = b[1] - by_m;
  out[2] = b[2] + by_m;
  out[3] = b[3] + by_m;
}

// Area (m²) of the overlap of two boxes; 0 when they do not overlap.
inline double box_overlap_m2(const double a[4], const double b[4]) {
  const double x0 = a[0] > b[0] ? a[0] : b[0];
  const double y0 = a[1] > b[1] ? a[1] : b[1];
  const double x1 = a[2] < b[2] ? a[2] : b[2];
  const double y1 = a[3] < b[3] ? a[3] : b[3];
  if (!(x1 > x0) || !(y1 > y0)) return 0.0;
  return (x1 - x0) * (y1 - y0);
}

}  // namespace sdpslam
