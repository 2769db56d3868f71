#pragma once
// Segmentation decision of SDP-SLAM (paper §III, Algorithm 1 line 4): "Our method was
// tested with a periodic segmentation at a fixed time and a segmentation based on the
// particles dispersion." Both are here:
//  - periodic: the segment ends when any of the enabled periods is reached: travelled
//    distance (odometry, summed per processed scan), log time, or processed scans;
//  - dispersion: the segment ends when the RMS distance of the bottom particles'
//    positions to their mean exceeds a threshold (the submaps start to disagree).
// In both modes a segment is at least min_segment_scans and at most max_segment_scans
// processed scans long (the upper bound keeps a segment's path storage bounded).
// Pure bookkeeping, O(1) per scan (O(N) for the dispersion), no heap, deterministic.
#include <cstdint>

#include "sdpslam/core/pose2.h"
#include "sdpslam/core/sdp_options.h"
#include "sdpslam/core/sdp_stats.h"  // SegmentEnd
#include "sdpslam/core/state_io.h"

namespace sdpslam {

class Segmenter {
 public:
  explicit Segmenter(const SdpOptions& options) : options_(options) {}

  // Starts a segment at this processed scan (its stamp and odometry pose).
  void start(std::int64_t stamp_us, const Pose2& odom);
  // Called after every processed scan of the segment with the bottom particles' poses;
  // says whether (and why) the segment ends at this scan.
  SegmentEnd on_processed(std::int64_t stamp_us, const Pose2& odom, const Pose2* particle_poses,
                          std::uint32_t particle_count);

  std::uint32_t scans() const { return scans_; }
  double travel_m() const { return travel_m_; }
  double last_dispersion_m() const { return last_dispersion_m_; }

  // RMS distance (m) of the positions to their mean; 0 for n < 2.
  static double dispersion_m(const Pose2* poses, std::uint32_t n);

  // The mutable state, for snapshots (core/state_io.h): what init() did not fix.
  void transfer_state(StateIo& io);

 private:
  const SdpOptions& options_;
  std::int64_t start_stamp_us_ = 0;
  Pose2 last_odom_{};
  std::uint32_t scans_ = 0U;
  double travel_m_ = 0.0;
  double last_dispersion_m_ = 0.0;
};

}  // namespace sdpslam
