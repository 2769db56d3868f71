// SdpSlam (sdp_slam.h): the API over SdpSlamImpl (sdp_slam_impl.h), which it keeps in
// fixed storage of its own so that the parts' headers stay the core's.
#include <new>

#include "sdp_slam_impl.h"

namespace sdpslam {

static_assert(sizeof(SdpSlamImpl) <= SdpSlam::kStorageBytes, "SdpSlam::kStorageBytes: too small for SdpSlamImpl");
static_assert(alignof(SdpSlamImpl) <= alignof(std::max_align_t), "SdpSlamImpl: over-aligned");

SdpSlam::SdpSlam() : impl_(new (storage_) SdpSlamImpl()) {}
SdpSlam::~SdpSlam() { impl_->~SdpSlamImpl(); }

DpSlamOptions SdpSlam::bottom_options_for(const DpSlamOptions& bottom, const SdpOptions& sdp) {
  return SdpSlamImpl::bottom_options_for(bottom, sdp);
}
bool SdpSlam::check_options(const DpSlamOptions& bottom, const SdpOptions& sdp, char* why, std::size_t n) {
  return SdpSlamImpl::check_options(bottom, sdp, why, n);
}
std::size_t SdpSlam::required_arena_bytes(const DpSlamOptions& bottom, const SdpOptions& sdp) {
  return SdpSlamImpl::required_arena_bytes(bottom, sdp);
}
double SdpSlam::box_overlap_m2(const double a[4], const double b[4]) { return SdpSlamImpl::box_overlap_m2(a, b); }

bool SdpSlam::init(const DpSlamOptions& bottom, const SdpOptions& sdp, Arena& arena, std::uint64_t seed) {
  return impl().init(bottom, sdp, arena, seed);
}
const char* SdpSlam::why() const { return impl().why(); }
SdpStepResult SdpSlam::process(const OdometrySample& odom, const RangeScan& scan) { return impl().process(odom, scan); }
void SdpSlam::finish() { impl().finish(); }
bool SdpSlam::relocate(const Pose2& delta) { return impl().relocate(delta); }
void SdpSlam::set_permanent_sink(SdpPathSink* sink) { impl().set_permanent_sink(sink); }
void SdpSlam::set_listener(TopLevelListener* listener) { impl().set_listener(listener); }

void SdpSlam::visit_best_poses(void (*fn)(void*, std::int64_t, const Pose2&), void* context) const {
  impl().for_each_best_pose([&](std::int64_t stamp_us, const Pose2& p) { fn(context, stamp_us, p); });
}
void SdpSlam::visit_best_submaps(void (*fn)(void*, NodeId, const Pose2&, const CellRect&), void* context) const {
  impl().for_each_best_submap([&](NodeId node, const Pose2& frame, const CellRect& r) { fn(context, node, frame, r); });
}
void SdpSlam::visit_permanent_cells(void (*fn)(void*, double, double, const CellObservation&), void* context) const {
  impl().for_each_permanent_cell([&](double x, double y, const CellObservation& v) { fn(context, x, y, v); });
}
void SdpSlam::visit_global_cells(void (*fn)(void*, double, double, const CellObservation&), void* context) const {
  impl().for_each_global_cell([&](double x, double y, const CellObservation& v) { fn(context, x, y, v); });
}

bool SdpSlam::global_map_grid(GlobalMapGrid* grid) const { return impl().global_map_grid(grid); }
double SdpSlam::occupancy(const CellObservation& value) const { return impl().occupancy(value); }
Pose2 SdpSlam::current_frame() const { return impl().current_frame(); }
std::uint32_t SdpSlam::best_top_particle() const { return impl().best_top_particle(); }
const DpSlamFilter& SdpSlam::bottom() const { return impl().bottom(); }
const SdpOptions& SdpSlam::options() const { return impl().options(); }
const SdpStats& SdpSlam::stats() const { return impl().stats(); }

SdpPools SdpSlam::pools() const {
  const PermanentMap& map = impl().permanent_map();
  SdpPools p;
  p.pgs_levels_peak = impl().graph().peak_levels_used();
  p.permanent_submaps = impl().permanent_submap_count();
  p.pose_ring_capacity = impl().pose_ring_capacity();
  p.pending_releases = impl().pending_releases();
  p.pending_copies = impl().pending_copies();
  p.permanent_map_tile_capacity = map.tile_capacity();
  p.permanent_map_tiles_used = map.tiles_used();
  p.permanent_map_known_cells = map.known_cells();
  p.permanent_map_compactions = map.compactions();
  p.permanent_map_scale_log2 = map.scale_log2();
  p.permanent_map_refused = map.refused_no_tile();
  return p;
}

std::uint32_t SdpSlam::loop_record_count() const { return impl().loop_closure().record_count(); }
SdpLoopRecord SdpSlam::loop_record(std::uint32_t k) const {
  const LoopClosure::Record& r = impl().loop_closure().record(k);
  SdpLoopRecord out;
  out.older_level = r.older_level;
  out.newer_level = r.newer_level;
  out.searched = r.searched;
  out.error_m = r.error_m;
  out.z = r.z;
  return out;
}
bool SdpSlam::level_origin(std::uint32_t level, std::int64_t* stamp_us, Pose2* initial) const {
  return impl().level_origin(level, stamp_us, initial);
}
bool SdpSlam::level_held(std::uint32_t level) const { return impl().level_held(level); }
bool SdpSlam::current_segment(std::uint32_t* level, std::int64_t* start_stamp_us) const {
  return impl().current_segment(level, start_stamp_us);
}
std::size_t SdpSlam::arena_bytes_used() const { return impl().arena_bytes_used(); }
void SdpSlam::top_error(double* mean_m, double* std_m, std::uint32_t* count) const {
  impl().top_error(mean_m, std_m, count);
}

const SegmentGraph& SdpSlam::graph() const { return impl().graph(); }
const PermanentMap& SdpSlam::permanent_map() const { return impl().permanent_map(); }

bool SdpSlam::save_state(StateWriter& writer) { return impl().save_state(writer); }
bool SdpSlam::load_state(StateReader& reader) { return impl().load_state(reader); }
std::uint64_t SdpSlam::state_bytes() const { return impl().state_bytes(); }

}  // namespace sdpslam
