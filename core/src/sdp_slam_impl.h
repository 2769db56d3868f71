#pragma once
// The engine behind SdpSlam (sdp_slam.h, whose comment gives the design: paper §III,
// Algorithm 1, and what the default adds beyond it). It holds the parts of both levels
// and of loop closure by value; their headers are the core's own (not installed), so
// the public SdpSlam keeps this object in fixed storage of its own and forwards to it.
// Methods and comments are those of the API unless marked otherwise.
#include <cstddef>
#include <cstdint>

#include "loops/frame_graph.h"
#include "loops/loop_closure.h"
#include "pose_ring.h"
#include "sdpslam/core/bottom/dpslam_filter.h"
#include "sdpslam/core/sdp_options.h"
#include "sdpslam/core/sdp_slam.h"
#include "sdpslam/core/sdp_stats.h"
#include "sdpslam/core/top/icp2d.h"
#include "top/combination_evaluator.h"
#include "top/free_space_skeleton.h"
#include "top/map_transfer.h"
#include "top/permanent_map.h"
#include "top/segment_graph.h"
#include "top/segmentation.h"
#include "top/skeleton_reader.h"
#include "top/submap_store.h"
#include "top/top_particles.h"

namespace sdpslam {

class SdpSlamImpl {
 public:
  // The API of SdpSlam (sdp_slam.h, which documents it), and the parts for inspection.
  SdpSlamImpl() = default;
  SdpSlamImpl(const SdpSlamImpl&) = delete;
  SdpSlamImpl& operator=(const SdpSlamImpl&) = delete;

  static DpSlamOptions bottom_options_for(const DpSlamOptions& bottom, const SdpOptions& sdp);
  static bool check_options(const DpSlamOptions& bottom, const SdpOptions& sdp, char* why, std::size_t n);
  static std::size_t required_arena_bytes(const DpSlamOptions& bottom, const SdpOptions& sdp);
  bool init(const DpSlamOptions& bottom, const SdpOptions& sdp, Arena& arena, std::uint64_t seed);
  const char* why() const { return why_; }

  SdpStepResult process(const OdometrySample& odom, const RangeScan& scan);
  void finish();
  bool relocate(const Pose2& delta);

  void set_permanent_sink(SdpPathSink* sink) { permanent_sink_ = sink; }
  void set_listener(TopLevelListener* listener) { listener_ = listener; }

  template <class F>
  void for_each_best_pose(F&& f) const;
  template <class F>
  void for_each_best_submap(F&& f) const;
  template <class F>
  void for_each_permanent_cell(F&& f) const;
  const PermanentMap& permanent_map() const { return permanent_map_; }

  using GlobalMapGrid = SdpGlobalMapGrid;
  bool global_map_grid(GlobalMapGrid* grid) const;
  template <class F>
  void for_each_global_cell(F&& f) const;
  double occupancy(const CellObservation& value) const { return filter_->occupancy(value); }

  Pose2 current_frame() const { return current_frame_; }
  std::uint32_t best_top_particle() const { return best_top_; }

  const DpSlamFilter& bottom() const { return *filter_; }
  const SegmentGraph& graph() const { return graph_; }
  const SdpOptions& options() const { return options_; }
  const SdpStats& stats() const { return stats_; }

  const LoopClosure& loop_closure() const { return loop_closure_; }
  bool level_origin(std::uint32_t level, std::int64_t* stamp_us, Pose2* initial) const;
  bool current_segment(std::uint32_t* level, std::int64_t* start_stamp_us) const {
    if (!initialised_ || !started_) return false;
    *level = graph_.level_end();
    *start_stamp_us = segment_start_stamp_us_;
    return true;
  }
  bool level_held(std::uint32_t level) const {
    std::uint32_t index = 0U;
    return graph_index(level, &index);
  }
  std::uint32_t permanent_submap_count() const { return store_.permanent_count(); }
  std::uint32_t pose_ring_capacity() const { return ring_.capacity(); }
  std::uint32_t pending_copies() const { return (transfer_.active() ? 1U : 0U) + copy_count_; }
  std::uint32_t pending_releases() const { return release_count_; }
  std::size_t arena_bytes_used() const { return arena_used_; }
  void top_error(double* mean_m, double* std_m, std::uint32_t* count) const;

  bool save_state(StateWriter& writer);
  bool load_state(StateReader& reader);
  std::uint64_t state_bytes() const;

  static double box_overlap_m2(const double a[4], const double b[4]);

 private:
  class RingSink final : public PoseSink {
   public:
    explicit RingSink(SdpSlamImpl& owner) : owner_(owner) {}
    void on_committed(std::int64_t stamp_us, const Pose2& pose) override { owner_.ring_push(stamp_us, pose); }

   private:
    SdpSlamImpl& owner_;
  };

  // Cell points → metres in the submap frame (scratch buffer).
  void unpack(const CellPoint* in, std::uint32_t n, Point2* out) const;
  std::uint16_t choice(std::uint32_t particle, std::uint32_t level) const { return top_.choice(particle, level); }

  void ring_push(std::int64_t stamp_us, const Pose2& pose);
  template <class F>
  void for_each_level_pose(std::uint32_t level, NodeId leaf, F&& f) const;
  template <class F>
  void for_each_current_pose(F&& f) const;

  void segment(std::int64_t stamp_us);
  std::uint64_t observations_needed() const;
  void make_room(std::uint64_t need);
  // Room for writes about to be made (MapRoom): what make_room() does, with the room
  // there now.
  void make_room_now(std::uint64_t need);
  // Observations the pending releases and map copy will give back.
  std::uint64_t pending_release_observations() const;
  // Of them, those make_room() deferred: room counted as made.
  std::uint64_t deferred_observations() const { return releases_deferred_ ? pending_release_observations() : 0U; }
  void defer_pending_releases() { releases_deferred_ = release_count_ > 0U || copies_pending(); }
  bool copies_pending() const { return transfer_.active() || copy_count_ > 0U; }
  // One slice of the deferred releases and map copy (once per process()).
  void deferred_release_step();
  // The most DP map observations one processed scan asked for, in this segment or the previous one.
  std::uint64_t scan_burst() const;
  void finish_releases();
  void make_oldest_permanent();
  std::uint32_t do_work(std::uint32_t budget_cells);
  // The whole skeleton now (completing any other job first); returns cells read.
  std::uint32_t extract_skeleton(std::uint32_t level, std::uint32_t node);
  std::uint32_t skeleton_step(std::uint32_t budget_cells);  // the job, within the budget
  std::uint32_t transfer_step(std::uint32_t budget_cells);  // the map transfer, within the budget
  FineBuffer fine_buffer() const { return FineBuffer{fine_values_, fine_known_, fine_cells_}; }
  std::uint32_t release_one();
  void evaluate(std::uint32_t particle);
  void end_round(std::int64_t stamp_us, bool may_continue);
  void update_best();
  // Index of a level's frame in the best combination's frame graph, if it is part of it.
  bool graph_index(std::uint32_t level, std::uint32_t* index) const;
  void adjust_frames();
  // Both directions of a snapshot (save_state / load_state).
  void transfer_state(StateIo& io);
  // Obstacle points and global frame of a level in the best combination (permanent or
  // live); false if the level is no longer held.
  bool level_obstacles(std::uint32_t level, const CellPoint** points, std::uint32_t* count, Pose2* frame,
                       double box[4]) const;
  // The best combination's submaps, as loop closure sees them (LoopView).
  std::uint32_t first_held_level() const;
  bool placement(std::uint32_t level, Pose2* frame, double box[4], std::uint32_t* obstacle_count) const;
  void obstacles(std::uint32_t level, Point2* out) const;
  // LoopSubmaps for LoopClosure, kept a member (as RingSink) so that SdpSlam itself has no
  // virtual functions.
  class LoopView final : public LoopSubmaps {
   public:
    explicit LoopView(SdpSlamImpl& owner) : owner_(owner) {}
    bool node_index(std::uint32_t level, std::uint32_t* index) const override { return owner_.graph_index(level, index); }
    std::uint32_t node_count() const override { return owner_.store_.permanent_count() + owner_.graph_.live_level_count(); }
    std::uint32_t first_held_level() const override { return owner_.first_held_level(); }
    std::uint32_t first_live_level() const override { return owner_.graph_.first_live_level(); }
    std::uint32_t level_end() const override { return owner_.graph_.level_end(); }
    bool placement(std::uint32_t level, Pose2* frame, double box[4], std::uint32_t* count) const override {
      return owner_.placement(level, frame, box, count);
    }
    void obstacles(std::uint32_t level, Point2* out) const override { owner_.obstacles(level, out); }
    void on_verified_loop() override { owner_.update_best(); }

   private:
    SdpSlamImpl& owner_;
  };

  SdpOptions options_{};
  DpSlamOptions bottom_options_{};
  DpSlamFilter* filter_ = nullptr;  // in the arena
  Icp2d* icp_ = nullptr;            // in the arena
  SegmentGraph graph_;
  Segmenter* segmenter_ = nullptr;
  Rng rng_;
  // The bottom level's writes of a scan (DpSlamFilter: all in the pool before prune
  // folds them) get room from older levels, as a new segment does (make_room()): a scan
  // that first sees an open hall asks several times what any scan before it did, which
  // no estimate from past scans foresees.
  class RoomForWrites final : public MapRoom {
   public:
    explicit RoomForWrites(SdpSlamImpl& owner) : owner_(owner) {}
    void make_room(std::uint64_t observations) override { owner_.make_room_now(observations); }

   private:
    SdpSlamImpl& owner_;
  };
  RingSink ring_sink_{*this};
  RoomForWrites room_for_writes_{*this};
  SdpPathSink* permanent_sink_ = nullptr;
  TopLevelListener* listener_ = nullptr;
  SdpStats stats_{};

  std::uint32_t n_bottom_ = 0U;
  SubmapStore store_;                  // live and permanent submaps
  SkeletonReader skeletons_;           // skeletons read from the DP map at anchorage
  TopParticles top_;                   // the T combinations (lines 9-12)
  CombinationEvaluator evaluator_;     // a combination's ICP error (line 11)
  CombinationResult evaluation_{};     // scratch of evaluate()
  std::uint32_t* chain_ = nullptr;     // max_levels
  Pose2* frames_ = nullptr;            // max_levels: the best particle's chain
  Pose2* eval_frames_ = nullptr;       // max_levels: the chain being evaluated
  Pose2* poses_scratch_ = nullptr;     // N
  PoseRing ring_;  // committed poses of the live levels and the current segment
  CellObservation* fine_values_ = nullptr;
  std::uint8_t* fine_known_ = nullptr;
  std::size_t fine_cells_ = 0U;
  Point2* obst_a_ = nullptr;        // loop_points (scratch)
  Point2* obst_b_ = nullptr;
  LoopClosure loop_closure_;
  LoopView loop_view_{*this};
  // Submaps of permanent levels waiting to be released, one per call of process()
  // (freeing a submap's observations walks their cell lists: spread over scans). Several
  // levels' may wait at once: a segmentation that makes two levels permanent leaves the
  // first one's releases queued instead of doing them in its own scan.
  NodeId* release_queue_ = nullptr;  // N × max_levels
  std::uint32_t release_count_ = 0U;
  std::uint32_t release_capacity_ = 0U;
  // The copy of a permanent level's submap into permanent_map_, one at a time, oldest
  // level first; the levels made permanent while one is copied wait in copy_queue_ (each
  // starts once the releases queued before it are done: pop mode, map_transfer.h).
  struct PendingCopy {
    NodeId node = kNoNode;
    Pose2 frame;
    std::uint32_t level = 0U;
    CellRect rect{};
  };
  MapTransfer transfer_;
  PendingCopy* copy_queue_ = nullptr;  // max_levels
  std::uint32_t copy_count_ = 0U;
  PermanentMap permanent_map_;

  // Current segment.
  bool started_ = false;
  Pose2 segment_start_pose_{};     // restart pose (current segment's initial pose)
  double window_radius_m_ = 0.0;   // a segment ends when its path leaves this disc (1/8 window)
  std::int64_t segment_start_stamp_us_ = 0;  // exclusive
  std::uint32_t segment_scans_ = 0U;  // processed scans in the current segment
  // DP map observations asked for by one processed scan: the most in this segment, and
  // in the previous one; the same over the scans after a segment's first (its restart).
  std::uint64_t scan_requests_ = 0U;
  std::uint64_t previous_scan_requests_ = 0U;
  std::uint64_t later_scan_requests_ = 0U;
  std::uint64_t previous_later_scan_requests_ = 0U;
  // DP map observations freed by releasing permanent levels' submaps (release_one,
  // transfer_rows), ever; and, when the current segment started, that count and the
  // observations in use and refused then (observations_needed()).
  std::uint64_t observations_released_ = 0U;
  std::uint64_t segment_observations_released_ = 0U;
  std::uint64_t segment_observations_used_ = 0U;
  std::uint64_t segment_observations_refused_ = 0U;
  std::int64_t last_processed_stamp_us_ = 0;
  double seg_box_[4] = {0.0, 0.0, 0.0, 0.0};  // best poses of the current segment
  // Top-level round.
  bool round_active_ = false;
  // The pending releases and map copy are make_room()'s: they give their room back over
  // the next scans (deferred_release_step()), outside do_work()'s budget.
  bool releases_deferred_ = false;
  std::uint32_t deferred_in_a_row_ = 0U;  // defer_top_work: processed scans without top-level work
  std::uint32_t eval_cursor_ = 0U;
  std::uint32_t rounds_in_segment_ = 0U;
  double round_sum_ = 0.0;
  double round_sq_ = 0.0;
  std::uint32_t round_samples_ = 0U;
  std::uint32_t best_top_ = 0U;
  Pose2 current_frame_{};
  std::size_t arena_used_ = 0U;
  unsigned char* state_begin_ = nullptr;  // the arena blocks init() carved
  unsigned char* state_end_ = nullptr;
  bool initialised_ = false;
  char why_[200] = {};
};

// ---- templates ----------------------------------------------------------------------

template <class F>
void SdpSlamImpl::for_each_level_pose(std::uint32_t level, NodeId leaf, F&& f) const {
  const SubmapLevel& lv = store_.level(level);
  ring_.for_each_between(lv.start_stamp_us, lv.end_stamp_us, f);
  filter_->tree().for_each_pose_from_root(leaf, f);
}

template <class F>
void SdpSlamImpl::for_each_current_pose(F&& f) const {
  ring_.for_each_between(segment_start_stamp_us_, INT64_MAX, f);
  filter_->for_each_best_pose(f);
}

template <class F>
void SdpSlamImpl::for_each_best_pose(F&& f) const {
  if (!initialised_) return;
  const std::uint32_t first = graph_.first_live_level();
  const std::uint32_t count = graph_.live_level_count();
  for (std::uint32_t i = 0; i < count; ++i) {
    const std::uint32_t level = first + i;
    const Pose2 frame = frames_[i];
    const Submap& sm = store_.submap(level, choice(best_top_, level));
    for_each_level_pose(level, sm.node, [&](std::int64_t s, const Pose2& p) { f(s, frame.compose(p)); });
  }
  const Pose2 cur = current_frame_;
  for_each_current_pose([&](std::int64_t s, const Pose2& p) { f(s, cur.compose(p)); });
}

template <class F>
void SdpSlamImpl::for_each_best_submap(F&& f) const {
  if (!initialised_ || !started_) return;
  // What the permanent map does not hold yet, at its level's frame now: the rest of the
  // copy in progress, and the submaps waiting for theirs.
  NodeId copying = kNoNode;
  CellRect rest{};
  std::uint32_t slot = 0U;
  if (transfer_.pending(&copying, &rest) && store_.find_permanent(transfer_.tag() - 1U, &slot)) {
    f(copying, store_.permanent(slot).frame_in_global, rest);
  }
  for (std::uint32_t k = 0; k < copy_count_; ++k) {
    const PendingCopy& c = copy_queue_[k];
    if (store_.find_permanent(c.level, &slot)) f(c.node, store_.permanent(slot).frame_in_global, c.rect);
  }
  const std::uint32_t first = graph_.first_live_level();
  const std::uint32_t count = graph_.live_level_count();
  for (std::uint32_t i = 0; i < count; ++i) {
    const Submap& sm = store_.submap(first + i, choice(best_top_, first + i));
    f(sm.node, frames_[i], sm.map_rect);
  }
  const double pad = bottom_options_.beam.max_update_range_m;
  f(filter_->best_node(), current_frame_,
    filter_->map().rect_around(seg_box_[0], seg_box_[1], seg_box_[2], seg_box_[3], pad));
}

template <class F>
void SdpSlamImpl::for_each_permanent_cell(F&& f) const {
  if (!initialised_) return;
  std::uint32_t last_tag = 0U;
  Pose2 correction;
  permanent_map_.for_each_cell([&](std::int32_t ix, std::int32_t iy, const PermanentMap::Cell& c) {
    if (c.tag != last_tag) {
      last_tag = c.tag;
      correction = Pose2{};
      std::uint32_t slot = 0U;
      if (store_.find_permanent(c.tag - 1U, &slot)) {  // a tag is its level + 1
        const PermanentSubmap& pm = store_.permanent(slot);
        correction = pm.frame_in_global.compose(pm.frame_in_map.inverse());
      }
    }
    // A coarsened cell (PermanentMap::compact) stands for the block of fine cells it
    // covers: each is drawn with its value.
    const std::uint32_t s = permanent_map_.scale_log2();
    const std::int64_t side = std::int64_t{1} << s;
    for (std::int64_t b = 0; b < side; ++b) {
      for (std::int64_t a = 0; a < side; ++a) {
        double x = 0.0;
        double y = 0.0;
        filter_->map().cell_center(static_cast<std::int32_t>(static_cast<std::int64_t>(ix) * side + a),
                                   static_cast<std::int32_t>(static_cast<std::int64_t>(iy) * side + b), &x, &y);
        double gx = 0.0;
        double gy = 0.0;
        correction.transform_point(x, y, gx, gy);
        f(gx, gy, c.value);
      }
    }
  });
}

template <class F>
void SdpSlamImpl::for_each_global_cell(F&& f) const {
  if (!initialised_) return;
  for_each_permanent_cell(f);
  const DpMap& map = filter_->map();
  for_each_best_submap([&](NodeId node, const Pose2& frame, const CellRect& r) {
    if (r.width == 0U || r.height == 0U) return;
    // Strips of whole rows that fit the work buffer (of columns too, for a rectangle
    // wider than the buffer), row-major as the rectangle reads.
    const std::uint32_t cols = r.width < fine_cells_ ? r.width : static_cast<std::uint32_t>(fine_cells_);
    const std::uint32_t rows_per_strip = static_cast<std::uint32_t>(fine_cells_ / cols);
    for (std::uint32_t y0 = 0; y0 < r.height; y0 += rows_per_strip) {
      for (std::uint32_t x0 = 0; x0 < r.width; x0 += cols) {
        CellRect strip = r;
        strip.ix0 = r.ix0 + static_cast<std::int32_t>(x0);
        strip.iy0 = r.iy0 + static_cast<std::int32_t>(y0);
        strip.width = r.width - x0 < cols ? r.width - x0 : cols;
        strip.height = r.height - y0 < rows_per_strip ? r.height - y0 : rows_per_strip;
        map.fill_rect(node, strip, fine_values_, fine_known_);
        for (std::uint32_t y = 0; y < strip.height; ++y) {
          for (std::uint32_t x = 0; x < strip.width; ++x) {
            const std::size_t i = static_cast<std::size_t>(y) * strip.width + x;
            if (fine_known_[i] == 0U) continue;
            double cx = 0.0;
            double cy = 0.0;
            map.cell_center(strip.ix0 + static_cast<std::int32_t>(x), strip.iy0 + static_cast<std::int32_t>(y), &cx, &cy);
            double gx = 0.0;
            double gy = 0.0;
            frame.transform_point(cx, cy, gx, gy);
            f(gx, gy, fine_values_[i]);
          }
        }
      }
    }
  });
}

}  // namespace sdpslam
