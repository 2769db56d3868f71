#include "loops/loop_closure.h"

#include "sdpslam/core/box2.h"
#include "sdpslam/core/det_math.h"

namespace sdpslam {
namespace {

// The search's coarse pass works in blocks of this many grid cells.
constexpr std::uint32_t kSearchCoarseCells = 4U;

// The widest window a search may have (LoopClosure::search_window_m).
double widest_window_m(const SdpOptions& s) {
  return s.loop_search_max_window_m > s.loop_search_window_m ? s.loop_search_max_window_m : s.loop_search_window_m;
}

std::uint32_t search_steps(const SdpOptions& s, const LoopSearchGeometry& g) {
  return CorrelativeMatcher::steps_for(widest_window_m(s), g.resolution_m, kSearchCoarseCells);
}

FrameGraphOptions graph_options(const SdpOptions& s, std::uint32_t max_nodes) {
  FrameGraphOptions o;
  o.max_nodes = max_nodes;
  o.max_loops = s.max_loop_constraints;
  o.iterations = s.graph_iterations;
  o.robust_chi = s.loop_robust_chi;
  return o;
}

}  // namespace

std::size_t LoopClosure::required_bytes(const SdpOptions& s, std::uint32_t max_nodes, const LoopSearchGeometry& g) {
  if (!s.loop_closure) return 0U;
  std::size_t total = Arena::bytes_for<Record>(s.max_loop_constraints) + FrameGraph::required_bytes(graph_options(s, max_nodes));
  if (s.loop_search_window_m > 0.0) {
    total += CorrelativeMatcher::required_bytes(g.grid_side, s.loop_points, search_steps(s, g)) +
             2U * Arena::bytes_for<Point2>(s.loop_points) + Arena::bytes_for<std::uint32_t>(max_nodes);
  }
  return total;
}

bool LoopClosure::init(const SdpOptions& s, std::uint32_t max_nodes, const LoopSearchGeometry& g, Icp2d* icp,
                       LoopSubmaps* submaps, LoopClosureStats* stats, Arena& arena) {
  options_ = s;
  geometry_ = g;
  icp_ = icp;
  submaps_ = submaps;
  stats_ = stats;
  max_nodes_ = max_nodes;
  count_ = 0U;
  search_level_ = 0U;
  search_count_ = 0U;
  search_cursor_ = 0U;
  recentring_ = false;
  records_ = arena.allocate_array<Record>(s.max_loop_constraints);
  if (records_ == nullptr || !graph_.init(graph_options(s, max_nodes), arena)) return false;
  if (s.loop_search_window_m > 0.0) {
    search_a_ = arena.allocate_array<Point2>(s.loop_points);
    search_b_ = arena.allocate_array<Point2>(s.loop_points);
    hops_ = arena.allocate_array<std::uint32_t>(max_nodes);
    if (search_a_ == nullptr || search_b_ == nullptr || hops_ == nullptr ||
        !matcher_.init(g.grid_side, s.loop_points, search_steps(s, g), arena)) {
      return false;
    }
  }
  return icp_ != nullptr && submaps_ != nullptr && stats_ != nullptr;
}

// A record can never join the graph again once one of its levels was forgotten.
bool LoopClosure::record_dead(const Record& r) const {
  std::uint32_t index = 0U;
  return !submaps_->node_index(r.older_level, &index) || !submaps_->node_index(r.newer_level, &index);
}

Icp2dOptions LoopClosure::icp_options() const {
  Icp2dOptions fine = options_.icp;
  fine.max_correspondence_m = options_.loop_icp_max_correspondence_m;
  fine.min_pairs = options_.loop_min_pairs;
  return fine;
}

// The pairing's direction information M (icp2d.h) weights the constraint per direction
// (FrameInfo::from_directions): a corridor match keeps its across-corridor information.
FrameInfo LoopClosure::information(const Point2* target, std::uint32_t target_count, const Point2* source,
                                   std::uint32_t source_count, const Pose2& z) {
  const FrameInfo iso = FrameInfo::from_sigma(options_.loop_sigma_xy_m, options_.loop_sigma_theta_rad);
  if (!(options_.loop_normal_radius_m > 0.0)) return iso;
  Icp2dInformation m;
  if (!icp_->direction_information(target, target_count, source, source_count, z, icp_options(),
                                   options_.loop_normal_radius_m, &m)) {
    ++stats_->loop_information_unmeasured;
    return iso;
  }
  const FrameInfo info = FrameInfo::from_directions(options_.loop_sigma_xy_m, options_.loop_sigma_theta_rad, m.xx, m.xy,
                                                    m.yy, options_.loop_weak_direction_floor, z.heading_rad);
  if (!info.valid()) {
    ++stats_->loop_information_unmeasured;
    return iso;
  }
  // Weak: some direction keeps less than half of the isotropic information.
  if (info.xx * info.yy - info.xy * info.xy < 0.5 * iso.xx * iso.yy) ++stats_->loop_constraints_weak_direction;
  return info;
}

void LoopClosure::refine(std::uint32_t older_level, const Point2* older, std::uint32_t older_count,
                         std::uint32_t newer_level, const Point2* newer, std::uint32_t newer_count, const Pose2& guess,
                         const Pose2& skeleton) {
  if (older_count < options_.loop_min_pairs || newer_count < options_.loop_min_pairs) return;
  const Icp2dResult f = icp_->match(older, older_count, newer, newer_count, skeleton, icp_options());
  ++stats_->loop_refinements;
  const Pose2 moved = between(guess, f.transform);
  if (!(f.usable() && f.mean_nn_error_m <= options_.loop_max_error_m && f.matched_pairs >= options_.loop_min_pairs &&
        det::sqrt(moved.x_m * moved.x_m + moved.y_m * moved.y_m) <= options_.loop_max_correction_m)) {
    return;
  }
  record(matched(older_level, older, older_count, newer_level, newer, newer_count, f, false));
}

LoopClosure::Record LoopClosure::matched(std::uint32_t older_level, const Point2* older, std::uint32_t older_count,
                                         std::uint32_t newer_level, const Point2* newer, std::uint32_t newer_count,
                                         const Icp2dResult& f, bool searched) {
  Record r;
  r.older_level = older_level;
  r.newer_level = newer_level;
  r.z = f.transform;
  r.error_m = f.mean_nn_error_m;
  r.info = information(older, older_count, newer, newer_count, f.transform);
  r.searched = searched;
  return r;
}

// One record per pair of levels. Two estimates of the same loop (within a coarse block
// of the search's grid of each other: the reach of the search's ICP polish) keep the
// lower residual, verified if either was. Estimates farther apart are rival optima of
// the pair: the wide search's exact, unambiguous peak (verified) wins over the top
// level's ICP, whatever their residuals (a match that slid along a corridor fits its
// walls as well as the true one does); between two of a kind the lower residual wins.
// When the store is full a dead record makes room, else the worst record if the new
// one is better.
void LoopClosure::record(const Record& r) {
  std::uint32_t worst = count_;
  std::uint32_t dead = count_;
  for (std::uint32_t k = 0; k < count_; ++k) {
    Record& q = records_[k];
    if (q.older_level == r.older_level && q.newer_level == r.newer_level) {
      const double dx = r.z.x_m - q.z.x_m;
      const double dy = r.z.y_m - q.z.y_m;
      const double block = static_cast<double>(kSearchCoarseCells) * geometry_.resolution_m;
      if (q.searched != r.searched && dx * dx + dy * dy > block * block) {
        if (r.searched) {
          q = r;
        } else if (r.error_m < q.error_m) {
          ++stats_->loop_rivals_refused;  // it would have won on its residual
        }
        return;
      }
      if (r.error_m < q.error_m) {
        const bool searched = q.searched || r.searched;
        q = r;
        q.searched = searched;
      }
      return;
    }
    if (dead == count_ && count_ == options_.max_loop_constraints && record_dead(q)) dead = k;
    if (worst == count_ || q.error_m > records_[worst].error_m) worst = k;
  }
  ++stats_->loop_records_added;
  if (count_ < options_.max_loop_constraints) {
    records_[count_++] = r;
  } else if (dead < count_) {
    records_[dead] = r;
  } else if (worst < count_ && r.error_m < records_[worst].error_m) {
    records_[worst] = r;
    ++stats_->loop_records_dropped;
  } else {
    ++stats_->loop_records_dropped;
  }
  stats_->loop_records = count_;
}

FrameGraph& LoopClosure::begin_adjustment() {
  graph_.clear();
  return graph_;
}

bool LoopClosure::finish_adjustment() {
  FrameGraph& g = graph_;
  std::uint32_t used = 0U;
  for (std::uint32_t k = 0; k < count_; ++k) {
    const Record& r = records_[k];
    std::uint32_t a = 0U, b = 0U;
    if (!submaps_->node_index(r.older_level, &a) || !submaps_->node_index(r.newer_level, &b)) continue;
    // The search's constraints were verified before they were recorded (search_continue);
    // the top level's ICP constraints were not, and keep their kernel.
    const double chi = r.searched ? FrameGraph::kNoKernel : options_.loop_robust_chi;
    if (g.add_loop(a, b, r.z, r.info, chi)) {
      ++used;
    } else {
      ++stats_->frame_graph_refused;
    }
  }
  stats_->loop_constraints_used = used;
  if (used == 0U) return false;  // the chain alone is already consistent
  const std::uint64_t refused_before = g.stats().refused_steps;
  const std::uint64_t capped_before = g.stats().capped;
  g.optimise();
  ++stats_->frame_adjustments;
  stats_->frame_steps_refused += g.stats().refused_steps - refused_before;
  stats_->frame_adjustments_capped += g.stats().capped - capped_before;
  stats_->loop_downweighted = g.stats().last_downweighted;
  return true;
}

// ---- wide loop search (correlative_matcher.h) -------------------------------------------

// A search in progress continues; else the next candidate of the level being searched
// starts, else the newest level's candidates are collected (each level once, as soon as
// it is the newest).
// Newest first: the robot is in the newest level's submap, and a loop found for it
// corrects the frames it is mapping in now. So once a newer level exists, what is left
// of the current level's candidates is dropped, and levels that were passed over while
// one pair was being searched are not searched at all (both counted). A search that went
// on level by level instead would fall behind the robot for good wherever a level has
// more candidates than a segment's scans can search.
void LoopClosure::search_step() {
  if (!(options_.loop_search_window_m > 0.0) || hops_ == nullptr) return;
  if (matcher_.active()) {
    search_continue();
    return;
  }
  const std::uint32_t end = submaps_->level_end();
  if (search_cursor_ < search_count_ && search_level_ < end) {
    stats_->loop_search_candidates_dropped += search_count_ - search_cursor_;
    search_cursor_ = search_count_;
  }
  if (search_cursor_ >= search_count_) {
    const std::uint32_t first = submaps_->first_live_level();
    if (search_level_ < first) search_level_ = first;
    if (search_level_ >= end) return;
    if (search_level_ + 1U < end) {
      // Passed over: [search_level_, end - 1). Only a level two past the oldest held one
      // can have a candidate (adjacent levels never are).
      const std::uint32_t can = submaps_->first_held_level() + 2U;
      const std::uint32_t from = search_level_ > can ? search_level_ : can;
      if (from < end - 1U) stats_->loop_search_levels_skipped += end - 1U - from;
      search_level_ = end - 1U;
    }
    search_newer_ = search_level_++;
    search_collect(search_newer_);
    if (search_count_ == 0U) return;
  }
  search_pair(search_older_[search_cursor_++], search_newer_);
}

// Older held levels (not adjacent, not already constrained to it) whose boxes in the
// best combination overlap the newer's box grown by the window the pair would be
// searched with (search_window_m: the drift bound between the two, within
// [loop_search_window_m, loop_search_max_window_m]), so that every submap the search
// could recover is a candidate; the loop_search_candidates largest overlaps. The others
// are not searched for this level, and are counted (loop_search_candidates_dropped).
void LoopClosure::search_collect(std::uint32_t newer) {
  search_count_ = 0U;
  search_cursor_ = 0U;
  std::uint32_t n = 0U;
  Pose2 frame;
  double box[4];
  if (!submaps_->placement(newer, &frame, box, &n) || n < options_.loop_min_pairs || !box_valid(box)) return;
  double nb[4];
  box_transform(frame, box, nb);
  // The widest any pair is searched with: a cheap first test before the pair's own.
  const double widest = widest_window_m(options_);
  double area[SdpOptions::kMaxLoopSearchCandidates];
  const std::uint32_t kmax = options_.loop_search_candidates;
  for (std::uint32_t older = submaps_->first_held_level(); older + 2U <= newer; ++older) {
    std::uint32_t on = 0U;
    Pose2 of;
    double ob[4];
    if (!submaps_->placement(older, &of, ob, &on) || on < options_.loop_min_pairs || !box_valid(ob)) continue;
    bool constrained = false;
    for (std::uint32_t k = 0; k < count_ && !constrained; ++k) {
      constrained = records_[k].older_level == older && records_[k].newer_level == newer;
    }
    if (constrained) continue;
    double gb[4];
    box_transform(of, ob, gb);
    double grown[4];
    box_grow(nb, widest, grown);
    if (!(box_overlap_m2(gb, grown) > 0.0)) continue;
    box_grow(nb, search_window_m(older, newer), grown);
    const double a = box_overlap_m2(gb, grown);
    if (a < options_.min_overlap_m2 || !(a > 0.0)) continue;
    std::uint32_t pos = search_count_ < kmax ? search_count_ : kmax;
    if (pos == kmax) ++stats_->loop_search_candidates_dropped;  // this one or the smallest so far
    if (pos == kmax && !(a > area[kmax - 1U])) continue;
    if (pos == kmax) pos = kmax - 1U;
    while (pos > 0U && area[pos - 1U] < a) {
      area[pos] = area[pos - 1U];
      search_older_[pos] = search_older_[pos - 1U];
      --pos;
    }
    area[pos] = a;
    search_older_[pos] = older;
    if (search_count_ < kmax) ++search_count_;
  }
}

void LoopClosure::search_pair(std::uint32_t older, std::uint32_t newer) {
  std::uint32_t tn = 0U;
  std::uint32_t sn = 0U;
  Pose2 tframe;
  Pose2 sframe;
  double tb[4];
  double sb[4];
  // Either level may have been forgotten, or its choice changed, since it was collected.
  if (!submaps_->placement(older, &tframe, tb, &tn) || !submaps_->placement(newer, &sframe, sb, &sn)) return;
  ++stats_->loop_searches;
  submaps_->obstacles(older, search_a_);
  submaps_->obstacles(newer, search_b_);
  search_pair_older_ = older;
  search_pair_newer_ = newer;
  search_a_count_ = tn;
  search_b_count_ = sn;
  recentring_ = false;
  if (!matcher_.begin(search_a_, tn, search_b_, sn, tframe.inverse().compose(sframe), search_options(older, newer))) {
    ++stats_->loop_search_failed;
    return;
  }
  search_continue();
}

CorrelativeOptions LoopClosure::search_options(std::uint32_t older_level, std::uint32_t newer_level) const {
  CorrelativeOptions co;
  co.resolution_m = geometry_.resolution_m;
  co.coarse_cells = kSearchCoarseCells;
  co.kernel_sigma_m = 1.5 * co.resolution_m;
  co.window_xy_m = search_window_m(older_level, newer_level);
  co.window_theta_rad = options_.loop_search_window_rad;
  co.min_score = options_.loop_search_min_score;
  co.min_overlap_points = options_.loop_min_pairs;  // what obstacle ICP needs to confirm a peak
  co.max_ambiguity = options_.loop_search_max_ambiguity;
  return co;
}

// The coarse pass within the per-scan budget; the fine pass, ICP and the verdict when
// it is complete.
void LoopClosure::search_continue() {
  const std::uint64_t cost = matcher_.heading_cost();
  std::uint64_t h = cost > 0U ? options_.loop_search_reads_per_scan / cost : 1U;
  if (h < 1U) h = 1U;
  if (h > 0xFFFFFFFFULL) h = 0xFFFFFFFFULL;
  if (!matcher_.advance(static_cast<std::uint32_t>(h))) return;
  const CorrelativeResult c = matcher_.finish();
  if (recentring_) {
    recentre_verdict(c);
    return;
  }
  if (c.status == CorrelativeResult::Status::kWeak) {
    ++stats_->loop_search_weak;
    return;
  }
  if (c.status == CorrelativeResult::Status::kAmbiguous) {
    ++stats_->loop_search_ambiguous;
    return;
  }
  if (!c.found()) {
    ++stats_->loop_search_failed;
    return;
  }
  const Icp2dResult f = icp_->match(search_a_, search_a_count_, search_b_, search_b_count_, c.transform, icp_options());
  ++stats_->loop_refinements;
  // ICP only polishes the peak: it must stay within a coarse block of it.
  const Pose2 polish = between(c.transform, f.transform);
  const double reach = static_cast<double>(kSearchCoarseCells) * geometry_.resolution_m;
  if (!f.usable() || f.mean_nn_error_m > options_.loop_max_error_m || f.matched_pairs < options_.loop_min_pairs ||
      polish.x_m * polish.x_m + polish.y_m * polish.y_m > reach * reach) {
    ++stats_->loop_search_refuted;
    return;
  }
  const Record lr =
      matched(search_pair_older_, search_a_, search_a_count_, search_pair_newer_, search_b_, search_b_count_, f, true);
  if (options_.loop_search_drift_m > 0.0 && moves_too_far(lr)) {
    ++stats_->loop_search_far;
    return;
  }
  search_verdict(lr);
}

// The search proves a peak unique only within its window, which is centred on where the
// chain puts the newer submap. A peak that moves the submap (its box centre) by at most
// half the window has the other half on every side of it searched too: a repeated
// structure at up to that distance from it would have shown as a rival peak
// (kAmbiguous), so it is accepted. A peak farther out had part of its surroundings
// outside the window, where its alias may lie unseen. So the pair is searched again
// with the same window centred on the peak: if the peak is still the unique best there
// (recentre_verdict()), no alias lies within a window of it on any side, and the
// first search showed none between it and where the chain puts the submap; it is
// accepted. Otherwise it is dropped. The exactness of each search in its window is
// what makes the two windows together a proof of uniqueness.
void LoopClosure::search_verdict(const Record& r) {
  double dx = 0.0;
  double dy = 0.0;
  if (!centre_shift(r, &dx, &dy)) {
    ++stats_->loop_search_failed;  // a level was forgotten while it was searched
    return;
  }
  const double half = 0.5 * options_.loop_search_window_m;
  if (dx * dx + dy * dy <= half * half) {
    search_accept(r);
    return;
  }
  ++stats_->loop_search_recentred;
  if (!matcher_.begin(search_a_, search_a_count_, search_b_, search_b_count_, r.z,
                      search_options(r.older_level, r.newer_level))) {
    return;  // cannot happen: the same sets passed begin() for the first search
  }
  recentring_ = true;
  recentred_ = r;
  search_continue();
}

// The re-centred search agrees when its best pose is the peak itself (not distinct from
// it) and unambiguous.
void LoopClosure::recentre_verdict(const CorrelativeResult& c) {
  recentring_ = false;
  if (!c.found()) return;
  const Pose2 d = between(recentred_.z, c.transform);
  if (search_options(recentred_.older_level, recentred_.newer_level).distinct(d.x_m, d.y_m, d.heading_rad)) return;
  ++stats_->loop_search_recentred_closed;  // its search was counted recentred, not closed
  keep_verified(recentred_);
}

void LoopClosure::search_accept(const Record& r) {
  ++stats_->loop_search_closed;
  keep_verified(r);
}

void LoopClosure::keep_verified(const Record& r) {
  record(r);
  if (!record_dead(r)) submaps_->on_verified_loop();  // the frames follow the new constraint now
}

// How far r moves its newer submap (the centre of its box) from where the best
// combination's frames put it now; false if either level has no placement.
bool LoopClosure::centre_shift(const Record& r, double* dx_m, double* dy_m) const {
  std::uint32_t n = 0U;
  Pose2 fo;
  Pose2 fn;
  double ob[4];
  double nb[4];
  if (!submaps_->placement(r.older_level, &fo, ob, &n) || !submaps_->placement(r.newer_level, &fn, nb, &n) ||
      !box_valid(nb)) {
    return false;
  }
  const Pose2 centre{0.5 * (nb[0] + nb[2]), 0.5 * (nb[1] + nb[3]), 0.0};
  const Pose2 now = fn.compose(centre);
  const Pose2 moved = fo.compose(r.z).compose(centre);
  *dx_m = moved.x_m - now.x_m;
  *dy_m = moved.y_m - now.y_m;
  return true;
}

// How far the chain can have drifted between two levels: loop_search_drift_m × √hops.
double LoopClosure::drift_bound_m(std::uint32_t older_level, std::uint32_t newer_level) const {
  return options_.loop_search_drift_m * det::sqrt(static_cast<double>(level_hops(older_level, newer_level)));
}

// loop_search_window_m, grown to the drift bound up to loop_search_max_window_m
// (SdpOptions::loop_search_max_window_m says why).
double LoopClosure::search_window_m(std::uint32_t older_level, std::uint32_t newer_level) const {
  const double w = options_.loop_search_window_m;
  if (!(options_.loop_search_max_window_m > w) || !(options_.loop_search_drift_m > 0.0)) return w;
  const double bound = drift_bound_m(older_level, newer_level);
  if (!(bound > w)) return w;
  return bound < options_.loop_search_max_window_m ? bound : options_.loop_search_max_window_m;
}

// Whether r would move its newer submap farther than the chain may have drifted between
// the two levels: loop_search_drift_m × √hops (SdpOptions::loop_search_drift_m).
bool LoopClosure::moves_too_far(const Record& r) const {
  double dx = 0.0;
  double dy = 0.0;
  if (!centre_shift(r, &dx, &dy)) return false;
  const double bound = drift_bound_m(r.older_level, r.newer_level);
  const double limit_m2 = bound * bound;
  return dx * dx + dy * dy > limit_m2;
}

// The fewest steps between two levels over the frame graph's nodes: chain steps between
// consecutive levels, one step across each record both of whose levels are held (other
// than one of this same pair).
// Bounded work: at most kHopPasses rounds of relaxation (more would only shorten a
// path that already crosses that many loops); the level gap if either is not held.
std::uint32_t LoopClosure::level_hops(std::uint32_t older_level, std::uint32_t newer_level) const {
  constexpr std::uint32_t kHopPasses = 8U;
  const std::uint32_t gap = newer_level > older_level ? newer_level - older_level : older_level - newer_level;
  std::uint32_t a = 0U;
  std::uint32_t b = 0U;
  if (hops_ == nullptr || !submaps_->node_index(older_level, &a) || !submaps_->node_index(newer_level, &b)) return gap;
  std::uint32_t n = submaps_->node_count();
  if (n > max_nodes_) n = max_nodes_;
  for (std::uint32_t i = 0; i < n; ++i) hops_[i] = i > a ? i - a : a - i;
  for (std::uint32_t pass = 0; pass < kHopPasses; ++pass) {
    bool changed = false;
    for (std::uint32_t k = 0; k < count_; ++k) {
      const Record& r = records_[k];
      // A record of the same pair is a rival estimate of this very constraint, not a path.
      if (r.older_level == older_level && r.newer_level == newer_level) continue;
      std::uint32_t u = 0U;
      std::uint32_t v = 0U;
      if (!submaps_->node_index(r.older_level, &u) || !submaps_->node_index(r.newer_level, &v)) continue;
      if (hops_[u] + 1U < hops_[v]) {
        hops_[v] = hops_[u] + 1U;
        changed = true;
      } else if (hops_[v] + 1U < hops_[u]) {
        hops_[u] = hops_[v] + 1U;
        changed = true;
      }
    }
    if (!changed) break;
    for (std::uint32_t i = 1; i < n; ++i) {
      if (hops_[i - 1U] + 1U < hops_[i]) hops_[i] = hops_[i - 1U] + 1U;
    }
    for (std::uint32_t i = n - 1U; i > 0U; --i) {
      if (hops_[i] + 1U < hops_[i - 1U]) hops_[i - 1U] = hops_[i] + 1U;
    }
  }
  return hops_[b];
}

void LoopClosure::transfer_state(StateIo& io) {
  io.section("loop_closure");
  io.value(count_);
  graph_.transfer_state(io);
  matcher_.transfer_state(io);
  io.value(search_level_);
  io.value(search_newer_);
  io.value(search_count_);
  io.value(search_cursor_);
  io.value(search_a_count_);
  io.value(search_b_count_);
  io.value(search_pair_older_);
  io.value(search_pair_newer_);
  io.value(recentring_);
  io.value(recentred_);
}

}  // namespace sdpslam
