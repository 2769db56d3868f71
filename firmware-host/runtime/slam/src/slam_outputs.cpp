#include "sdpslam/slam/slam_outputs.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

#include "sdpslam/core/det_math.h"

namespace sdpslam::slam {

std::vector<io::StampedPose> assemble_trajectory(const std::vector<ScanRecord>& scans,
                                                 const std::vector<io::StampedPose>& path,
                                                 std::uint64_t* path_gaps) {
  std::vector<io::StampedPose> trajectory;
  trajectory.reserve(scans.size());
  std::size_t pi = 0U;
  bool anchored = false;
  Pose2 anchor_pose;
  Pose2 anchor_odom;
  std::uint64_t gaps = 0U;
  for (const ScanRecord& s : scans) {
    Pose2 pose;
    bool from_path = false;
    if (s.processed) {
      while (pi < path.size() && path[pi].stamp_us < s.stamp_us) ++pi;
      if (pi < path.size() && path[pi].stamp_us == s.stamp_us) {
        pose = path[pi].pose;
        ++pi;
        from_path = true;
      } else {
        ++gaps;
      }
    }
    if (!from_path) pose = anchored ? anchor_pose.compose(between(anchor_odom, s.odom)) : s.online;
    if (from_path || !anchored) {
      anchor_pose = pose;
      anchor_odom = s.odom;
      anchored = true;
    }
    trajectory.push_back({s.stamp_us, pose});
  }
  if (path_gaps != nullptr) *path_gaps = gaps;
  return trajectory;
}

std::vector<io::StampedPose> smooth_with_odometry(const std::vector<ScanRecord>& scans,
                                                  const std::vector<io::StampedPose>& trajectory) {
  const std::size_t n = trajectory.size();
  if (scans.size() != n) return trajectory;
  for (std::size_t i = 0; i < n; ++i) {
    if (scans[i].stamp_us != trajectory[i].stamp_us) return trajectory;
  }
  // Travel along the trajectory up to each pose.
  std::vector<double> travel(n, 0.0);
  for (std::size_t i = 1; i < n; ++i) {
    const Pose2 d = between(trajectory[i - 1].pose, trajectory[i].pose);
    travel[i] = travel[i - 1] + det::sqrt(d.x_m * d.x_m + d.y_m * d.y_m) + kSmoothTurnM * std::fabs(d.heading_rad);
  }
  const double reach = 2.0 * kSmoothSigmaM;
  std::vector<io::StampedPose> out = trajectory;
  std::size_t lo = 0;
  for (std::size_t i = 0; i < n; ++i) {
    while (travel[i] - travel[lo] > reach) ++lo;
    const Pose2& own = trajectory[i].pose;
    double sx = 0.0, sy = 0.0, sc = 0.0, ss = 0.0, sw = 0.0;
    for (std::size_t j = lo; j < n && travel[j] - travel[i] <= reach; ++j) {
      const Pose2 p = trajectory[j].pose.compose(between(scans[j].odom, scans[i].odom));
      const double ex = p.x_m - own.x_m;
      const double ey = p.y_m - own.y_m;
      if (ex * ex + ey * ey > kSmoothGateM * kSmoothGateM) continue;
      const double u = (travel[j] - travel[i]) / kSmoothSigmaM;
      const double w = det::exp(-0.5 * u * u);
      // Positions relative to p_i, headings as their difference to p_i's: no wrap.
      const double dh = normalize_angle_rad(p.heading_rad - own.heading_rad);
      sx += w * ex;
      sy += w * ey;
      sc += w * det::cos(dh);
      ss += w * det::sin(dh);
      sw += w;
    }
    if (!(sw > 0.0)) continue;  // p_i itself counts, so only a non-finite pose: left as it was
    out[i].pose = Pose2{own.x_m + sx / sw, own.y_m + sy / sw, normalize_angle_rad(own.heading_rad + det::atan2(ss, sc))};
  }
  return out;
}

std::uint32_t best_map_image(const DpSlamFilter& filter, io::OccupancyImage* image) {
  const DpMap& map = filter.map();
  *image = io::OccupancyImage{};
  image->resolution_m = map.resolution_m();
  CellRect rect;
  if (!map.touched_bounds(&rect)) return 0U;
  std::vector<CellObservation> values(static_cast<std::size_t>(rect.width) * rect.height);
  std::vector<std::uint8_t> known(values.size(), 0U);
  const std::uint32_t known_cells = map.fill_rect(filter.best_node(), rect, values.data(), known.data());
  image->width = rect.width;
  image->height = rect.height;
  image->origin_x_m = map.options().origin_x_m + rect.ix0 * map.resolution_m();
  image->origin_y_m = map.options().origin_y_m + rect.iy0 * map.resolution_m();
  image->occupancy.resize(values.size());
  for (std::size_t i = 0; i < values.size(); ++i) {
    image->occupancy[i] = known[i] != 0U ? static_cast<float>(filter.occupancy(values[i])) : -1.0F;
  }
  return known_cells;
}

bool write_trajectories(const std::string& out_dir, const std::vector<io::StampedPose>& trajectory,
                        std::string* error) {
  return io::write_trajectory(out_dir + "/trajectory.txt", trajectory, error) &&
         io::write_trajectory_tum(out_dir + "/trajectory.tum", trajectory, error);
}

io::MapWriteOptions slam_map_thresholds() {
  io::MapWriteOptions t;
  t.occupied_thresh = kSlamOccupiedThreshold;
  return t;
}

bool write_trajectory_and_map(const std::string& out_dir, const std::vector<io::StampedPose>& trajectory,
                              const io::OccupancyImage& image, std::string* error, const io::Painter* painter) {
  if (!write_trajectories(out_dir, trajectory, error)) return false;
  if (image.width > 0U) {
    if (!io::write_map_pgm_yaml(out_dir + "/map", image, slam_map_thresholds(), error)) return false;
    io::MapFigure figure;
    figure.title = "Map and path";
    figure.map = &image;
    figure.path = &trajectory;
    const io::Painter plain = io::plain_painter();
    if (!(painter != nullptr ? *painter : plain).map(out_dir + "/map.png", figure, error)) return false;
  }
  return true;
}

// ---- SDP-SLAM ------------------------------------------------------------------------

void SdpPermanentPath::on_pose(std::uint32_t level, std::int64_t stamp_us, const Pose2& local) {
  if (bounded_ && poses_.size() >= poses_.capacity()) {
    ++dropped_;
    return;
  }
  poses_.push_back(LocalPose{level, stamp_us, local});
}

void SdpPermanentPath::write_state(io::SnapshotOut& out) const {
  io::put_vector(out, poses_);
  io::put_vector(out, frames_);
  out.put_u64(dropped_);
}

bool SdpPermanentPath::read_state(io::SnapshotIn& in) {
  if (!io::get_vector(in, &poses_) || !io::get_vector(in, &frames_) || !in.get_u64(&dropped_)) return false;
  // A bounded path keeps its room: the poses it may still take were reserved.
  if (bounded_) return poses_.size() <= poses_.capacity() && frames_.size() <= frames_.capacity();
  return true;
}

void SdpPermanentPath::on_frame(std::uint32_t level, const Pose2& frame_in_global) {
  if (level >= frames_.size()) {
    if (bounded_ && level >= frames_.capacity()) return;  // its poses were not stored either
    frames_.resize(level + 1U);
  }
  frames_[level] = frame_in_global;
}

std::vector<io::StampedPose> SdpPermanentPath::global_poses() const {
  std::vector<io::StampedPose> out;
  out.reserve(poses_.size());
  for (const LocalPose& p : poses_) {
    if (p.level < frames_.size()) out.push_back({p.stamp_us, frames_[p.level].compose(p.local)});
  }
  return out;
}

std::vector<io::StampedPose> sdp_best_path(const SdpSlam& slam, const SdpPermanentPath& permanent) {
  std::vector<io::StampedPose> path = permanent.global_poses();
  slam.for_each_best_pose([&](std::int64_t s, const Pose2& p) { path.push_back({s, p}); });
  return path;
}

std::uint32_t sdp_global_map_image(const SdpSlam& slam, io::OccupancyImage* image) {
  *image = io::OccupancyImage{};
  SdpSlam::GlobalMapGrid grid;
  if (!slam.global_map_grid(&grid)) return 0U;
  const std::uint32_t w = grid.width;
  const std::uint32_t h = grid.height;
  std::vector<CellObservation> sum(static_cast<std::size_t>(w) * h);
  std::vector<std::uint8_t> any(sum.size(), 0U);
  // Every known cell, the permanent ones moved with their level's frame; the cells that
  // fall in one image cell are summed.
  slam.for_each_global_cell([&](double x, double y, const CellObservation& v) {
    const double fx = std::floor((x - grid.origin_x_m) / grid.resolution_m);
    const double fy = std::floor((y - grid.origin_y_m) / grid.resolution_m);
    if (fx < 0.0 || fy < 0.0 || fx >= w || fy >= h) return;
    const std::size_t g = static_cast<std::size_t>(fy) * w + static_cast<std::size_t>(fx);
    sum[g] = accumulate(sum[g], v.hits, v.misses);
    any[g] = 1U;
  });
  image->width = w;
  image->height = h;
  image->resolution_m = grid.resolution_m;
  image->origin_x_m = grid.origin_x_m;
  image->origin_y_m = grid.origin_y_m;
  image->occupancy.assign(sum.size(), -1.0F);
  std::uint32_t known_cells = 0U;
  for (std::size_t i = 0; i < sum.size(); ++i) {
    if (any[i] == 0U) continue;
    image->occupancy[i] = static_cast<float>(slam.occupancy(sum[i]));
    ++known_cells;
  }
  return known_cells;
}

io::Json proposal_json(const DpSlamStats& stats) {
  return {{"matched", stats.proposal_matched},
          {"fallback_few_beams", stats.proposal_fallback_few_beams},
          {"fallback_empty_map", stats.proposal_fallback_empty_map},
          {"fallback_low_score", stats.proposal_fallback_low_score},
          {"evaluations", stats.proposal_evaluations}};
}

io::Json filter_pools_json(const DpSlamFilter& filter) {
  const AncestryTree& tree = filter.tree();
  const DpMap& map = filter.map();
  io::Json js;
  js["ancestry_nodes"] = {{"capacity", tree.capacity()},
                          {"peak", tree.peak_used()},
                          {"exhausted", tree.node_oom_count()},
                          {"fallbacks", filter.stats().node_fallback_count}};
  js["path_entries"] = {{"capacity", tree.path_entry_capacity()},
                        {"peak", tree.path_entries_peak()},
                        {"exhausted", tree.path_oom_count()}};
  js["observations"] = {{"capacity", map.observation_capacity()},
                        {"peak", map.observations_peak()},
                        {"exhausted", map.observation_oom_count()},
                        {"room_asked", filter.stats().map_room_asked},
                        {"room_short", filter.stats().map_room_short},
                        {"writes_shortened", filter.stats().map_writes_shortened},
                        {"shortest_write_reach_m", filter.stats().map_writes_shortened > 0U
                                                       ? filter.stats().shortest_write_reach_m
                                                       : filter.options().beam.max_update_range_m}};
  js["tiles"] = {{"capacity", map.tile_capacity()}, {"peak", map.tiles_peak()}, {"exhausted", map.tile_oom_count()}};
  return js;
}

std::string sdp_loops_tsv(const SdpSlam& slam) {
  std::string out =
      "# sdpslam loop constraints: older newer source used error_m z_x z_y z_theta older_stamp older_x older_y "
      "older_theta newer_stamp newer_x newer_y newer_theta (s, m, rad)\n";
  auto origin = [&slam](std::uint32_t level) {
    std::int64_t stamp_us = 0;
    Pose2 p;
    if (!slam.level_origin(level, &stamp_us, &p)) return std::string("- 0 0 0");
    char text[160];
    std::snprintf(text, sizeof text, "%s %.6f %.6f %.9f", io::format_stamp_us(stamp_us).c_str(), p.x_m, p.y_m,
                  p.heading_rad);
    return std::string(text);
  };
  for (std::uint32_t k = 0; k < slam.loop_record_count(); ++k) {
    const SdpLoopRecord r = slam.loop_record(k);
    const bool used = slam.level_held(r.older_level) && slam.level_held(r.newer_level);
    char line[200];
    std::snprintf(line, sizeof line, "%u %u %s %d %.6f %.6f %.6f %.9f ", r.older_level, r.newer_level,
                  r.searched ? "search" : "icp", used ? 1 : 0, r.error_m, r.z.x_m, r.z.y_m, r.z.heading_rad);
    out += line + origin(r.older_level) + " " + origin(r.newer_level) + "\n";
  }
  return out;
}

std::string sdp_segments_tsv(const SdpSlam& slam) {
  std::string out = "# sdpslam segments: level start_stamp (s); a level holds the scans after its start up to the next start\n";
  std::uint32_t current = 0U;
  std::int64_t current_start_us = 0;
  if (!slam.current_segment(&current, &current_start_us)) return out;
  for (std::uint32_t level = 0; level <= current; ++level) {
    std::int64_t start_us = current_start_us;
    Pose2 initial;
    if (level < current && !slam.level_origin(level, &start_us, &initial)) continue;
    out += std::to_string(level) + " " + io::format_stamp_us(start_us) + "\n";
  }
  return out;
}

io::Json sdp_state_json(const SdpSlam& slam, std::size_t arena_bytes, std::size_t arena_used_bytes,
                        std::uint64_t path_gaps, std::uint32_t known_cells) {
  const DpSlamFilter& bottom = slam.bottom();
  const DpMap& map = bottom.map();
  const DpSlamStats& bs = bottom.stats();
  const SdpStats& st = slam.stats();
  const SdpPools sp = slam.pools();
  const SdpOptions& so = slam.options();
  auto fixed = [](double v, int decimals) { return io::json_fixed(v, decimals); };
  io::Json js;
  js["segments"] = st.segments;
  js["restart_refused"] = st.restart_refused;
  js["window_segmentations"] = st.window_segmentations;
  js["pool_segmentations"] = st.pool_segmentations;
  js["levels_made_permanent"] = st.levels_made_permanent;
  js["levels_made_permanent_for_room"] = st.levels_made_permanent_for_room;
  js["submaps_released"] = st.submaps_released;
  js["global_map_transfers"] = {{"cells", st.map_transfer_cells},
                                {"popped", st.map_transfers_popped},
                                {"by_rows", st.map_transfers_by_rows},
                                {"permanent_offset_m", fixed(st.permanent_map_offset_m, 3)},
                                {"permanent_offset_max_m", fixed(st.permanent_map_offset_max_m, 3)}};
  js["icp_error"] = {{"mean_m", fixed(st.error_mean_m(), 6)},
                     {"std_m", fixed(st.error_std_m(), 6)},
                     {"samples", st.error_samples},
                     {"rounds", st.rounds},
                     {"rounds_with_overlap", st.rounds_with_overlap},
                     {"evaluations", st.evaluations},
                     {"icp_matches", st.icp_matches},
                     {"icp_failures", st.icp_failures}};
  js["top_work_deferred"] = st.top_work_deferred;
  js["bottom_proposal"] = bottom.options().proposal == DpSlamOptions::Proposal::kScanMatch ? "scan_match" : "odometry";
  js["proposal"] = proposal_json(bs);
  js["loop_closure"] = {{"enabled", so.loop_closure},
                        {"records", st.loop_records},
                        {"refinements", st.loop_refinements},
                        {"added", st.loop_records_added},
                        {"dropped", st.loop_records_dropped},
                        {"rivals_refused", st.loop_rivals_refused},
                        {"used_last", st.loop_constraints_used},
                        {"downweighted_last", st.loop_downweighted},
                        {"weak_direction", st.loop_constraints_weak_direction},
                        {"information_unmeasured", st.loop_information_unmeasured},
                        {"adjustments", st.frame_adjustments},
                        {"graph_refused", st.frame_graph_refused},
                        {"steps_refused", st.frame_steps_refused},
                        {"adjustments_capped", st.frame_adjustments_capped},
                        {"search",
                         {{"window_m", fixed(so.loop_search_window_m, 3)},
                          {"max_window_m", fixed(so.loop_search_max_window_m, 3)},
                          {"pairs", st.loop_searches},
                          {"weak", st.loop_search_weak},
                          {"ambiguous", st.loop_search_ambiguous},
                          {"failed", st.loop_search_failed},
                          {"refuted", st.loop_search_refuted},
                          {"closed", st.loop_search_closed},
                          {"far", st.loop_search_far},
                          {"recentred", st.loop_search_recentred},
                          {"recentred_closed", st.loop_search_recentred_closed},
                          {"candidates_dropped", st.loop_search_candidates_dropped},
                          {"levels_skipped", st.loop_search_levels_skipped}}}};
  io::Json pools = filter_pools_json(bottom);
  pools["pgs_levels"] = {{"capacity", so.max_levels}, {"peak", sp.pgs_levels_peak}, {"refused", st.pgs_refused}};
  pools["permanent_submaps"] = {{"capacity", so.max_permanent_submaps},
                                {"used", sp.permanent_submaps},
                                {"forgotten", st.permanent_forgotten}};
  pools["permanent_map_tiles"] = {{"capacity", sp.permanent_map_tile_capacity},
                                  {"used", sp.permanent_map_tiles_used},
                                  {"known_cells", sp.permanent_map_known_cells},
                                  {"compactions", sp.permanent_map_compactions},
                                  {"cell_m", fixed(bottom.map().resolution_m() *
                                                       static_cast<double>(std::uint64_t{1} << sp.permanent_map_scale_log2), 3)},
                                  {"exhausted", sp.permanent_map_refused}};
  pools["pose_ring"] = {{"capacity", sp.pose_ring_capacity},
                        {"peak", st.pose_ring_peak},
                        {"dropped", st.pose_ring_dropped}};
  pools["map_updates_dropped"] = bs.map_updates_dropped;
  pools["global_map_updates_dropped"] = st.map_transfer_dropped;
  pools["out_of_map_updates"] = map.out_of_bounds_count();
  pools["trajectory_gaps_filled_from_odometry"] = path_gaps;
  js["pools"] = std::move(pools);
  js["memory"] = {{"arena_bytes", arena_bytes},
                  {"arena_used_bytes", arena_used_bytes},
                  {"global_map_known_cells", known_cells}};
  return js;
}

}  // namespace sdpslam::slam
