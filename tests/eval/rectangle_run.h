#pragma once
// A synthetic run for the evaluation tests: a robot driving round a 6 m × 4 m rectangle,
// one scan every 10 cm, and the segments such a run would be cut into.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "sdpslam/core/pose2.h"
#include "sdpslam/eval/frame_fit.h"
#include "sdpslam/io/trajectory_io.h"

namespace sdpslam::test {

inline constexpr std::int64_t kRectangleStart_us = 1000000000LL;
inline constexpr std::int64_t kRectanglePeriod_us = 100000;

// `laps` times round, 200 scans a lap, stamped kRectangleStart_us + k · kRectanglePeriod_us.
inline std::vector<io::StampedPose> rectangle_run(int laps) {
  std::vector<io::StampedPose> p;
  Pose2 pose{0.0, 0.0, 0.0};
  const double side_m[4] = {6.0, 4.0, 6.0, 4.0};
  for (int lap = 0; lap < laps; ++lap) {
    for (double side : side_m) {
      for (int k = 0; k < static_cast<int>(side / 0.1 + 0.5); ++k) {
        p.push_back({kRectangleStart_us + static_cast<std::int64_t>(p.size()) * kRectanglePeriod_us, pose});
        pose = pose.compose(Pose2{0.1, 0.0, 0.0});
      }
      pose = pose.compose(Pose2{0.0, 0.0, 3.14159265358979323846 / 2.0});
    }
  }
  return p;
}

// A segment every `per_segment` scans, each starting just before its first scan.
inline std::vector<eval::SegmentStart> segments_every(const std::vector<io::StampedPose>& run,
                                                      std::size_t per_segment) {
  std::vector<eval::SegmentStart> s;
  for (std::size_t i = 0; i < run.size(); i += per_segment) {
    s.push_back(eval::SegmentStart{static_cast<std::uint32_t>(s.size()), run[i].stamp_us - 1});
  }
  return s;
}

}  // namespace sdpslam::test
