#include "top/combination_evaluator.h"

#include <cstring>

#include "sdpslam/core/box2.h"
#include "sdpslam/core/capacities.h"
#include "sdpslam/core/det_math.h"
#include "sdpslam/core/rng.h"

namespace sdpslam {

CombinationOptions CombinationOptions::from(const SdpOptions& sdp) {
  CombinationOptions o;
  o.max_pairs = sdp.max_pairs_per_sample;
  o.overlap_margin_m = sdp.overlap_margin_m;
  o.min_overlap_m2 = sdp.min_overlap_m2;
  o.icp = sdp.icp;
  o.correction_weight = sdp.icp_correction_weight;
  o.correction_lever_m = sdp.icp_correction_lever_m;
  return o;
}

bool CombinationOptions::valid() const {
  return max_pairs >= 1U && max_pairs <= kMaxPairs && overlap_margin_m >= 0.0 && min_overlap_m2 >= 0.0 &&
         correction_weight >= 0.0 && correction_lever_m >= 0.0;
}

bool CombinationEvaluator::init(const CombinationOptions& options, Icp2d* icp, Arena& arena) {
  memo_ = nullptr;
  if (!options.valid() || icp == nullptr || arena.available_bytes() < required_bytes()) return false;
  Memo* memo = arena.allocate_array<Memo>(kMemoSlots);
  if (memo == nullptr) return false;
  for (std::uint32_t i = 0; i < kMemoSlots; ++i) memo[i] = Memo{};
  options_ = options;
  icp_ = icp;
  memo_ = memo;
  return true;
}

void CombinationEvaluator::evaluate(const SubmapStore& store, std::uint32_t first, const std::uint32_t* chain,
                                    const Pose2* frames, std::uint32_t count, CombinationResult* out) {
  CombinationResult& res = *out;
  res.measured = false;
  res.error_m = 0.0;
  res.icp_matches = 0U;
  res.icp_failures = 0U;
  res.memo_hits = 0U;
  res.match_count = 0U;
  res.lo_level = first + count;
  res.hi_level = first;
  if (memo_ == nullptr || count == 0U) return;
  // Candidate pairs: (older, newer), non-adjacent, largest box overlap first.
  struct Cand {
    double area;
    std::int32_t older;   // live level index i (>= 0) or -(permanent slot + 1)
    std::uint32_t newer;  // live level index
  };
  Cand best[CombinationOptions::kMaxPairs];
  std::uint32_t nbest = 0U;
  const std::uint32_t kmax = options_.max_pairs;
  auto consider = [&](double area, std::int32_t older, std::uint32_t newer) {
    if (area < options_.min_overlap_m2 || area <= 0.0) return;
    std::uint32_t pos = nbest;
    while (pos > 0U && best[pos - 1U].area < area) --pos;
    if (pos >= kmax) return;
    const std::uint32_t last = nbest < kmax ? nbest : kmax - 1U;
    for (std::uint32_t k = last; k > pos; --k) best[k] = best[k - 1U];
    best[pos] = Cand{area, older, newer};
    if (nbest < kmax) ++nbest;
  };
  const double m = options_.overlap_margin_m;
  const std::uint32_t min_points = options_.icp.min_pairs;
  double gbox[capacity::kMaxPgsLevels][4];
  for (std::uint32_t i = 0; i < count; ++i) {
    const Submap& sm = store.submap(first + i, chain[i]);
    if (!sm.skeleton_done || sm.point_count < min_points || !box_valid(sm.box)) {
      gbox[i][0] = 1.0;
      gbox[i][2] = -1.0;
      gbox[i][1] = 1.0;
      gbox[i][3] = -1.0;
      continue;
    }
    box_transform(frames[i], sm.box, gbox[i]);
    box_grow(gbox[i], m, gbox[i]);
  }
  for (std::uint32_t j = 0; j < count; ++j) {
    if (!box_valid(gbox[j])) continue;
    for (std::uint32_t i = 0; i + 2U <= j; ++i) {
      if (box_valid(gbox[i])) consider(box_overlap_m2(gbox[i], gbox[j]), static_cast<std::int32_t>(i), j);
    }
    for (std::uint32_t k = 0; k < store.permanent_count(); ++k) {
      const std::uint32_t pi = store.permanent_slot_at(k);
      const PermanentSubmap& pm = store.permanent(pi);
      if (pm.level + 1U >= first + j || pm.point_count < min_points) continue;  // adjacent
      double pb[4];
      box_transform(pm.frame_in_global, pm.box, pb);
      consider(box_overlap_m2(pb, gbox[j]), -static_cast<std::int32_t>(pi) - 1, j);
    }
  }
  double sum = 0.0;
  double pairs = 0.0;
  for (std::uint32_t k = 0; k < nbest; ++k) {
    const Cand& c = best[k];
    const Submap& sn = store.submap(first + c.newer, chain[c.newer]);
    const bool permanent = c.older < 0;
    const std::uint32_t older = permanent ? static_cast<std::uint32_t>(-c.older - 1) : static_cast<std::uint32_t>(c.older);
    const Point2* target = nullptr;
    std::uint32_t tcount = 0U;
    Pose2 tframe;
    std::uint32_t older_level = first;
    if (!permanent) {
      target = store.points(first + older, chain[older]);
      tcount = store.submap(first + older, chain[older]).point_count;
      tframe = frames[older];
      older_level = first + older;
    } else {
      const PermanentSubmap& pm = store.permanent(older);
      target = store.permanent_points(older);
      tcount = pm.point_count;
      tframe = pm.frame_in_global;
    }
    const Pose2 guess = tframe.inverse().compose(frames[c.newer]);
    // Memo key: older submap (live level/node or permanent slot), newer level/node.
    const std::uint64_t older_id = !permanent
                                       ? (static_cast<std::uint64_t>(older_level) << 16U) | chain[older]
                                       : (1ULL << 63U) | static_cast<std::uint64_t>(older) << 16U | store.permanent(older).level;
    const std::uint64_t key =
        (older_id * 0x9E3779B97F4A7C15ULL) ^ ((static_cast<std::uint64_t>(first + c.newer) << 16U) | chain[c.newer]);
    std::uint64_t gh = key;
    const double gv[3] = {guess.x_m, guess.y_m, guess.heading_rad};
    for (double v : gv) {
      std::uint64_t b = 0U;
      std::memcpy(&b, &v, sizeof b);
      gh = splitmix64_next(gh) ^ b;
    }
    gh = splitmix64_next(gh);
    Memo& memo = memo_[gh % kMemoSlots];
    double e = 0.0;
    double w = 0.0;
    if (memo.valid && memo.key == key && memo.guess_hash == gh) {
      ++res.memo_hits;
      e = memo.error_m;
      w = memo.weight;
    } else {
      const Icp2dResult r =
          icp_->match(target, tcount, store.points(first + c.newer, chain[c.newer]), sn.point_count, guess, options_.icp);
      if (r.usable() && r.matched_pairs > 0U) {
        ++res.icp_matches;
        e = r.mean_nn_error_m;
        w = static_cast<double>(r.matched_pairs);
        CombinationMatch& mt = res.matches[res.match_count++];
        mt.older_permanent = permanent;
        mt.older_level = permanent ? store.permanent(older).level : older_level;
        mt.older = older;
        mt.newer = c.newer;
        mt.guess = guess;
        mt.transform = r.transform;
        if (options_.correction_weight > 0.0) {
          const Pose2 d = between(guess, r.transform);
          e += options_.correction_weight * (det::sqrt(d.x_m * d.x_m + d.y_m * d.y_m) +
                                             options_.correction_lever_m * (d.heading_rad < 0.0 ? -d.heading_rad : d.heading_rad));
        }
      } else if (r.status == Icp2dResult::Status::kInsufficientOverlap) {
        ++res.icp_failures;
        e = options_.icp.max_correspondence_m;
        w = static_cast<double>(options_.icp.min_pairs);
      }
      memo = Memo{key, gh, e, w, true};
    }
    if (!(w > 0.0)) continue;
    sum += e * w;
    pairs += w;
    if (older_level < res.lo_level) res.lo_level = older_level;
    if (first + c.newer > res.hi_level) res.hi_level = first + c.newer;
  }
  if (!(pairs > 0.0)) return;
  res.measured = true;
  res.error_m = sum / pairs;
}

}  // namespace sdpslam
