#pragma once
// Where a relations error comes from: the placement of a run's submaps, or their insides.
//
// SDP-SLAM maps each segment of the path as a submap in its own frame and places the
// frames by the chain of segments and by loop closure (core/src/loops/frame_graph.h). A
// relation (relations.h) between two scans of one segment measures that submap's inside
// only; a relation between two segments also measures where the two frames were put.
// fit_segment_frames() moves every segment's frame rigidly, each segment's scans together,
// so as to minimise the mean translational error of the relations (the metric's own
// figure, Kümmerle et al. 2009, Eq. 2), and reports the error before and after, within
// and across segments. What the fit takes away is the most that a better placement of
// the same submaps could gain (loop closure, the pose graph); what it leaves lies within
// the submaps (the bottom level's filter) or in the relations themselves.
//
// The fit: the first segment with a relation across segments holds still (the metric
// is relative, so one frame is the gauge). Each other such segment gets a correction
// (dx, dy, dθ) that turns its scans about their mean position by dθ and shifts them by
// (dx, dy). The mean |t(E)| is minimised by iteratively reweighted least squares (weights
// 1 / max(|t(E)|, 1 mm): Weiszfeld's scheme for a sum of norms) with Levenberg–Marquardt
// steps on the dense normal equations (3 unknowns per segment; a step is kept only when it
// lowers the mean). Cost per step O(relations + (3 segments)³); deterministic.
// The corrections themselves are not reported: they are relative to the gauge, so a
// segment far along the path carries the drift of all those before it, and where the
// relations leave a frame free (a stretch joined to the rest by its two ends only) any
// placement along that freedom fits as well.
//
// Segments come from `sdpslam run`'s segments.tsv: "level start_stamp" per line, stamps
// in seconds; level l holds the scans after its start stamp up to the next line's start
// stamp, included (scans before the first start belong to the first segment).
#include <cstddef>
#include <cstdint>
#include <istream>
#include <string>
#include <vector>

#include "sdpslam/eval/relations.h"
#include "sdpslam/io/trajectory_io.h"

namespace sdpslam::eval {

struct SegmentStart {
  std::uint32_t level = 0U;
  std::int64_t start_us = 0;  // exclusive
};

// Reads segments.tsv ('#' lines and blank lines skipped). False iff the file cannot be
// read, a line is malformed, or the start stamps do not increase with the lines; `error`
// then says "file:line: reason" and `*segments` holds the lines read before.
bool read_segments(const std::string& path, std::vector<SegmentStart>* segments, std::string* error);
bool read_segments(std::istream& in, const std::string& name, std::vector<SegmentStart>* segments, std::string* error);

// Index into `segments` of the segment holding a scan stamped `stamp_us` (0 when it lies
// at or before the first start). `segments` ascending by start_us, not empty.
std::size_t segment_of(const std::vector<SegmentStart>& segments, std::int64_t stamp_us);

struct FrameFitPart {
  std::size_t count = 0;
  double mean_m = 0.0;         // mean |t(E)| as estimated
  double fitted_mean_m = 0.0;  // ... with the fitted frames
};

struct FrameFitResult {
  std::size_t segments_moved = 0;  // segments with a relation to another segment, less the gauge
  FrameFitPart all;
  FrameFitPart within;  // both scans in one segment (the fit cannot change these)
  FrameFitPart across;  // scans in two segments
  std::uint32_t steps = 0U;  // Levenberg–Marquardt steps taken
  // The last kept step lowered the mean by less than 1e-10 m, or no step could lower it.
  // False when the fit ran out of steps: the fitted means are then reached by some
  // placement, but the best one may go lower.
  bool converged = false;
};

// `per_scan` ascending by stamp (one pose per laser scan, as for evaluate_relations());
// relations whose stamps match no pose within tolerance_us are left out (evaluate_relations
// counts them). `segments` ascending by start_us and not empty.
FrameFitResult fit_segment_frames(const std::vector<Relation>& relations, const std::vector<io::StampedPose>& per_scan,
                                  const std::vector<SegmentStart>& segments,
                                  std::int64_t tolerance_us = kDefaultStampToleranceUs);

}  // namespace sdpslam::eval
