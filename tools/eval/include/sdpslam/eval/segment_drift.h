#pragma once
// The ground-truth counterpart of frame_fit.h: how much of a run's error against a
// ground-truth trajectory lies within its submaps, and how much in where their frames
// were put.
//
// SDP-SLAM builds one submap per segment of the path with its bottom-level filter; the
// chain of segments and loop closure then place the submaps' frames
// (core/src/loops/frame_graph.h). With a ground truth for every scan both parts are
// measured exactly, without a fit:
//  - each segment's scans aligned on their own (the closed-form SE(2) alignment of
//    ate.h, per segment) leave the error inside the submap: the absolute error with
//    every frame where the ground truth wants it;
//  - a segment's drift is the error of the relative pose from its first scan to its
//    last, the bottom level's dead reckoning over the segment. Its component along the
//    ground truth's chord, summed over the segments and divided by their chords, is the
//    along-track scale error of the submaps (negative: they come out short).
// Evaluating another trajectory with the same segments (the log's raw odometry, written
// by `sdpslam simulate` as odometry.txt) says what dead reckoning alone does over the
// same stretches: a bottom level that drifts more than that loses to its own odometry.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "sdpslam/eval/frame_fit.h"
#include "sdpslam/io/trajectory_io.h"

namespace sdpslam::eval {

// Chords shorter than this give no along-track direction (a turn on the spot).
inline constexpr double kMinDriftChordM = 1.0;

struct SegmentDriftResult {
  std::size_t segments_measured = 0;  // segments with at least two matched scans
  std::size_t scans_matched = 0;
  double path_m = 0.0;                // ground-truth path length of those segments
  double endpoint_mean_m = 0.0;       // mean |translation error| from first to last scan
  double endpoint_max_m = 0.0;
  double drift_per_10m_m = 0.0;       // Σ endpoint error / Σ path × 10 m
  double heading_mean_rad = 0.0;      // mean |heading error| from first to last scan
  std::size_t chords_measured = 0;    // segments whose chord is at least kMinDriftChordM
  double along_track_scale = 0.0;     // Σ along-chord error / Σ chord (−0.01: 1 % short)
  double aligned_rmse_m = 0.0;        // position error with each segment aligned on its own
  double aligned_mean_m = 0.0;
};

// Pairs `estimate` with `ground_truth` by stamp (stamp_match.h), assigns each pair to its
// segment (segment_of), and measures as above. False iff no segment has two matched
// scans (`*result` then holds the counts). `segments` ascending by start_us, not empty.
bool measure_segment_drift(const std::vector<io::StampedPose>& estimate,
                           const std::vector<io::StampedPose>& ground_truth,
                           const std::vector<SegmentStart>& segments, std::int64_t tolerance_us,
                           SegmentDriftResult* result);

}  // namespace sdpslam::eval
