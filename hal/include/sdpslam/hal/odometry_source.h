#pragma once
// Source of odometry poses (dead reckoning of the base), e.g. integrated wheel encoders.
#include <cstdint>

#include "sdpslam/core/pose2.h"

namespace sdpslam::hal {

enum class OdometryStatus : std::uint8_t {
  kValid,     // pose integrated up to stamp_us from fresh data
  kNoData,    // nothing received yet
  kLatching,  // first sample seen and latched; no motion known yet
  kStale,     // input stopped (a wheel is stale): the pose is the last known one and
              // does NOT account for motion since stamp_us; never extrapolated
};

struct OdometryReading {
  Pose2 pose;                 // in the odometry frame (origin = pose at the first latch)
  std::int64_t stamp_us = 0;  // monotonic time of the newest data used for `pose`
  OdometryStatus status = OdometryStatus::kNoData;
  bool valid() const { return status == OdometryStatus::kValid; }
};

class OdometrySource {
 public:
  virtual ~OdometrySource() = default;
  // Non-blocking: pulls and integrates whatever new input is available. Returns the
  // number of integration steps taken (>= 0) or < 0 when the input failed.
  virtual int update() = 0;
  // The pose at the newest integrated stamp, with its status.
  virtual OdometryReading latest() const = 0;
};

const char* to_string(OdometryStatus status);

inline const char* to_string(OdometryStatus status) {
  switch (status) {
    case OdometryStatus::kValid: return "valid";
    case OdometryStatus::kNoData: return "no-data";
    case OdometryStatus::kLatching: return "latching";
    case OdometryStatus::kStale: return "stale";
  }
  return "?";
}

}  // namespace sdpslam::hal
