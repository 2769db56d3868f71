#include "sdp_slam_impl.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <new>

#include "sdpslam/core/box2.h"
#include "sdpslam/core/det_math.h"

namespace sdpslam {
namespace {

constexpr std::size_t kSlack = 64U;

std::uint32_t fine_side_cells(const DpSlamOptions& b, const SdpOptions& s) {
  return static_cast<std::uint32_t>(s.skeleton_max_side_m / b.map_resolution_m) + 2U;
}
std::uint32_t coarse_side_cells(const DpSlamOptions& b, const SdpOptions& s) {
  return fine_side_cells(b, s) / s.skeleton_downsample + 2U;
}
std::uint32_t ring_capacity_for(const SdpOptions& s) { return (s.max_levels + 2U) * (s.max_segment_scans + 2U); }
// Wide loop search grid: a skeleton patch of coarse cells plus the reach of a kernel of
// 1.5 cells (2 × (5 + 2) cells, correlative_matcher.cpp); the search works on obstacle
// points, which lie on the skeleton's coarse cells.
LoopSearchGeometry search_geometry(const DpSlamOptions& b, const SdpOptions& s) {
  LoopSearchGeometry g;
  g.resolution_m = b.map_resolution_m * static_cast<double>(s.skeleton_downsample);
  g.grid_side = coarse_side_cells(b, s) + 16U;
  return g;
}
// The loop-closure graph holds every permanent submap still kept and every live level.
std::uint32_t graph_nodes(const SdpOptions& s) { return s.max_permanent_submaps + s.max_levels; }

SkeletonReaderOptions skeleton_options(const DpSlamOptions& b, const SdpOptions& s) {
  SkeletonReaderOptions o;
  o.patch_side = coarse_side_cells(b, s);
  o.downsample = s.skeleton_downsample;
  o.skeleton_points = s.skeleton_points;
  o.obstacle_points = s.loop_closure ? s.loop_points : 0U;
  o.occupied_threshold = s.occupied_threshold;
  o.free_threshold = s.free_threshold;
  o.min_clearance_m = s.skeleton_min_clearance_m;
  return o;
}

// Obstacle points are kept for loop closure only.
SubmapStoreOptions store_options(const SdpOptions& s, std::uint32_t n) {
  SubmapStoreOptions o;
  o.max_levels = s.max_levels;
  o.nodes = n;
  o.skeleton_points = s.skeleton_points;
  o.obstacle_points = s.loop_closure ? s.loop_points : 0U;
  o.max_permanent = s.max_permanent_submaps;
  return o;
}

SegmentGraphOptions graph_options(const SdpOptions& s, std::uint32_t n) {
  SegmentGraphOptions g;
  g.max_levels = s.max_levels;
  g.nodes_per_level = n;
  g.accumulation = s.accumulation;
  g.prior_error_m = s.prior_error_m;
  return g;
}

// How far apart two placements of a submap put its box's corners (m): the largest
// corner distance. An invalid (empty) box counts its frame origin only.
double frame_offset_m(const Pose2& a, const Pose2& b, const double box[4]) {
  double worst = det::sqrt((a.x_m - b.x_m) * (a.x_m - b.x_m) + (a.y_m - b.y_m) * (a.y_m - b.y_m));
  if (!box_valid(box)) return worst;
  const double xs[2] = {box[0], box[2]};
  const double ys[2] = {box[1], box[3]};
  for (double x : xs) {
    for (double y : ys) {
      double ax = 0.0, ay = 0.0, bx = 0.0, by = 0.0;
      a.transform_point(x, y, ax, ay);
      b.transform_point(x, y, bx, by);
      const double d = det::sqrt((ax - bx) * (ax - bx) + (ay - by) * (ay - by));
      if (d > worst) worst = d;
    }
  }
  return worst;
}

}  // namespace

double SdpStats::error_std_m() const {
  if (error_samples < 2U) return 0.0;
  const double n = static_cast<double>(error_samples);
  const double m = error_sum_m / n;
  const double v = error_sq_sum_m2 / n - m * m;
  return v > 0.0 ? det::sqrt(v) : 0.0;
}

double SdpSlamImpl::box_overlap_m2(const double a[4], const double b[4]) { return sdpslam::box_overlap_m2(a, b); }

DpSlamOptions SdpSlamImpl::bottom_options_for(const DpSlamOptions& bottom, const SdpOptions& sdp) {
  DpSlamOptions b = bottom;
  const std::uint32_t n = b.particle_count;
  // Anchored segments keep at most 2N-1 nodes each (prune bound); the restart needs N+1;
  // headroom.
  b.extra_ancestry_nodes = sdp.max_levels * 2U * n + n + 8U;
  // Anchored leaves keep their uncommitted poses: at most N × segment length per segment.
  b.extra_path_entries = (sdp.max_levels + 1U) * n * sdp.max_segment_scans;
  if (sdp.map_tile_capacity != 0U) b.map_tile_capacity = sdp.map_tile_capacity;
  if (sdp.map_observation_capacity != 0U) {
    b.map_observations_base = sdp.map_observation_capacity;
    b.map_observations_per_particle = 1U;
  }
  // Few particles per segment: the DP map's (owner, cell) index would cost a third of the
  // memory budget for little time (the index is for DP-SLAM at hundreds of particles).
  b.map_owner_cell_index = sdp.map_owner_cell_index;
  // The DP map is a torus that moves with the robot (sdp_slam.h): each segment is a
  // lineage of its own, kept within a square of half the window by segmenting.
  b.map_wrap = true;
  return b;
}

std::size_t SdpSlamImpl::required_arena_bytes(const DpSlamOptions& bottom_in, const SdpOptions& s) {
  if (!s.validate(nullptr, 0U)) return 0U;
  const DpSlamOptions b = bottom_options_for(bottom_in, s);
  const std::size_t fb = DpSlamFilter::required_arena_bytes(b);
  if (fb == 0U) return 0U;
  const std::size_t gb = SegmentGraph::required_bytes(graph_options(s, b.particle_count));
  if (gb == 0U) return 0U;
  const std::size_t n = b.particle_count;
  const std::size_t L = s.max_levels;
  const std::size_t fine = static_cast<std::size_t>(fine_side_cells(b, s)) * fine_side_cells(b, s);
  const std::size_t pb = PermanentMap::required_bytes(s.permanent_map_tiles);
  if (pb == 0U) return 0U;
  std::size_t total = fb + gb + pb + Arena::bytes_for<DpSlamFilter>(1U) + Arena::bytes_for<Icp2d>(1U) + Arena::bytes_for<Segmenter>(1U);
  total += SkeletonReader::required_bytes(skeleton_options(b, s));
  total += SubmapStore::required_bytes(store_options(s, b.particle_count));
  total += TopParticles::required_bytes(TopParticleOptions::from(s));
  total += Arena::bytes_for<std::uint32_t>(L) + 2U * Arena::bytes_for<Pose2>(L) + Arena::bytes_for<Pose2>(n);
  total += PoseRing::required_bytes(ring_capacity_for(s)) + CombinationEvaluator::required_bytes() + Arena::bytes_for<NodeId>(n * L) +
           Arena::bytes_for<PendingCopy>(L);
  if (s.loop_closure) {
    total += LoopClosure::required_bytes(s, graph_nodes(s), search_geometry(b, s));
    total += 2U * Arena::bytes_for<Point2>(s.loop_points);
  }
  total += Arena::bytes_for<CellObservation>(fine) + Arena::bytes_for<std::uint8_t>(fine);
  return total + kSlack;
}

bool SdpSlamImpl::check_options(const DpSlamOptions& bottom, const SdpOptions& s, char* why, std::size_t n) {
  if (why != nullptr && n > 0U) why[0] = '\0';
  if (!s.validate(why, n) || !bottom.validate(why, n)) return false;
  const DpSlamOptions b = bottom_options_for(bottom, s);
  if (!b.validate(why, n)) {
    // Valid alone, too large once anchored segments get their pool room.
    if (why != nullptr && n > 0U) {
      const std::size_t len = std::strlen(why);
      std::snprintf(why + len, n - len, " (with the pool room of sdp.max_levels = %u segments)", s.max_levels);
    }
    return false;
  }
  static_assert(capacity::kMaxPgsNodesPerLevel >= capacity::kMaxBottomParticles,
                "every bottom particle count validate() accepts has its PGS node");
  const std::uint32_t coarse = coarse_side_cells(b, s);
  if (coarse > capacity::kMaxSkeletonPatchSide) {
    if (why != nullptr && n > 0U) {
      std::snprintf(why, n,
                    "sdp.skeleton_max_side_m: a skeleton patch of %u cells, above the %u cells it may have "
                    "(raise [sdp] skeleton_downsample or [map] resolution_m)",
                    coarse, capacity::kMaxSkeletonPatchSide);
    }
    return false;
  }
  // Loop closure keeps obstacle points as 16-bit cell coordinates of the map grid.
  const bool wide = b.map_width_m >= b.map_height_m;
  const double cells = (wide ? b.map_width_m : b.map_height_m) / b.map_resolution_m;
  if (s.loop_closure && cells > 32767.0) {
    if (why != nullptr && n > 0U) {
      std::snprintf(why, n,
                    "map.%s: a map grid %.0f cells %s, above the 32767 that loop closure's cell coordinates hold "
                    "(lower [map] width_m/height_m or raise resolution_m)",
                    wide ? "width_m" : "height_m", cells, wide ? "wide" : "high");
    }
    return false;
  }
  return true;
}

bool SdpSlamImpl::init(const DpSlamOptions& bottom_in, const SdpOptions& s, Arena& arena, std::uint64_t seed) {
  initialised_ = false;
  if (!check_options(bottom_in, s, why_, sizeof why_)) return false;
  const DpSlamOptions b = bottom_options_for(bottom_in, s);
  const std::size_t need = required_arena_bytes(bottom_in, s);
  if (need == 0U || arena.available_bytes() < need) {
    std::snprintf(why_, sizeof why_, "arena too small: %zu bytes available, %zu needed", arena.available_bytes(), need);
    return false;
  }
  const std::size_t used0 = arena.used_bytes();
  state_begin_ = arena.cursor();
  options_ = s;
  bottom_options_ = b;
  n_bottom_ = b.particle_count;
  // The bottom filter, ICP and segmenter live in the arena: placement new below (init
  // only) constructs them there; nothing comes from the heap (tests/sdp/test_sdp_no_heap).
  void* fmem = arena.allocate(sizeof(DpSlamFilter), alignof(DpSlamFilter));
  void* imem = arena.allocate(sizeof(Icp2d), alignof(Icp2d));
  void* smem = arena.allocate(sizeof(Segmenter), alignof(Segmenter));
  if (fmem == nullptr || imem == nullptr || smem == nullptr) {
    std::snprintf(why_, sizeof why_, "arena exhausted (filter objects)");
    return false;
  }
  filter_ = new (fmem) DpSlamFilter();
  icp_ = new (imem) Icp2d();
  segmenter_ = new (smem) Segmenter(options_);
  if (!filter_->init(b, arena, seed)) {
    std::snprintf(why_, sizeof why_, "bottom filter: %s", filter_->why());
    return false;
  }
  filter_->set_pose_sink(&ring_sink_);
  filter_->set_map_room(&room_for_writes_);
  {
    // A segment's updates must stay within a square of half the window (DpMap's wrap
    // contract): its path within window/8 of its start (process()) and its beams'
    // updates within max_update_range_m of the path, which the filter's map options keep
    // below window/8 (DpSlamOptions::map_wrap).
    const DpMap& map = filter_->map();
    const std::int32_t side = map.width_cells() < map.height_cells() ? map.width_cells() : map.height_cells();
    window_radius_m_ = 0.125 * map.resolution_m() * static_cast<double>(side);
  }
  if (!permanent_map_.init(arena, s.permanent_map_tiles)) {
    std::snprintf(why_, sizeof why_, "arena exhausted while carving the permanent map");
    return false;
  }
  if (!graph_.init(graph_options(s, n_bottom_), arena)) {
    std::snprintf(why_, sizeof why_, "PGS init failed");
    return false;
  }
  if (!skeletons_.init(skeleton_options(b, s), arena)) {
    std::snprintf(why_, sizeof why_, "skeleton init failed (patch side %u cells)", coarse_side_cells(b, s));
    return false;
  }
  const std::uint32_t L = s.max_levels;
  if (!store_.init(store_options(s, n_bottom_), arena)) {
    std::snprintf(why_, sizeof why_, "arena exhausted while carving the submap store");
    return false;
  }
  if (!top_.init(TopParticleOptions::from(s), arena)) {
    std::snprintf(why_, sizeof why_, "arena exhausted while carving the top-level particles");
    return false;
  }
  chain_ = arena.allocate_array<std::uint32_t>(L);
  frames_ = arena.allocate_array<Pose2>(L);
  eval_frames_ = arena.allocate_array<Pose2>(L);
  poses_scratch_ = arena.allocate_array<Pose2>(n_bottom_);
  if (!ring_.init(arena, ring_capacity_for(s))) {
    std::snprintf(why_, sizeof why_, "arena exhausted while carving the pose ring");
    return false;
  }
  if (!evaluator_.init(CombinationOptions::from(s), icp_, arena)) {
    std::snprintf(why_, sizeof why_, "arena exhausted while carving the ICP memo");
    return false;
  }
  if (s.loop_closure) {
    obst_a_ = arena.allocate_array<Point2>(s.loop_points);
    obst_b_ = arena.allocate_array<Point2>(s.loop_points);
    if (obst_a_ == nullptr || obst_b_ == nullptr ||
        !loop_closure_.init(s, graph_nodes(s), search_geometry(b, s), icp_, &loop_view_, &stats_, arena)) {
      std::snprintf(why_, sizeof why_, "arena exhausted (loop closure)");
      return false;
    }
  }
  release_capacity_ = n_bottom_ * s.max_levels;
  release_queue_ = arena.allocate_array<NodeId>(release_capacity_);
  copy_queue_ = arena.allocate_array<PendingCopy>(s.max_levels);
  const std::uint32_t fs = fine_side_cells(b, s);
  fine_cells_ = static_cast<std::size_t>(fs) * fs;
  fine_values_ = arena.allocate_array<CellObservation>(fine_cells_);
  fine_known_ = arena.allocate_array<std::uint8_t>(fine_cells_);
  if (chain_ == nullptr || frames_ == nullptr ||
      eval_frames_ == nullptr || poses_scratch_ == nullptr || fine_values_ == nullptr ||
      fine_known_ == nullptr || release_queue_ == nullptr || copy_queue_ == nullptr) {
    std::snprintf(why_, sizeof why_, "arena exhausted while carving SDP-SLAM state");
    return false;
  }
  rng_.reseed(seed ^ 0x5D95E6A1C3B2F407ULL);
  stats_ = SdpStats{};
  arena_used_ = arena.used_bytes() - used0;
  state_end_ = arena.cursor();
  why_[0] = '\0';
  initialised_ = true;
  return true;
}

void SdpSlamImpl::ring_push(std::int64_t stamp_us, const Pose2& pose) {
  if (!ring_.push(stamp_us, pose)) {
    ++stats_.pose_ring_dropped;
    return;
  }
  if (ring_.size() > stats_.pose_ring_peak) stats_.pose_ring_peak = ring_.size();
}

bool SdpSlamImpl::global_map_grid(GlobalMapGrid* grid) const {
  *grid = GlobalMapGrid{};
  if (!initialised_) return false;
  const DpMap& map = filter_->map();
  const double res = map.resolution_m() * static_cast<double>(std::uint64_t{1} << permanent_map_.scale_log2());
  const double fine = map.resolution_m();
  const double ox = map.options().origin_x_m;
  const double oy = map.options().origin_y_m;
  // Bounds in the global frame: the permanent cells, and the live views' rectangles.
  double gx0 = 1e300;
  double gy0 = 1e300;
  double gx1 = -1e300;
  double gy1 = -1e300;
  const auto grow = [&](double x0, double y0, double x1, double y1) {
    gx0 = x0 < gx0 ? x0 : gx0;
    gy0 = y0 < gy0 ? y0 : gy0;
    gx1 = gx1 < x1 ? x1 : gx1;
    gy1 = gy1 < y1 ? y1 : gy1;
  };
  const double half = 0.5 * fine;
  for_each_permanent_cell([&](double x, double y, const CellObservation&) { grow(x - half, y - half, x + half, y + half); });
  for_each_best_submap([&](NodeId, const Pose2& frame, const CellRect& r) {
    if (r.width == 0U || r.height == 0U) return;
    const double xs[2] = {ox + r.ix0 * fine, ox + (r.ix0 + static_cast<double>(r.width)) * fine};
    const double ys[2] = {oy + r.iy0 * fine, oy + (r.iy0 + static_cast<double>(r.height)) * fine};
    for (double x : xs) {
      for (double y : ys) {
        double gx = 0.0;
        double gy = 0.0;
        frame.transform_point(x, y, gx, gy);
        grow(gx, gy, gx, gy);
      }
    }
  });
  if (!(gx1 > gx0) || !(gy1 > gy0)) return false;
  grid->origin_x_m = ox + std::floor((gx0 - ox) / res) * res;
  grid->origin_y_m = oy + std::floor((gy0 - oy) / res) * res;
  grid->resolution_m = res;
  grid->width = static_cast<std::uint32_t>(std::ceil((gx1 - grid->origin_x_m) / res)) + 1U;
  grid->height = static_cast<std::uint32_t>(std::ceil((gy1 - grid->origin_y_m) / res)) + 1U;
  return true;
}

void SdpSlamImpl::top_error(double* mean_m, double* std_m, std::uint32_t* count) const {
  top_.error_summary(mean_m, std_m, count);
}

// ---- per scan -------------------------------------------------------------------------

bool SdpSlamImpl::relocate(const Pose2& delta) {
  if (!initialised_ || !started_) return false;
  return filter_->displace(delta);
}

SdpStepResult SdpSlamImpl::process(const OdometrySample& odom, const RangeScan& scan) {
  SdpStepResult result;
  if (!initialised_) return result;
  const std::uint64_t requested_before = filter_->map().observations_requested();
  result.bottom = filter_->process(odom, scan);
  if (result.bottom.status == StepResult::Status::kProcessed) {
    ++segment_scans_;
    const std::uint64_t requests = filter_->map().observations_requested() - requested_before;
    if (requests > scan_requests_) scan_requests_ = requests;
    if (segment_scans_ > 1U && requests > later_scan_requests_) later_scan_requests_ = requests;
    const Pose2 best = filter_->best_pose();
    if (!started_) {
      started_ = true;
      segment_start_stamp_us_ = scan.stamp_us - 1;  // the first scan belongs to segment 0
      segment_start_pose_ = Pose2{};
      segmenter_->start(scan.stamp_us, odom.pose);
      box_init(seg_box_);
    }
    last_processed_stamp_us_ = scan.stamp_us;
    box_add(seg_box_, best.x_m, best.y_m);
    const std::uint32_t n = filter_->particle_count();
    for (std::uint32_t i = 0; i < n; ++i) poses_scratch_[i] = filter_->particle_pose(i);
    SegmentEnd end = segmenter_->on_processed(scan.stamp_us, odom.pose, poses_scratch_, n);
    if (end == SegmentEnd::kNone) {
      // The segment's lineage must stay within its square of the DP map's torus.
      const double dx = best.x_m - segment_start_pose_.x_m;
      const double dy = best.y_m - segment_start_pose_.y_m;
      if (!(dx * dx + dy * dy <= window_radius_m_ * window_radius_m_)) end = SegmentEnd::kWindow;
    }
    if (end == SegmentEnd::kNone && segment_scans_ >= 2U) {
      // The pool could not take another scan like this one (each particle writes its
      // scan as new observations before prune folds them into its lineage): the segment
      // ends, and make_room() frees older levels.
      const DpMap& map = filter_->map();
      const std::uint64_t held = std::uint64_t{map.observations_used()} - deferred_observations();
      if (std::uint64_t{map.observation_capacity()} - held < scan_burst()) end = SegmentEnd::kPool;
    }
    if (end != SegmentEnd::kNone) {
      const std::uint64_t before = stats_.segments;
      segment(scan.stamp_us);
      if (stats_.segments != before) {
        result.segmented = end;
        if (end == SegmentEnd::kWindow) ++stats_.window_segmentations;
        if (end == SegmentEnd::kPool) ++stats_.pool_segmentations;
        segmenter_->start(scan.stamp_us, odom.pose);
      }
    }
  }
  deferred_release_step();
  // Top-level work within the budget: anchorage first (the evaluation needs skeletons).
  // With defer_top_work it waits while the bottom level processes scans (bounded).
  if (options_.defer_top_work && result.bottom.status == StepResult::Status::kProcessed &&
      deferred_in_a_row_ < capacity::kMaxDeferredTopWork) {
    ++deferred_in_a_row_;
    ++stats_.top_work_deferred;
    result.pose = current_frame_.compose(result.bottom.pose);
    return result;
  }
  deferred_in_a_row_ = 0U;
  result.work_cells = do_work(options_.work_cells_per_scan);
  bool work_pending = false;
  for (std::uint32_t lv = graph_.first_live_level(); lv < graph_.level_end() && !work_pending; ++lv) {
    for (std::uint32_t k = 0; k < store_.level(lv).count; ++k) {
      if (!store_.submap(lv, k).skeleton_done) {
        work_pending = true;
        break;
      }
    }
  }
  if (round_active_ && !work_pending) {
    for (std::uint32_t e = 0; e < options_.evaluations_per_scan && eval_cursor_ < top_.size(); ++e) {
      evaluate(eval_cursor_++);
      ++result.evaluations;
    }
    if (eval_cursor_ >= top_.size()) end_round(scan.stamp_us, true);
  }
  if (options_.loop_closure && options_.loop_search_window_m > 0.0 && !work_pending && started_) loop_closure_.search_step();
  result.pose = current_frame_.compose(result.bottom.pose);
  return result;
}

void SdpSlamImpl::finish() {
  if (!initialised_) return;
  finish_releases();
  releases_deferred_ = false;
  while (do_work(0xFFFFFFFFU) > 0U) {
  }
}

// ---- segmentation, anchorage, restart (lines 4-8) --------------------------------------

void SdpSlamImpl::segment(std::int64_t stamp_us) {
  const std::uint32_t n = filter_->particle_count();
  // Room in the PGS first (bounded memory): the oldest level becomes permanent.
  if (graph_.live_level_count() >= options_.max_levels) make_oldest_permanent();
  const std::uint64_t room_needed = observations_needed();
  make_room(room_needed);
  NodeId nodes[capacity::kMaxPgsNodesPerLevel];
  std::uint32_t bottom_best = 0U;
  for (std::uint32_t i = 0; i < n; ++i) {
    nodes[i] = filter_->particle_node(i);
    poses_scratch_[i] = filter_->particle_pose(i);
    if (nodes[i] == filter_->best_node()) bottom_best = i;
  }
  const Pose2 restart_pose = filter_->best_pose();
  // Line 6 before line 8: if the restart is refused nothing was anchored yet.
  if (!filter_->restart_segment(restart_pose)) {
    ++stats_.restart_refused;
    return;
  }
  PgsNodeInput in[capacity::kMaxPgsNodesPerLevel];
  for (std::uint32_t i = 0; i < n; ++i) {
    in[i].particle_id = nodes[i];
    in[i].initial_pose = segment_start_pose_;
    in[i].final_pose = poses_scratch_[i];
  }
  const PgsLevelResult added = graph_.add_level(in, n);
  if (added.status != PgsStatus::kOk) {
    // Cannot happen after make_oldest_permanent; the anchored nodes are released so that
    // nothing leaks, and the segment's submaps are lost (counted).
    ++stats_.pgs_refused;
    for (std::uint32_t i = 0; i < n; ++i) filter_->release_anchored(nodes[i]);
    segment_start_pose_ = restart_pose;
    segment_start_stamp_us_ = stamp_us;
    box_init(seg_box_);
    return;
  }
  const std::uint32_t level = added.level;
  SubmapLevel& lv = store_.level(level);
  lv.start_stamp_us = segment_start_stamp_us_;
  lv.end_stamp_us = stamp_us;
  lv.count = n;
  const double pad = bottom_options_.beam.max_update_range_m;
  for (std::uint32_t i = 0; i < n; ++i) {
    Submap& sm = store_.submap(level, i);
    sm = Submap{};
    sm.node = nodes[i];
    sm.initial = segment_start_pose_;
    sm.final_pose = poses_scratch_[i];
    double b[4];
    box_init(b);
    for_each_level_pose(level, nodes[i], [&b](std::int64_t, const Pose2& p) { box_add(b, p.x_m, p.y_m); });
    box_add(b, sm.final_pose.x_m, sm.final_pose.y_m);
    box_add(b, sm.initial.x_m, sm.initial.y_m);
    sm.map_rect = filter_->map().rect_around(b[0], b[1], b[2], b[3], pad);
    sm.path_rect = filter_->map().rect_around(b[0], b[1], b[2], b[3], options_.skeleton_pad_m);
    sm.skeleton_done = false;
  }
  ++stats_.segments;
  segment_scans_ = 0U;
  previous_scan_requests_ = scan_requests_;
  scan_requests_ = 0U;
  previous_later_scan_requests_ = later_scan_requests_;
  later_scan_requests_ = 0U;
  segment_observations_released_ = observations_released_;
  segment_observations_used_ = filter_->map().observations_used();
  segment_observations_refused_ = filter_->map().observation_oom_count();
  if (graph_.live_level_count() > stats_.max_live_levels) stats_.max_live_levels = graph_.live_level_count();
  segment_start_pose_ = restart_pose;
  segment_start_stamp_us_ = stamp_us;
  box_init(seg_box_);
  box_add(seg_box_, restart_pose.x_m, restart_pose.y_m);

  // Lines 10-11: resample with elitism, extend to the new level, start evaluating.
  if (round_active_) end_round(stamp_us, false);  // a round cut short keeps what it measured
  if (level > graph_.first_live_level()) top_.resample_and_diversify(graph_, rng_);
  top_.extend_to_level(level, bottom_best, graph_, rng_);
  rounds_in_segment_ = 0U;
  round_active_ = true;
  eval_cursor_ = 0U;
  round_sum_ = 0.0;
  round_sq_ = 0.0;
  round_samples_ = 0U;
  update_best();
  // The segment just anchored may itself leave no room: it is made permanent too.
  make_room(room_needed);
}

// Room in the bottom level's observation pool (bounded memory): the next segment is
// expected to need as many observations as the one ending now took (its growth of the
// pool, not counting what releases of older submaps gave back meanwhile, plus what the
// pool refused it), and on top what it writes before its first pool check can end it
// (process(): after its second scan): its first scan, which a restart writes whole into
// every particle's fresh lineage (the most a scan of this segment or the previous one
// asked for), and one later scan, whose writes all sit in the pool at once before
// prune folds them (the most a later scan of either asked for). While that does not fit
// beside what is held, pending releases are done at once, then the oldest level
// becomes permanent and is released at once (its observations return to the pool),
// all of them if need be. Fewer live levels only narrow the top level's choice among
// older segments; a full pool would refuse the new segment's own map updates, and its
// particles would then weigh scans against a map with holes. When the pool has room,
// nothing changes: releases stay spread over scans. Checked before the restart and
// again once the ended segment is a level (which may then go too).
std::uint64_t SdpSlamImpl::observations_needed() const {
  const DpMap& map = filter_->map();
  const std::uint64_t grown_to = std::uint64_t{map.observations_used()} + (observations_released_ - segment_observations_released_);
  const std::uint64_t grown = grown_to > segment_observations_used_ ? grown_to - segment_observations_used_ : 0U;
  const std::uint64_t later = later_scan_requests_ > previous_later_scan_requests_ ? later_scan_requests_
                                                                                   : previous_later_scan_requests_;
  return grown + (map.observation_oom_count() - segment_observations_refused_) + scan_burst() + later;
}

// The levels that go are decided on the room as it will be once their releases and map
// copies are done; the releases and copies of all of them are deferred: they give their
// observations back over the next scans, one submap (or one slice of a copy) per scan,
// outside do_work()'s budget, so that the scan of a segmentation does not pay for a
// whole level, even when it makes two or more levels permanent. Until then that room
// counts as made wherever the pool's room is judged (here, the segment's pool check in
// process()), and a scan whose writes need it now takes it at once (make_room_now()).
// Which levels go, and when, is the same as if every release were done at once.
void SdpSlamImpl::make_room(std::uint64_t need) {
  const DpMap& map = filter_->map();
  const std::uint64_t capacity = map.observation_capacity();
  if (std::uint64_t{map.observations_used()} - deferred_observations() + need <= capacity) return;
  defer_pending_releases();
  auto short_of_room = [&] {
    return std::uint64_t{map.observations_used()} - pending_release_observations() + need > capacity;
  };
  while (short_of_room() && graph_.live_level_count() > 0U) {
    const std::uint64_t before = stats_.levels_made_permanent;
    make_oldest_permanent();  // queues its releases and copy behind those pending
    if (stats_.levels_made_permanent == before) return;
    defer_pending_releases();
    ++stats_.levels_made_permanent_for_room;
  }
}

// The deferred releases first, one submap at a time, then the map copy, until the
// writes fit; if they do not, the room a segmentation would make, taken now.
void SdpSlamImpl::make_room_now(std::uint64_t need) {
  const DpMap& map = filter_->map();
  auto fits = [&] { return std::uint64_t{map.observations_used()} + need <= std::uint64_t{map.observation_capacity()}; };
  while (releases_deferred_ && !fits() && release_count_ > 0U) release_one();
  while (releases_deferred_ && !fits() && copies_pending()) transfer_step(0xFFFFFFFFU);
  if (releases_deferred_ && release_count_ == 0U && !copies_pending()) releases_deferred_ = false;
  if (fits()) return;
  make_room(need);
  finish_releases();
}

// A permanent level's tree goes whole: its other submaps are released (prune frees
// their lineages and folds the rest into the chosen one), and the chosen submap is
// copied into the global map and released. Every level made permanent has one copy,
// in progress or queued, and every path finishes a level's releases before its copy
// starts, so the pending trees are those of the copies, one per level: their
// observations are what the pending work gives back.
std::uint64_t SdpSlamImpl::pending_release_observations() const {
  const AncestryTree& tree = filter_->tree();
  const DpMap& map = filter_->map();
  const auto tree_observations = [&](NodeId node) {
    std::uint64_t held = 0U;
    if (node == kNoNode || !tree.contains(node)) return held;
    const std::uint32_t sequence = tree.tree_sequence_unchecked(node);
    for (NodeId n = 0U; n < tree.capacity(); ++n) {
      if (tree.contains(n) && tree.tree_sequence_unchecked(n) == sequence) held += map.observation_count(n);
    }
    return held;
  };
  NodeId copying = kNoNode;
  CellRect rest;
  std::uint64_t held = transfer_.pending(&copying, &rest) ? tree_observations(copying) : 0U;
  for (std::uint32_t k = 0; k < copy_count_; ++k) held += tree_observations(copy_queue_[k].node);
  return held;
}

void SdpSlamImpl::deferred_release_step() {
  if (!releases_deferred_) return;
  if (release_count_ > 0U) {
    release_one();
  } else if (copies_pending()) {
    transfer_step(options_.work_cells_per_scan);
  }
  if (release_count_ == 0U && !copies_pending()) releases_deferred_ = false;
}

std::uint64_t SdpSlamImpl::scan_burst() const {
  return scan_requests_ > previous_scan_requests_ ? scan_requests_ : previous_scan_requests_;
}

// The pending releases and the permanent submaps' copies, all now.
void SdpSlamImpl::finish_releases() {
  while (release_count_ > 0U) release_one();
  while (copies_pending()) transfer_step(0xFFFFFFFFU);
}

void SdpSlamImpl::make_oldest_permanent() {
  const std::uint32_t level = graph_.first_live_level();
  if (!graph_.is_live(level)) return;
  // Pending work first: this level's skeletons. The earlier levels' releases and copies
  // stay queued (the scan that makes two levels permanent does not pay for the first
  // one's), unless the queues have no room for this level's: then they are done now.
  const std::uint32_t count = store_.level(level).count;
  if (release_count_ + count > release_capacity_ || copy_count_ >= options_.max_levels) {
    finish_releases();
    releases_deferred_ = false;
  }
  for (std::uint32_t k = 0; k < count; ++k) {
    if (!store_.submap(level, k).skeleton_done) extract_skeleton(level, k);
  }
  const std::uint32_t chosen = choice(top_.rank(), level);
  const bool had_anchor = graph_.has_anchor();
  const Pose2 previous_frame = graph_.anchor_frame();
  const PgsPermanentResult r = graph_.make_oldest_permanent(chosen);
  if (r.status != PgsStatus::kOk) return;
  ++stats_.levels_made_permanent;
  const Submap& sm = store_.submap(level, chosen);
  // Its poses, in its own frame, and that frame in the global frame.
  if (permanent_sink_ != nullptr) {
    permanent_sink_->on_frame(level, r.frame_in_global);
    for_each_level_pose(level, sm.node, [&](std::int64_t s, const Pose2& p) { permanent_sink_->on_pose(level, s, p); });
  }
  // Its skeleton joins the permanent ring (the oldest is forgotten when full).
  bool forgot = false;
  PermanentSubmap& pm = store_.permanent(store_.make_permanent(level, chosen, &forgot));
  if (forgot) ++stats_.permanent_forgotten;
  pm.frame_in_global = r.frame_in_global;
  pm.frame_in_map = r.frame_in_global;  // the map transfer's frame below
  pm.from_previous = had_anchor ? between(previous_frame, r.frame_in_global) : Pose2{};
  // The other submaps of the level are released now; the chosen one once its map has
  // been copied into the global map node.
  for (std::uint32_t k = 0; k < count; ++k) {
    if (k != chosen && release_count_ < release_capacity_) release_queue_[release_count_++] = store_.submap(level, k).node;
  }
  copy_queue_[copy_count_++] = PendingCopy{sm.node, r.frame_in_global, level, sm.map_rect};
  // Committed poses of the level leave the ring (they are the oldest).
  ring_.drop_through(store_.level(level).end_stamp_us);
  store_.level(level).count = 0U;
}

// The permanent submap's copy into the global map (map_transfer.h), within the budget.
std::uint32_t SdpSlamImpl::transfer_step(std::uint32_t budget_cells) {
  if (!transfer_.active()) {
    if (copy_count_ == 0U) return 0U;
    const PendingCopy c = copy_queue_[0];
    for (std::uint32_t k = 1; k < copy_count_; ++k) copy_queue_[k - 1U] = copy_queue_[k];
    --copy_count_;
    transfer_.start(c.node, c.frame, c.level + 1U, c.rect);
  }
  const TransferStep st = transfer_.work(budget_cells, *filter_, permanent_map_, fine_buffer());
  stats_.map_transfer_cells += st.cells_copied;
  stats_.map_transfer_dropped += st.cells_dropped;
  if (st.popped) ++stats_.map_transfers_popped;
  if (st.by_rows) ++stats_.map_transfers_by_rows;
  if (st.released) ++stats_.submaps_released;
  observations_released_ += st.observations_freed;
  return st.work_cells;
}

std::uint32_t SdpSlamImpl::release_one() {
  if (release_count_ == 0U) return 0U;
  const NodeId node = release_queue_[--release_count_];
  const std::uint32_t held = filter_->map().observations_used();
  if (filter_->release_anchored(node)) ++stats_.submaps_released;
  const std::uint32_t left = filter_->map().observations_used();
  if (left < held) observations_released_ += held - left;
  return 1U;
}

std::uint32_t SdpSlamImpl::do_work(std::uint32_t budget_cells) {
  // Deferred releases and copy have their own slice per scan (deferred_release_step()).
  const bool own_releases = !releases_deferred_;
  std::uint32_t used = own_releases ? release_one() : 0U;
  // The permanent submap's copy into the global map first, in strips within the budget:
  // its observations (and the tiles only it holds) are freed when it completes, and the
  // pool is what the bottom level's new observations come from.
  // It waits for the releases (one per call): they let prune fold the submap's lineage
  // into its node, which can then be popped.
  if (own_releases && copies_pending() && release_count_ == 0U && used < budget_cells) {
    used += transfer_step(budget_cells - used);
  }
  if (used >= budget_cells) return used;
  // Skeletons of the live levels, oldest first, in slices.
  if (skeletons_.active()) used += skeleton_step(budget_cells - used);
  for (std::uint32_t lv = graph_.first_live_level(); lv < graph_.level_end() && used < budget_cells; ++lv) {
    for (std::uint32_t k = 0; k < store_.level(lv).count && used < budget_cells; ++k) {
      if (store_.submap(lv, k).skeleton_done) continue;
      skeletons_.start(store_, lv, k);
      used += skeleton_step(budget_cells - used);
    }
  }
  return used;
}

// A submap's skeleton in slices (skeleton_reader.h), one job at a time.
std::uint32_t SdpSlamImpl::extract_skeleton(std::uint32_t level, std::uint32_t node) {
  if (!skeletons_.is_job(level, node)) {
    while (skeletons_.active()) skeleton_step(0xFFFFFFFFU);
    skeletons_.start(store_, level, node);
  }
  std::uint32_t used = 0U;
  while (skeletons_.active()) used += skeleton_step(0xFFFFFFFFU);
  return used;
}

std::uint32_t SdpSlamImpl::skeleton_step(std::uint32_t budget_cells) {
  const SkeletonStep st = skeletons_.work(budget_cells, *filter_, store_, fine_buffer());
  if (st.extracted) {
    ++stats_.skeletons;
    stats_.skeleton_truncated_points += st.truncated_points;
  }
  return st.cells_read;
}

// ---- top level (lines 10-12) -----------------------------------------------------------

// Ranking, elitism, diversification and extension are TopParticles' (top_particles.h);
// here a combination is evaluated, and each round's outcome published.

void SdpSlamImpl::evaluate(std::uint32_t p) {
  ++stats_.evaluations;
  const std::uint32_t first = graph_.first_live_level();
  const std::uint32_t count = graph_.live_level_count();
  if (count == 0U) return;
  for (std::uint32_t i = 0; i < count; ++i) chain_[i] = choice(p, first + i);
  if (graph_.compose_chain(chain_, count, eval_frames_) != PgsStatus::kOk) return;
  CombinationResult& r = evaluation_;
  evaluator_.evaluate(store_, first, chain_, eval_frames_, count, &r);
  stats_.icp_matches += r.icp_matches;
  stats_.icp_failures += r.icp_failures;
  stats_.icp_memo_hits += r.memo_hits;
  // Loop closure refines each fresh match on obstacle points, from the skeleton match.
  for (std::uint32_t k = 0; k < r.match_count && options_.loop_closure; ++k) {
    const CombinationMatch& mt = r.matches[k];
    const CellPoint* to = nullptr;
    std::uint32_t tn = 0U;
    if (mt.older_permanent) {
      to = store_.permanent_obstacles(mt.older);
      tn = store_.permanent(mt.older).obstacle_count;
    } else {
      to = store_.obstacles(first + mt.older, chain_[mt.older]);
      tn = store_.submap(first + mt.older, chain_[mt.older]).obstacle_count;
    }
    const std::uint32_t newer = first + mt.newer;
    const std::uint32_t sn_count = store_.submap(newer, chain_[mt.newer]).obstacle_count;
    if (tn >= options_.loop_min_pairs && sn_count >= options_.loop_min_pairs) {
      unpack(to, tn, obst_a_);
      unpack(store_.obstacles(newer, chain_[mt.newer]), sn_count, obst_b_);
      loop_closure_.refine(mt.older_level, obst_a_, tn, newer, obst_b_, sn_count, mt.guess, mt.transform);
    }
  }
  if (!r.measured) return;  // no overlap: the weight is not changed (§IV)
  const double err = r.error_m;
  const std::uint32_t lo = r.lo_level;
  const std::uint32_t hi = r.hi_level;
  top_.set_error(p, err);
  ++stats_.evaluations_with_overlap;
  stats_.error_sum_m += err;
  stats_.error_sq_sum_m2 += err * err;
  ++stats_.error_samples;
  round_sum_ += err;
  round_sq_ += err * err;
  ++round_samples_;
  // Line 12: the error goes to the PGS edges of the combination it measured.
  if (hi > lo) graph_.record_chain_error(lo, chain_ + (lo - first), hi - lo + 1U, err);
}

void SdpSlamImpl::end_round(std::int64_t stamp_us, bool may_continue) {
  round_active_ = false;
  ++stats_.rounds;
  ++rounds_in_segment_;
  const bool overlap = round_samples_ > 0U;
  if (overlap) {
    ++stats_.rounds_with_overlap;
    const double n = static_cast<double>(round_samples_);
    const double mean = round_sum_ / n;
    const double v = round_sq_ / n - mean * mean;
    if (listener_ != nullptr) listener_->on_round(stamp_us, mean, v > 0.0 ? det::sqrt(v) : 0.0, round_samples_);
  }
  update_best();
  if (may_continue && overlap && rounds_in_segment_ < options_.rounds_per_segment) {
    top_.resample_and_diversify(graph_, rng_);
    update_best();
    round_active_ = true;
    eval_cursor_ = 0U;
    round_sum_ = 0.0;
    round_sq_ = 0.0;
    round_samples_ = 0U;
  }
}

void SdpSlamImpl::update_best() {
  best_top_ = top_.rank();
  const std::uint32_t first = graph_.first_live_level();
  const std::uint32_t count = graph_.live_level_count();
  if (count == 0U) {
    current_frame_ = Pose2{};
    return;
  }
  for (std::uint32_t i = 0; i < count; ++i) chain_[i] = choice(best_top_, first + i);
  if (graph_.compose_chain(chain_, count, frames_) != PgsStatus::kOk) return;
  if (options_.loop_closure) adjust_frames();
  const Submap& last = store_.submap(first + count - 1U, chain_[count - 1U]);
  // The current segment starts where the last chosen submap ends (Fig. 3 (l)).
  current_frame_ = frames_[count - 1U].compose(last.final_pose.compose(segment_start_pose_.inverse()));
}

// ---- loop closure (beyond the paper; see the header) ------------------------------------

void SdpSlamImpl::unpack(const CellPoint* in, std::uint32_t n, Point2* out) const {
  const DpMap& map = filter_->map();
  const double half = 0.5 * map.resolution_m();
  const double ox = map.options().origin_x_m;
  const double oy = map.options().origin_y_m;
  for (std::uint32_t i = 0; i < n; ++i) {
    out[i].x_m = ox + static_cast<double>(in[i].ix) * half;
    out[i].y_m = oy + static_cast<double>(in[i].iy) * half;
  }
}

// Graph order: the permanent submaps held, oldest first, then the live levels. All
// submaps of a level share the level's frame (the bottom particles restarted at one
// pose in the map's grid frame), so a constraint between two levels' frames measured
// with some of their submaps holds for the chosen ones too.
bool SdpSlamImpl::level_origin(std::uint32_t level, std::int64_t* stamp_us, Pose2* initial) const {
  std::uint32_t pi = 0U;
  if (store_.find_permanent(level, &pi)) {
    *stamp_us = store_.permanent(pi).start_stamp_us;
    *initial = store_.permanent(pi).initial;
    return true;
  }
  const std::uint32_t first = graph_.first_live_level();
  if (level < first || level >= first + graph_.live_level_count() || store_.level(level).count == 0U) return false;
  *stamp_us = store_.level(level).start_stamp_us;
  *initial = store_.submap(level, 0U).initial;
  return true;
}

bool SdpSlamImpl::graph_index(std::uint32_t level, std::uint32_t* index) const {
  std::uint32_t pi = 0U;
  if (store_.find_permanent(level, &pi)) {
    *index = level - store_.first_held_level(level);
    return true;
  }
  const std::uint32_t first = graph_.first_live_level();
  if (level < first || level >= first + graph_.live_level_count()) return false;
  *index = store_.permanent_count() + (level - first);
  return true;
}

// The best combination's frames as a pose graph (frame_graph.h): permanent submaps held
// (oldest fixed), then the chosen live submaps (frames_ on entry: the composed chain),
// chain constraints T between consecutive ones, loop constraints between any two.
void SdpSlamImpl::adjust_frames() {
  const std::uint32_t first = graph_.first_live_level();
  const std::uint32_t count = graph_.live_level_count();
  FrameGraph& g = loop_closure_.begin_adjustment();
  const FrameInfo seg = FrameInfo::from_sigma(options_.segment_sigma_xy_m, options_.segment_sigma_theta_rad);
  bool ok = true;
  for (std::uint32_t k = 0; k < store_.permanent_count(); ++k) {
    const PermanentSubmap& pm = store_.permanent(store_.permanent_slot_at(k));
    ok = ok && g.add_node(pm.frame_in_global, pm.from_previous, seg);
  }
  for (std::uint32_t i = 0; i < count && ok; ++i) {
    Pose2 t;
    if (i > 0U) {
      ok = graph_.transform_between(first + i - 1U, chain_[i - 1U], chain_[i], t) == PgsStatus::kOk;
    } else if (store_.permanent_count() > 0U) {
      t = between(graph_.anchor_frame(), frames_[0]);
    }
    ok = ok && g.add_node(frames_[i], t, seg);
  }
  if (!ok) {
    ++stats_.frame_graph_refused;
    return;
  }
  if (!loop_closure_.finish_adjustment()) return;  // the chain alone is already consistent
  double offset = 0.0;
  for (std::uint32_t k = 0; k < store_.permanent_count(); ++k) {
    PermanentSubmap& pm = store_.permanent(store_.permanent_slot_at(k));
    pm.frame_in_global = g.frame(k);
    if (permanent_sink_ != nullptr) permanent_sink_->on_frame(pm.level, pm.frame_in_global);
    const double d = frame_offset_m(pm.frame_in_map, pm.frame_in_global, pm.box);
    if (d > offset) offset = d;
  }
  stats_.permanent_map_offset_m = offset;
  if (offset > stats_.permanent_map_offset_max_m) stats_.permanent_map_offset_max_m = offset;
  if (store_.permanent_count() > 0U) graph_.set_anchor_frame(g.frame(store_.permanent_count() - 1U));
  for (std::uint32_t i = 0; i < count; ++i) frames_[i] = g.frame(store_.permanent_count() + i);
}

// ---- the submaps as loop closure sees them (loop_closure.h) ----------------------------

bool SdpSlamImpl::level_obstacles(std::uint32_t level, const CellPoint** points, std::uint32_t* count, Pose2* frame,
                              double box[4]) const {
  std::uint32_t pi = 0U;
  if (store_.find_permanent(level, &pi)) {
    const PermanentSubmap& pm = store_.permanent(pi);
    *points = store_.permanent_obstacles(pi);
    *count = pm.obstacle_count;
    *frame = pm.frame_in_global;
    for (int i = 0; i < 4; ++i) box[i] = pm.box[i];
    return true;
  }
  const std::uint32_t first = graph_.first_live_level();
  if (level < first || level >= first + graph_.live_level_count()) return false;
  const std::uint32_t node = choice(best_top_, level);
  const Submap& sm = store_.submap(level, node);
  if (!sm.skeleton_done) return false;
  *points = store_.obstacles(level, node);
  *count = sm.obstacle_count;
  *frame = frames_[level - first];
  for (int i = 0; i < 4; ++i) box[i] = sm.box[i];
  return true;
}

std::uint32_t SdpSlamImpl::first_held_level() const {
  return store_.first_held_level(graph_.first_live_level());
}

bool SdpSlamImpl::placement(std::uint32_t level, Pose2* frame, double box[4], std::uint32_t* obstacle_count) const {
  const CellPoint* points = nullptr;
  return level_obstacles(level, &points, obstacle_count, frame, box);
}

void SdpSlamImpl::obstacles(std::uint32_t level, Point2* out) const {
  const CellPoint* points = nullptr;
  std::uint32_t n = 0U;
  Pose2 frame;
  double box[4];
  if (level_obstacles(level, &points, &n, &frame, box)) unpack(points, n, out);
}

}  // namespace sdpslam
