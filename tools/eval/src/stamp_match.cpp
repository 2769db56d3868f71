#include "sdpslam/eval/stamp_match.h"

#include <algorithm>

namespace sdpslam::eval {

std::vector<io::StampedPose> sorted_by_stamp(std::vector<io::StampedPose> poses) {
  std::stable_sort(poses.begin(), poses.end(),
                   [](const io::StampedPose& x, const io::StampedPose& y) { return x.stamp_us < y.stamp_us; });
  return poses;
}

std::vector<PosePair> pair_by_stamp(const std::vector<io::StampedPose>& estimate,
                                    const std::vector<io::StampedPose>& ground_truth, std::int64_t tolerance_us,
                                    std::size_t* unmatched) {
  const std::vector<io::StampedPose> gt = sorted_by_stamp(ground_truth);
  std::vector<PosePair> pairs;
  pairs.reserve(estimate.size());
  std::size_t missed = 0;
  for (const io::StampedPose& e : estimate) {
    std::size_t k = 0;
    if (find_stamp(gt, e.stamp_us, tolerance_us, &k) == StampMatch::kNone) {
      ++missed;
      continue;
    }
    pairs.push_back({e.stamp_us, e.pose, gt[k].pose});
  }
  if (unmatched != nullptr) *unmatched = missed;
  return pairs;
}

StampMatch find_stamp(const std::vector<io::StampedPose>& sorted, std::int64_t stamp_us, std::int64_t tolerance_us,
                      std::size_t* index) {
  const auto it = std::lower_bound(sorted.begin(), sorted.end(), stamp_us,
                                   [](const io::StampedPose& p, std::int64_t s) { return p.stamp_us < s; });
  if (it != sorted.end() && it->stamp_us == stamp_us) {
    *index = static_cast<std::size_t>(it - sorted.begin());
    return StampMatch::kExact;
  }
  // Candidates: the last stamp below and the first above. Differences computed in
  // unsigned arithmetic: stamps may span the whole int64 range.
  bool found = false;
  std::uint64_t best = 0;
  std::size_t best_index = 0;
  auto consider = [&](std::size_t i) {
    const std::int64_t s = sorted[i].stamp_us;
    const std::uint64_t d = s > stamp_us ? static_cast<std::uint64_t>(s) - static_cast<std::uint64_t>(stamp_us)
                                         : static_cast<std::uint64_t>(stamp_us) - static_cast<std::uint64_t>(s);
    if (tolerance_us < 0 || d > static_cast<std::uint64_t>(tolerance_us)) return;
    if (!found || d < best) {
      found = true;
      best = d;
      best_index = i;
    }
  };
  const auto pos = static_cast<std::size_t>(it - sorted.begin());
  if (pos > 0) consider(pos - 1);
  if (pos < sorted.size()) consider(pos);
  if (!found) return StampMatch::kNone;
  *index = best_index;
  return StampMatch::kNearest;
}

bool stamps_strictly_increasing(const std::vector<io::StampedPose>& poses, std::size_t* bad_index) {
  for (std::size_t i = 1; i < poses.size(); ++i) {
    if (poses[i].stamp_us <= poses[i - 1].stamp_us) {
      if (bad_index != nullptr) *bad_index = i;
      return false;
    }
  }
  return true;
}

}  // namespace sdpslam::eval
