#include "sdpslam/core/bottom/dpslam_filter.h"

#include <cmath>
#include <cstdio>

#include "sdpslam/core/det_math.h"
#include "sdpslam/core/bottom/resampling.h"
#include "sdpslam/core/bottom/scan_matcher.h"

namespace sdpslam {
namespace {

// Forwards committed poses to the filter's sink (if any) and keeps those of the scans in
// the restart ring: restart_segment() places those scans by their poses, which the
// lineage no longer holds once committed.
class SeedSink final : public PoseSink {
 public:
  SeedSink(PoseSink* next, const std::int64_t* stamps_us, std::uint32_t count, Pose2* poses, bool* known)
      : next_(next), stamps_us_(stamps_us), count_(count), poses_(poses), known_(known) {}
  void on_committed(std::int64_t stamp_us, const Pose2& pose) override {
    for (std::uint32_t k = 0; k < count_; ++k) {
      if (stamps_us_[k] == stamp_us) {
        poses_[k] = pose;
        known_[k] = true;
      }
    }
    if (next_ != nullptr) next_->on_committed(stamp_us, pose);
  }

 private:
  PoseSink* next_;
  const std::int64_t* stamps_us_;
  std::uint32_t count_;
  Pose2* poses_;
  bool* known_;
};

constexpr std::size_t kSlack = 64U;  // alignment padding per carved array

template <typename T>
std::size_t array_bytes(std::uint32_t n) {
  return sizeof(T) * static_cast<std::size_t>(n) + kSlack;
}

DpMap::Options map_options(const DpSlamOptions& o) {
  DpMap::Options m;
  // The map frame has the first processed pose at its origin; the area is centred on it.
  m.origin_x_m = -0.5 * o.map_width_m;
  m.origin_y_m = -0.5 * o.map_height_m;
  m.width_m = o.map_width_m;
  m.height_m = o.map_height_m;
  m.resolution_m = o.map_resolution_m;
  m.tile_capacity = o.tile_capacity();
  m.observation_capacity = o.observation_capacity();
  m.owner_cell_index = o.map_owner_cell_index;
  m.wrap = o.map_wrap;
  if (m.wrap) {
    // The origin stays where the area puts it (the same cells as without wrap); the
    // window is at least 8 × the reach of a map update (DpSlamOptions::map_wrap).
    const double window_m = 8.0 * (o.beam.max_update_range_m + 2.0 * o.map_resolution_m) + o.map_resolution_m;
    if (m.width_m < window_m) m.width_m = window_m;
    if (m.height_m < window_m) m.height_m = window_m;
  }
  return m;
}

}  // namespace

std::size_t DpSlamFilter::required_arena_bytes(const DpSlamOptions& o) {
  if (!o.validate(nullptr, 0U)) return 0U;
  const std::size_t map_bytes = DpMap::required_arena_bytes(map_options(o), o.node_capacity());
  if (map_bytes == 0U) return 0U;
  const std::uint32_t n = o.particle_count;
  return AncestryTree::required_arena_bytes(o.node_capacity(), o.path_entry_capacity()) + map_bytes +
         2U * array_bytes<Particle>(n) + array_bytes<Pose2>(n) + 2U * array_bytes<double>(n) +
         2U * array_bytes<std::uint32_t>(n) +
         Arena::bytes_for<std::uint64_t>(BeamModel::marks_words(o.beam.max_update_range_m, o.map_resolution_m)) +
         kSlack +
         (o.proposal == DpSlamOptions::Proposal::kScanMatch ? ViewCache::required_arena_bytes(capacity::kViewCacheSlots)
                                                            : 0U);
}

bool DpSlamFilter::init(const DpSlamOptions& options, Arena& arena, std::uint64_t seed) {
  initialised_ = false;
  if (!options.validate(why_, sizeof why_)) return false;
  const std::size_t need = required_arena_bytes(options);
  if (need == 0U) {
    std::snprintf(why_, sizeof why_, "map options rejected by DpMap");
    return false;
  }
  if (arena.available_bytes() < need) {
    std::snprintf(why_, sizeof why_, "arena too small: %zu bytes available, %zu needed", arena.available_bytes(),
                  need);
    return false;
  }
  options_ = options;
  if (!tree_.init(arena, options.node_capacity(), options.path_entry_capacity())) {
    std::snprintf(why_, sizeof why_, "ancestry tree init failed (capacity %u nodes)", options.node_capacity());
    return false;
  }
  if (!map_.init(arena, map_options(options), tree_)) {
    std::snprintf(why_, sizeof why_, "DP map init failed");
    return false;
  }
  if (!beam_.init(options.beam, options.map_resolution_m)) {
    std::snprintf(why_, sizeof why_, "observation model options rejected");
    return false;
  }
  motion_ = MotionModel(options.motion);
  const std::uint32_t n = options.particle_count;
  particles_ = arena.allocate_array<Particle>(n);
  next_ = arena.allocate_array<Particle>(n);
  proposed_ = arena.allocate_array<Pose2>(n);
  log_w_ = arena.allocate_array<double>(n);
  w_ = arena.allocate_array<double>(n);
  drawn_ = arena.allocate_array<std::uint32_t>(n);
  counts_ = arena.allocate_array<std::uint32_t>(n);
  marks_ = arena.allocate_array<std::uint64_t>(BeamModel::marks_words(options.beam.max_update_range_m,
                                                                      options.map_resolution_m));
  if (particles_ == nullptr || next_ == nullptr || proposed_ == nullptr || log_w_ == nullptr || w_ == nullptr ||
      drawn_ == nullptr || counts_ == nullptr || marks_ == nullptr) {
    std::snprintf(why_, sizeof why_, "arena exhausted while carving particle arrays");
    return false;
  }
  view_ = ViewCache{};
  if (options.proposal == DpSlamOptions::Proposal::kScanMatch && !view_.init(arena, capacity::kViewCacheSlots)) {
    std::snprintf(why_, sizeof why_, "arena exhausted while carving the scan matcher's view cache");
    return false;
  }
  particle_count_ = n;
  rng_.reseed(seed);
  stats_ = DpSlamStats{};
  started_ = false;
  best_index_ = 0U;
  why_[0] = '\0';
  initialised_ = true;
  return true;
}

void DpSlamFilter::first_scan(const OdometrySample& odom, const RangeScan& scan, StepResult* result) {
  prepare_rays(scan, &rays_);
  rays_stamp_us_ = scan.stamp_us;
  seed_head_ = 0U;
  seed_count_ = 0U;
  const Pose2 origin{};
  const NodeId root = tree_.create_root();
  std::uint32_t dropped = 0U;
  if (root != kNoNode) {
    dropped = beam_.update_map(map_, root, rays_, origin, beam_.options().max_update_range_m, marks_);
    tree_.append_pose(root, scan.stamp_us, origin);
  }
  for (std::uint32_t i = 0; i < particle_count_; ++i) {
    NodeId c = root != kNoNode ? tree_.add_child(root) : kNoNode;
    if (c == kNoNode) {
      c = root;
      ++stats_.node_fallback_count;
    }
    particles_[i] = Particle{c, origin, 0.0};
  }
  if (root != kNoNode && particles_[0].node != root) tree_.set_active(root, false);
  tree_.prune(&map_);
  SeedSink seed_sink(sink_, seed_stamp_us_, seed_count_, seed_pose_, seed_committed_);
  result->poses_committed = tree_.drain_committed(seed_sink);
  started_ = true;
  last_odom_ = odom;
  last_best_pose_ = origin;
  best_index_ = 0U;
  ++stats_.processed;
  stats_.map_updates_dropped += dropped;
  result->status = StepResult::Status::kProcessed;
  result->pose = origin;
  result->map_updates_dropped = dropped;
  result->effective_sample_size = static_cast<double>(particle_count_);
}

StepResult DpSlamFilter::process(const OdometrySample& odom, const RangeScan& scan) {
  StepResult result;
  if (!initialised_) return result;
  ++stats_.scans;
  if (!started_) {
    first_scan(odom, scan, &result);
    return result;
  }
  const Pose2 delta = between(last_odom_.pose, odom.pose);
  const double travel = det::sqrt(delta.x_m * delta.x_m + delta.y_m * delta.y_m);
  const double turn = delta.heading_rad < 0.0 ? -delta.heading_rad : delta.heading_rad;
  if (!update_due_ && travel < options_.update_min_travel_m && turn < options_.update_min_rotation_rad) {
    result.status = StepResult::Status::kSkippedNoMotion;
    result.pose = last_best_pose_.compose(delta);
    return result;
  }

  const std::uint32_t n = particle_count_;
  // The scan in rays_ becomes one of the previous scans (see restart_segment()).
  const std::uint32_t slot = seed_count_ < kSeedScans ? (seed_head_ + seed_count_) % kSeedScans : seed_head_;
  seed_rays_[slot] = rays_;
  seed_stamp_us_[slot] = rays_stamp_us_;
  seed_committed_[slot] = false;
  if (seed_count_ < kSeedScans) {
    ++seed_count_;
  } else {
    seed_head_ = (seed_head_ + 1U) % kSeedScans;
  }
  prepare_rays(scan, &rays_);
  rays_stamp_us_ = scan.stamp_us;
  // 1-2. propagate and weight.
  for (std::uint32_t i = 0; i < n; ++i) log_w_[i] = particles_[i].log_weight + propose(i, delta);
  if (!normalize_log_weights(log_w_, n, w_)) ++stats_.degenerate_weight_count;
  const double neff = effective_sample_size(w_, n);
  std::uint32_t best = 0U;
  for (std::uint32_t i = 1; i < n; ++i) {
    if (w_[i] > w_[best]) best = i;
  }
  // 3. resample.
  const bool resample = neff < options_.resample_neff_ratio * static_cast<double>(n);
  if (resample) {
    low_variance_resample(w_, n, rng_, drawn_);
    ++stats_.resamplings;
  } else {
    for (std::uint32_t i = 0; i < n; ++i) drawn_[i] = i;
  }
  for (std::uint32_t i = 0; i < n; ++i) counts_[i] = 0U;
  for (std::uint32_t m = 0; m < n; ++m) ++counts_[drawn_[m]];
  // 4. map update and path of every surviving particle (once per node: duplicates
  //    become children that inherit it).
  const double reach_m = reach_that_fits(rays_, nullptr, kNoNode);
  std::uint32_t dropped = 0U;
  for (std::uint32_t i = 0; i < n; ++i) {
    if (!writes(i)) continue;
    dropped += beam_.update_map(map_, particles_[i].node, rays_, proposed_[i], reach_m, marks_);
    tree_.append_pose(particles_[i].node, scan.stamp_us, proposed_[i]);
  }
  const double best_lw = log_w_[best];
  for (std::uint32_t m = 0; m < n; ++m) {
    const std::uint32_t i = drawn_[m];
    NodeId c = tree_.add_child(particles_[i].node);
    if (c == kNoNode) {
      c = particles_[i].node;  // degraded: continue on the parent's node
      ++stats_.node_fallback_count;
    }
    double lw = 0.0;
    if (!resample) {
      lw = log_w_[i] - best_lw;
      if (!(lw > -1.0e300)) lw = -1.0e300;  // keep finite: -inf would never recover
    }
    next_[m] = Particle{c, proposed_[i], lw};
  }
  for (std::uint32_t i = 0; i < n; ++i) tree_.set_active(particles_[i].node, false);
  for (std::uint32_t m = 0; m < n; ++m) {
    if (next_[m].node == particles_[drawn_[m]].node) tree_.set_active(next_[m].node, true);
  }
  // 5. prune/merge, commit.
  tree_.prune(&map_);
  SeedSink seed_sink(sink_, seed_stamp_us_, seed_count_, seed_pose_, seed_committed_);
  result.poses_committed = tree_.drain_committed(seed_sink);

  std::uint32_t new_best = 0U;
  for (std::uint32_t m = 0; m < n; ++m) {
    if (drawn_[m] == best) {
      new_best = m;
      break;
    }
  }
  Particle* tmp = particles_;
  particles_ = next_;
  next_ = tmp;
  best_index_ = new_best;
  last_odom_ = odom;
  last_best_pose_ = proposed_[best];
  update_due_ = false;

  ++stats_.processed;
  stats_.map_updates_dropped += dropped;
  result.status = StepResult::Status::kProcessed;
  result.pose = last_best_pose_;
  result.resampled = resample;
  result.effective_sample_size = neff;
  result.map_updates_dropped = dropped;
  return result;
}

double DpSlamFilter::propose(std::uint32_t i, const Pose2& delta) {
  const Particle& p = particles_[i];
  const DpMap::ViewScope view(map_, p.node);  // the proposal only reads the particle's map
  if (options_.proposal == DpSlamOptions::Proposal::kScanMatch) {
    // Improved proposal (Grisetti et al. 2007, §IV): from the odometry prediction, the
    // mode of the likelihood times the motion model's density along the path.
    const MotionPrior prior = motion_.prior(p.pose, delta);
    const ScanMatch m = match_scan(beam_, map_, p.node, rays_, prior.predicted, options_.match, &prior, &view_);
    stats_.proposal_evaluations += m.evaluations;
    switch (m.outcome) {
      case ScanMatch::Outcome::kMatched: {
        ++stats_.proposal_matched;
        const double ex = rng_.gaussian(options_.proposal_sigma_xy_m);
        const double ey = rng_.gaussian(options_.proposal_sigma_xy_m);
        const double et = rng_.gaussian(options_.proposal_sigma_rot_rad);
        proposed_[i] = Pose2{m.pose.x_m + ex, m.pose.y_m + ey, normalize_angle_rad(m.pose.heading_rad + et)};
        if (options_.proposal_weight == DpSlamOptions::ProposalWeight::kNeighbourhood) {
          // Matcher beams → the weighting beam count, so that fallback particles compare.
          const double scale = static_cast<double>(options_.match.beam_stride) /
                               static_cast<double>(options_.beam.weight_beam_stride);
          return m.neighbourhood_log_likelihood * scale;
        }
        return beam_.log_likelihood(map_, p.node, rays_, m.pose);
      }
      case ScanMatch::Outcome::kTooFewBeams: ++stats_.proposal_fallback_few_beams; break;
      case ScanMatch::Outcome::kMapTooEmpty: ++stats_.proposal_fallback_empty_map; break;
      case ScanMatch::Outcome::kScoreTooLow: ++stats_.proposal_fallback_low_score; break;
    }
  }
  proposed_[i] = motion_.sample(p.pose, delta, rng_);
  return beam_.log_likelihood(map_, p.node, rays_, proposed_[i]);
}

bool DpSlamFilter::is_particle_node(NodeId node) const {
  for (std::uint32_t i = 0; i < particle_count_; ++i) {
    if (particles_[i].node == node) return true;
  }
  return false;
}

bool DpSlamFilter::displace(const Pose2& delta) {
  if (!initialised_ || !started_) return false;
  if (!(std::isfinite(delta.x_m) && std::isfinite(delta.y_m) && std::isfinite(delta.heading_rad))) return false;
  for (std::uint32_t i = 0; i < particle_count_; ++i) particles_[i].pose = particles_[i].pose.compose(delta);
  last_best_pose_ = last_best_pose_.compose(delta);
  update_due_ = true;
  return true;
}

bool DpSlamFilter::restart_segment(const Pose2& start_pose) {
  if (!initialised_ || !started_) {
    ++restart_refused_count_;
    return false;
  }
  // All or nothing: the root and one child per particle must fit.
  if (tree_.capacity() - tree_.size() < particle_count_ + 1U) {
    ++restart_refused_count_;
    return false;
  }
  // The previous scans go where the best particle's lineage put them, relative to
  // start_pose as they were to its pose (a scan whose pose the lineage no longer holds,
  // e.g. one from before the last restart, is left out).
  Pose2 at[kSeedScans];
  bool found[kSeedScans] = {};
  if (seed_count_ > 0U) {
    const Pose2 best_inverse = particles_[best_index_].pose.inverse();
    for (std::uint32_t k = 0; k < seed_count_; ++k) {
      at[k] = seed_pose_[k];  // committed: on every lineage
      found[k] = seed_committed_[k];
    }
    tree_.for_each_pose_from_root(particles_[best_index_].node, [&](std::int64_t stamp_us, const Pose2& pose) {
      for (std::uint32_t k = 0; k < seed_count_; ++k) {
        if (seed_stamp_us_[k] == stamp_us) {
          at[k] = pose;
          found[k] = true;
        }
      }
    });
    for (std::uint32_t k = 0; k < seed_count_; ++k) at[k] = start_pose.compose(best_inverse.compose(at[k]));
  }
  const NodeId root = tree_.create_root();
  if (root == kNoNode) {
    ++restart_refused_count_;
    return false;
  }
  // Each scan's writes are counted, and room asked for them (or the scan's update range
  // shortened), just before it is written: the root keeps every write (one node: the
  // scans' common cells are shared), so what one scan adds is its cells the root does not
  // hold yet. The root is an active leaf, which making room leaves alone.
  for (std::uint32_t k = 0; k < seed_count_; ++k) {
    if (!found[k]) continue;
    const double reach_m = reach_that_fits(seed_rays_[k], &at[k], root);
    stats_.map_updates_dropped += beam_.update_map(map_, root, seed_rays_[k], at[k], reach_m, marks_);
  }
  const double reach_m = reach_that_fits(rays_, &start_pose, root);
  stats_.map_updates_dropped += beam_.update_map(map_, root, rays_, start_pose, reach_m, marks_);
  seed_count_ = 0U;  // the next segment starts from its own scans
  seed_head_ = 0U;
  for (std::uint32_t i = 0; i < particle_count_; ++i) {
    NodeId c = tree_.add_child(root);
    if (c == kNoNode) {  // cannot happen after the capacity check; degraded path anyway
      c = root;
      ++stats_.node_fallback_count;
    }
    // The old node stays active: it is the anchored leaf of the finished segment.
    particles_[i] = Particle{c, start_pose, 0.0};
  }
  if (particles_[0].node != root) tree_.set_active(root, false);
  tree_.prune(&map_);
  best_index_ = 0U;
  last_best_pose_ = start_pose;
  return true;
}

// Particle i survives resampling and is the first with its node (a node shared by
// several particles, a fallback, is updated once).
bool DpSlamFilter::writes(std::uint32_t i) const {
  if (counts_[i] == 0U) return false;
  for (std::uint32_t j = 0; j < i; ++j) {
    if (counts_[j] > 0U && particles_[j].node == particles_[i].node) return false;
  }
  return true;
}

// The writers are the surviving particles, one per node (step 4). Every writer's node is
// a fresh leaf (or, degraded, its parent's node), so it takes one new observation per
// distinct cell its scan traces (at most, for the parent's node).
std::uint64_t DpSlamFilter::writes_bound(const ScanRays& rays, const Pose2* pose, NodeId into, double reach_m) const {
  if (pose != nullptr) return beam_.cells_written(map_, rays, *pose, reach_m, into, marks_);
  std::uint64_t need = 0U;
  for (std::uint32_t i = 0; i < particle_count_; ++i) {
    if (writes(i)) need += beam_.cells_written(map_, rays, proposed_[i], reach_m, kNoNode, marks_);
  }
  return need;
}

// The bound at any pose is checked first (O(beams)); only where the pool is that tight
// are the scans' cells counted at their poses. Where the writes do not fit, the MapRoom
// is asked for room; where it cannot make enough, the update range is bisected down to a
// range whose writes fit, within max_update_range_m / 2^kReachBisections of the longest
// (the writes grow with the range; a range is kept only once its count fits, so the
// writes made always fit). The near cells, which the next scans are
// weighed against first, are then written in full, and every writer loses the same far
// misses, instead of the last writers losing whole scans to refusals. Where even a zero
// range does not fit, the pool refuses what it cannot hold (map_updates_dropped).
double DpSlamFilter::reach_that_fits(const ScanRays& rays, const Pose2* pose, NodeId into) {
  const double full_m = beam_.options().max_update_range_m;
  std::uint64_t nodes = 1U;
  if (pose == nullptr) {
    nodes = 0U;
    for (std::uint32_t i = 0; i < particle_count_; ++i) nodes += writes(i) ? 1U : 0U;
  }
  if (nodes * beam_.cells_bound(rays, full_m) <= free_observations()) return full_m;
  const std::uint64_t need = writes_bound(rays, pose, into, full_m);
  if (need <= free_observations()) return full_m;
  if (room_ != nullptr) {
    ++stats_.map_room_asked;
    room_->make_room(need);
    if (need <= free_observations()) return full_m;
    ++stats_.map_room_short;
  }
  double lo_m = 0.0;
  double hi_m = full_m;
  for (std::uint32_t k = 0; k < kReachBisections; ++k) {
    const double mid_m = 0.5 * (lo_m + hi_m);
    if (writes_bound(rays, pose, into, mid_m) <= free_observations()) {
      lo_m = mid_m;
    } else {
      hi_m = mid_m;
    }
  }
  if (stats_.map_writes_shortened == 0U || lo_m < stats_.shortest_write_reach_m) stats_.shortest_write_reach_m = lo_m;
  ++stats_.map_writes_shortened;
  return lo_m;
}

std::uint64_t DpSlamFilter::free_observations() const {
  return std::uint64_t{map_.observation_capacity()} - map_.observations_used();
}

bool DpSlamFilter::release_anchored(NodeId node) {
  if (!tree_.contains(node) || is_particle_node(node)) return false;
  if (!tree_.set_active(node, false)) return false;
  tree_.prune(&map_);
  return true;
}

bool DpSlamFilter::pop_anchored_observation(NodeId node, std::int32_t* ix, std::int32_t* iy,
                                            CellObservation* value) {
  if (is_particle_node(node)) return false;
  return map_.pop_observation(node, ix, iy, value);
}


void DpSlamFilter::transfer_state(StateIo& io) {
  io.section("dpslam_filter");
  tree_.transfer_state(io);
  map_.transfer_state(io);
  view_.transfer_state(io);
  rng_.transfer_state(io);
  io.value(stats_);
  io.value(rays_);
  io.value(seed_rays_);
  io.value(seed_stamp_us_);
  io.value(seed_pose_);
  io.value(seed_committed_);
  io.value(seed_head_);
  io.value(seed_count_);
  io.value(rays_stamp_us_);
  // The two generations swap each step: which block is which travels as an offset.
  io.arena_pointer(particles_, "filter particles");
  io.arena_pointer(next_, "filter next generation");
  io.value(best_index_);
  io.value(started_);
  io.value(update_due_);
  io.value(last_odom_);
  io.value(last_best_pose_);
  io.value(restart_refused_count_);
}

}  // namespace sdpslam
