#pragma once
// One planar laser scan as the core consumes it, whatever sensor or log it came from.
//
// Beam i points at angle_min_rad + i * angle_increment_rad in the laser frame (x forward,
// y left, counter-clockwise positive); the laser frame sits at laser_in_base in the
// robot's base frame. A beam's range_m means:
//   - range_min_m <= range_m < range_max_m : a return (obstacle at that distance);
//   - range_m >= range_max_m               : no return within range (free up to max);
//   - otherwise (below range_min_m, 0, NaN): invalid, carries no information.
// Fixed capacity (capacity::kMaxBeams); copying a RangeScan never allocates.
#include <cstdint>

#include "sdpslam/core/capacities.h"
#include "sdpslam/core/pose2.h"

namespace sdpslam {

struct ScanGeometry {
  float angle_min_rad = 0.0F;
  float angle_increment_rad = 0.0F;
  float range_min_m = 0.0F;
  float range_max_m = 0.0F;
  Pose2 laser_in_base;  // laser mounting pose on the robot
};

struct RangeScan {
  std::int64_t stamp_us = 0;
  ScanGeometry geometry;
  std::uint32_t beam_count = 0U;
  float ranges_m[capacity::kMaxBeams] = {};

  enum class Beam : std::uint8_t { kReturn, kNoReturn, kInvalid };
  Beam classify(std::uint32_t i) const {
    const float r = ranges_m[i];
    if (!(r >= geometry.range_min_m) || r <= 0.0F) return Beam::kInvalid;  // also NaN
    return r >= geometry.range_max_m ? Beam::kNoReturn : Beam::kReturn;
  }
  float beam_angle_rad(std::uint32_t i) const {
    return geometry.angle_min_rad + static_cast<float>(i) * geometry.angle_increment_rad;
  }
};

// Odometry pose (integrated wheel odometry, in the odometry frame) at a time stamp.
struct OdometrySample {
  std::int64_t stamp_us = 0;
  Pose2 pose;
};

}  // namespace sdpslam
