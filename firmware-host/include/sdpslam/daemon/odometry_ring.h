#pragma once
// Recent odometry poses and their interpolation to a laser scan's time stamp.
//
// Encoders and laser are sampled independently on the program's one monotonic clock
// (hal::MonotonicClock); a scan is placed with the odometry pose AT its stamp, found
// between the two odometry samples that bracket it. Between two samples the base is taken
// to move with constant linear and angular velocity, i.e. along the SE(2) geodesic
// a ⊕ exp(f · log(a⁻¹ ⊕ b)) — a constant-curvature arc, the same motion model as the
// differential-drive integration (protocols.md §4).
//
// Breaks: when the encoders go stale the motion during the outage is unknown; the caller
// marks a break and no interpolation ever spans it (the scan is refused, never given an
// invented pose). Samples further apart than max_gap_us are treated the same way.
//
// Memory: fixed (kCapacity samples inside the object); the oldest sample is overwritten.
#include <cstddef>
#include <cstdint>

#include "sdpslam/core/pose2.h"
#include "sdpslam/core/ring_buffer.h"

namespace sdpslam::daemon {

// The SE(2) geodesic between a (f = 0) and b (f = 1); f outside [0, 1] extrapolates.
Pose2 interpolate_se2(const Pose2& a, const Pose2& b, double f);

class OdometryRing {
 public:
  static constexpr std::size_t kCapacity = 256U;  // 2.5 s of 100 Hz encoders

  enum class Lookup : std::uint8_t {
    kOk,       // *out holds the interpolated pose (exact sample pose when a stamp matches)
    kNotYet,   // stamp newer than the newest sample (or no sample yet): wait for odometry
    kTooOld,   // stamp older than the oldest sample kept
    kGap,      // the bracketing samples straddle a break or are more than max_gap_us apart
  };

  // Appends a sample. False (and counted in refused_count) iff stamp_us is not newer
  // than the newest sample.
  bool push(std::int64_t stamp_us, const Pose2& pose);
  // The next push starts a new segment: nothing is interpolated across this point.
  void mark_break();
  Lookup interpolate(std::int64_t stamp_us, std::int64_t max_gap_us, Pose2* out) const;

  std::size_t size() const { return ring_.size(); }
  bool empty() const { return ring_.empty(); }
  std::int64_t newest_stamp_us() const { return ring_.empty() ? 0 : ring_.back().stamp_us; }
  std::int64_t oldest_stamp_us() const { return ring_.empty() ? 0 : ring_.front().stamp_us; }
  std::uint64_t refused_count() const { return refused_count_; }
  std::uint64_t break_count() const { return break_count_; }

 private:
  struct Sample {
    std::int64_t stamp_us = 0;
    Pose2 pose;
    bool segment_start = false;  // no interpolation between this and the previous sample
  };
  RingBuffer<Sample, kCapacity> ring_;
  bool break_pending_ = false;
  std::uint64_t refused_count_ = 0U;
  std::uint64_t break_count_ = 0U;
};

const char* to_string(OdometryRing::Lookup l);

}  // namespace sdpslam::daemon
