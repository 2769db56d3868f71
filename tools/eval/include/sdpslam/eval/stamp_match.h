#pragma once
// Matching of timestamps between files that should carry the same laser stamps.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "sdpslam/io/trajectory_io.h"

namespace sdpslam::eval {

// Stamps of different files name the same scan when they are equal to the microsecond
// (both come from the log's ipc_timestamp printed with six decimals). Files that were
// written with fewer decimals or through floating point are off by a few µs; a stamp then
// matches the nearest one within this tolerance (1 ms: a tenth of the shortest scan
// period of the benchmark logs, so it never picks a neighbouring scan).
inline constexpr std::int64_t kDefaultStampToleranceUs = 1000;

enum class StampMatch { kExact, kNearest, kNone };

// Index into `sorted` (ascending by stamp_us) of the pose whose stamp equals `stamp_us`,
// else of the nearest one within `tolerance_us` (the earlier one on a tie). Returns
// kNone (index untouched) when there is none. O(log n).
StampMatch find_stamp(const std::vector<io::StampedPose>& sorted, std::int64_t stamp_us, std::int64_t tolerance_us,
                      std::size_t* index);

// An estimated pose and the ground-truth pose of the same stamp.
struct PosePair {
  std::int64_t stamp_us = 0;
  Pose2 estimate;
  Pose2 truth;
};

// Every estimate paired with the ground-truth pose find_stamp() gives for its stamp
// (`ground_truth` need not be sorted), in the estimate's order; `*unmatched` (may be
// null) counts the estimates left without one. O((n + m) log m).
std::vector<PosePair> pair_by_stamp(const std::vector<io::StampedPose>& estimate,
                                    const std::vector<io::StampedPose>& ground_truth, std::int64_t tolerance_us,
                                    std::size_t* unmatched);

// The poses in ascending stamp order (stable: equal stamps keep their order), as
// find_stamp() needs them.
std::vector<io::StampedPose> sorted_by_stamp(std::vector<io::StampedPose> poses);

// True iff stamps are strictly increasing; otherwise `*bad_index` is the first pose whose
// stamp is not greater than its predecessor's.
bool stamps_strictly_increasing(const std::vector<io::StampedPose>& poses, std::size_t* bad_index);

}  // namespace sdpslam::eval
