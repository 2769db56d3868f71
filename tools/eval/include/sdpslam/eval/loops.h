#pragma once
// The loop constraints of a run (`sdpslam run`'s loops.tsv, slam_outputs.h) checked
// against a ground-truth trajectory: how many were right, and how far off the others
// were. A loop constraint z joins the frames of two levels; a level's frame follows from
// where it started (SdpSlam::level_origin): the robot was at pose `initial` in that frame
// at the stamp, so with the ground truth GT the frame is F = GT(stamp) ⊕ initial⁻¹ and
// the true constraint is F_older⁻¹ ⊕ F_newer. Its error is z's difference from that:
// the translation of (true)⁻¹ ⊕ z and the wrapped heading. Wrong loops (a corridor
// matched one door along, a hall matched rotated) are what loop verification must keep
// out of the pose graph; this counts them.
#include <cstddef>
#include <cstdint>
#include <istream>
#include <string>
#include <vector>

#include "sdpslam/core/pose2.h"
#include "sdpslam/io/trajectory_io.h"

namespace sdpslam::eval {

struct LoopLine {
  std::uint32_t older_level = 0U;
  std::uint32_t newer_level = 0U;
  bool searched = false;  // found by the wide loop search (else by the top level's ICP)
  bool used = false;      // both levels in the pose graph at the end
  double residual_m = 0.0;
  Pose2 z;
  bool older_known = false;  // origin held ("-" in the file: not)
  bool newer_known = false;
  std::int64_t older_stamp_us = 0;
  std::int64_t newer_stamp_us = 0;
  Pose2 older_initial;
  Pose2 newer_initial;
};

// Reads loops.tsv ('#' lines are comments). False with "path:line: why" on the first
// malformed line; the lines before it are kept.
bool read_loops(std::istream& in, const std::string& name, std::vector<LoopLine>* lines, std::string* error);
bool read_loops(const std::string& path, std::vector<LoopLine>* lines, std::string* error);

// Error bins (translation): right within kLoopRightM, wrong beyond kLoopWrongM, and
// between. Reporting bins, not tuning: a loop constraint 2 m off folds a map.
inline constexpr double kLoopRightM = 0.5;
inline constexpr double kLoopWrongM = 2.0;

struct LoopBins {
  std::size_t count = 0;    // with both origins matched to the ground truth
  std::size_t right = 0;    // error < kLoopRightM
  std::size_t between = 0;
  std::size_t wrong = 0;    // error >= kLoopWrongM
  double max_m = 0.0;
  void add(double error_m);
};

struct LoopCheck {
  bool matched = false;  // both origins known and found in the ground truth
  double error_m = 0.0;
  double heading_error_rad = 0.0;
};

struct LoopsResult {
  std::size_t count = 0;      // lines read
  std::size_t unmatched = 0;  // an origin unknown or without ground truth within the tolerance
  LoopBins search;            // the wide search's constraints
  LoopBins icp;               // the top level's ICP constraints
  LoopBins used;              // either source, used at the end
  std::vector<LoopCheck> checks;  // per line, in file order
};

// `ground_truth` need not be sorted.
LoopsResult check_loops(const std::vector<LoopLine>& lines, const std::vector<io::StampedPose>& ground_truth,
                        std::int64_t tolerance_us);

}  // namespace sdpslam::eval
