#pragma once
// SE(2) pose of a planar robot: position in metres, heading in radians.
//
// Composition follows the usual convention: a.compose(b) is pose b expressed in the
// frame of a, mapped to the frame a is expressed in (a ⊕ b). between(a, b) = a⁻¹ ⊕ b,
// the displacement used by odometry deltas and by the relations metric (Kümmerle 2009).
// Trigonometry goes through det_math.h so that results are bit-identical across
// platforms (see there why).
#include <cstdint>

#include "sdpslam/core/det_math.h"

namespace sdpslam {

// Wraps an angle to (-pi, pi].
inline double normalize_angle_rad(double a) { return det::wrap_angle(a); }

struct Pose2 {
  double x_m = 0.0;
  double y_m = 0.0;
  double heading_rad = 0.0;

  // this ⊕ b
  Pose2 compose(const Pose2& b) const {
    const double c = det::cos(heading_rad);
    const double s = det::sin(heading_rad);
    return Pose2{x_m + c * b.x_m - s * b.y_m, y_m + s * b.x_m + c * b.y_m,
                 normalize_angle_rad(heading_rad + b.heading_rad)};
  }
  // this⁻¹
  Pose2 inverse() const {
    const double c = det::cos(heading_rad);
    const double s = det::sin(heading_rad);
    return Pose2{-c * x_m - s * y_m, s * x_m - c * y_m, normalize_angle_rad(-heading_rad)};
  }
  // Maps a point given in this pose's frame into the parent frame.
  void transform_point(double px_m, double py_m, double& out_x_m, double& out_y_m) const {
    const double c = det::cos(heading_rad);
    const double s = det::sin(heading_rad);
    out_x_m = x_m + c * px_m - s * py_m;
    out_y_m = y_m + s * px_m + c * py_m;
  }
};

// a⁻¹ ⊕ b: pose b expressed in the frame of pose a.
inline Pose2 between(const Pose2& a, const Pose2& b) { return a.inverse().compose(b); }

// A pose at an instant (microseconds on the log's or the robot's clock).
struct StampedPose {
  std::int64_t stamp_us = 0;
  Pose2 pose;
};

}  // namespace sdpslam
