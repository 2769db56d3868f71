#pragma once
// The error of one combination of submaps (paper §III, Algorithm 1 line 11: the "ICP
// nearest neighbour error" that weights a top-level particle).
//
// The combination's live submaps are placed in one frame by composing the PGS chain
// (the caller passes those frames). Pairs of non-adjacent submaps whose global bounding
// boxes overlap by at least min_overlap_m2 (boxes grown by overlap_margin_m; permanent
// submaps included as the older one) are ranked by that overlap, and the largest
// max_pairs are matched with ICP on their skeleton points, from the composed chain as
// the initial guess. The combination's error is the mean nearest-neighbour distance
// over every matched point pair. A pair whose boxes overlap but whose ICP finds too few
// correspondences counts as icp.max_correspondence_m over icp.min_pairs pairs (a gross
// misalignment must not look like "no overlap"). With correction_weight > 0 the move ICP
// made from the guess is charged too: weight × (|Δt| + lever × |Δθ|).
//
// Many samples share a pair of submaps placed identically (elite copies, common
// chains), and ICP is deterministic, so results are memoised: direct-mapped, keyed by
// the two submaps and the bits of the initial guess.
//
// The result names the levels the measured pairs span (the PGS edges the error goes to,
// equation (4)) and lists the fresh ICP matches, so that the caller can hand them on
// (loop closure refines them on obstacle points). Nothing here calls another part.
//
// Memory: init() carves the memo from an Arena; evaluate() allocates nothing.
#include <cstddef>
#include <cstdint>

#include "sdpslam/core/arena.h"
#include "sdpslam/core/pose2.h"
#include "sdpslam/core/sdp_options.h"
#include "sdpslam/core/top/icp2d.h"
#include "top/submap_store.h"

namespace sdpslam {

struct CombinationOptions {
  std::uint32_t max_pairs = 6U;  // pairs matched per combination, 1 .. kMaxPairs
  double overlap_margin_m = 0.0;
  double min_overlap_m2 = 4.0;
  Icp2dOptions icp{};
  double correction_weight = 0.0;
  double correction_lever_m = 1.0;

  static constexpr std::uint32_t kMaxPairs = 64U;
  // The [sdp] options these come from (SdpOptions::validate checks their ranges).
  static CombinationOptions from(const SdpOptions& sdp);
  bool valid() const;
};

// A fresh ICP match of two submaps of the combination.
struct CombinationMatch {
  bool older_permanent = false;
  std::uint32_t older_level = 0U;
  std::uint32_t older = 0U;  // live: its index in the chain; permanent: its store slot
  std::uint32_t newer = 0U;  // its index in the chain
  Pose2 guess;               // newer's frame in older's, from the chain
  Pose2 transform;           // ... as ICP found it
};

struct CombinationResult {
  bool measured = false;  // some pair was matched (false: the weight is left as it is, §IV)
  double error_m = 0.0;
  std::uint32_t lo_level = 0U;  // the oldest and newest live or permanent level measured
  std::uint32_t hi_level = 0U;
  std::uint32_t icp_matches = 0U;   // usable ICP results computed
  std::uint32_t icp_failures = 0U;  // overlapping boxes, too few correspondences
  std::uint32_t memo_hits = 0U;     // pair results reused
  std::uint32_t match_count = 0U;
  CombinationMatch matches[CombinationOptions::kMaxPairs];  // the usable fresh matches, in order
};

class CombinationEvaluator {
 public:
  static constexpr std::uint32_t kMemoSlots = 1024U;

  CombinationEvaluator() = default;
  CombinationEvaluator(const CombinationEvaluator&) = delete;
  CombinationEvaluator& operator=(const CombinationEvaluator&) = delete;

  static std::size_t required_bytes() { return Arena::bytes_for<Memo>(kMemoSlots); }
  // `icp` (not owned) does the matching. False iff the options are invalid or the arena
  // is too small.
  bool init(const CombinationOptions& options, Icp2d* icp, Arena& arena);
  const CombinationOptions& options() const { return options_; }

  // The combination choosing chain[i] at live level first_level + i, whose frames in the
  // global frame are frames[i] (i < count), against the store's submaps (permanent ones
  // at their frame_in_global).
  void evaluate(const SubmapStore& store, std::uint32_t first_level, const std::uint32_t* chain,
                const Pose2* frames, std::uint32_t count, CombinationResult* result);

 private:
  struct Memo {
    std::uint64_t key = 0U;
    std::uint64_t guess_hash = 0U;
    double error_m = 0.0;
    double weight = 0.0;  // matched pairs; 0 = no usable result
    bool valid = false;
  };

  CombinationOptions options_{};
  Icp2d* icp_ = nullptr;
  Memo* memo_ = nullptr;  // kMemoSlots
};

}  // namespace sdpslam
