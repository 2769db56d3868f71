#pragma once
// Loop closure of SDP-SLAM (beyond the paper; SdpOptions::loop_closure): the loop
// constraints between levels' frames, the pose graph that adjusts the best
// combination's frames to them, and the wide loop search. SdpSlam (sdp_slam.h) owns the
// submaps and drives this part through its API; the part sees the submaps only through
// LoopSubmaps.
//
// Constraints. The top level's skeleton ICP of two non-adjacent submaps is refined on
// their obstacle points (wall cells that border free space, kept per submap at
// anchorage) by refine(); a refined match with a small residual and a bounded correction
// is kept as a constraint between the two LEVELS' frames (all submaps of a level share
// its frame: the bottom particles restarted at one pose), one per pair of levels (the
// lowest residual wins, except that the wide search's verified peak is never displaced
// by an ICP match farther than a coarse search block from it, and displaces such a
// match itself; a full store makes room with a record whose levels are gone, else with
// its worst record). A constraint is only as certain as its match in each
// direction: the refined pairing's wall normals (Icp2d::direction_information) give it
// little information along a corridor it could slide in (FrameInfo::from_directions).
//
// Adjustment. The owner adds the graph's nodes (begin_adjustment(): the permanent
// submaps still held, then the chosen live submaps, with the chain transforms T of Fig. 3
// (l) between consecutive ones); finish_adjustment() adds every constraint whose two
// levels are held and solves (frame_graph.h). The top level's ICP constraints keep a
// robust kernel (Dynamic Covariance Scaling); the search's were verified before they were recorded and go without
// one (a kernel would keep a true loop of metres only partly closed).
//
// Wide loop search (loop_search_window_m > 0): ICP only sees loops the chain already
// closed to within decimetres, so once per level, newest level first (search_step()),
// the chosen submap is also searched against up to loop_search_candidates older,
// non-adjacent submaps whose boxes (grown by the pair's window) overlap its own (the
// largest overlaps; the others are counted), exhaustively over ±loop_search_window_m and
// ±loop_search_window_rad (correlative_matcher.h; the window grows to the chain's drift
// bound between the two levels, up to loop_search_max_window_m), in slices of
// loop_search_reads_per_scan grid reads per search_step(). An unambiguous peak scoring
// loop_search_min_score that obstacle ICP confirms becomes a constraint unless it would
// move the newer submap farther than the chain can have drifted
// (loop_search_drift_m × √hops). A peak that moves it by more than half the window was
// proved unique only on the side the window covered: the pair is searched again with
// the window centred on the peak, and the peak is kept only if it is still the unique
// best there (search_verdict()). A recorded search constraint asks the owner to adjust at once
// (LoopSubmaps::on_verified_loop), so the next pair is judged against the corrected
// frames.
//
// Memory: init() carves everything from the caller's Arena (required_bytes()); nothing
// touches the heap afterwards. Deterministic: fixed order, no clocks.
#include <cstddef>
#include <cstdint>

#include "sdpslam/core/arena.h"
#include "sdpslam/core/loops/correlative_matcher.h"
#include "loops/frame_graph.h"
#include "sdpslam/core/top/icp2d.h"
#include "sdpslam/core/pose2.h"
#include "sdpslam/core/sdp_options.h"
#include "sdpslam/core/sdp_stats.h"  // LoopClosureStats
#include "sdpslam/core/state_io.h"

namespace sdpslam {

// The submaps loop closure works on: for each level the graph holds, the submap of the
// best combination. Provided by the owner (SdpSlam).
class LoopSubmaps {
 public:
  // Levels with a frame in the graph: node_index() of each, 0 .. node_count() - 1, in
  // level order; the oldest held level; the live levels [first_live_level(), level_end()).
  virtual bool node_index(std::uint32_t level, std::uint32_t* index) const = 0;
  virtual std::uint32_t node_count() const = 0;
  virtual std::uint32_t first_held_level() const = 0;
  virtual std::uint32_t first_live_level() const = 0;
  virtual std::uint32_t level_end() const = 0;
  // The chosen submap of a held level whose obstacle points exist: its frame in the
  // global frame, its box (submap frame: x0, y0, x1, y1) and its obstacle point count;
  // false otherwise.
  virtual bool placement(std::uint32_t level, Pose2* frame, double box[4], std::uint32_t* obstacle_count) const = 0;
  // Its obstacle points, in metres in the submap frame (placement()'s count of them).
  virtual void obstacles(std::uint32_t level, Point2* out) const = 0;
  // A verified constraint was recorded: the frames should follow it now.
  virtual void on_verified_loop() = 0;

 protected:
  ~LoopSubmaps() = default;
};

// The search grid: its cell (the obstacle points lie on coarse cells) and its side
// (cells; the largest submap patch plus the kernel's reach).
struct LoopSearchGeometry {
  double resolution_m = 0.1;
  std::uint32_t grid_side = 0U;
};

class LoopClosure {
 public:
  // A loop constraint: the pose of the newer level's frame in the older one's, as ICP on
  // obstacle points found it, with the residual it left.
  struct Record {
    std::uint32_t older_level = 0U;
    std::uint32_t newer_level = 0U;
    Pose2 z;
    FrameInfo info;  // in the frame of z's error (frame_graph.h)
    double error_m = 0.0;
    bool searched = false;  // found by the wide loop search (else by the top level's ICP)
  };

  LoopClosure() = default;
  LoopClosure(const LoopClosure&) = delete;
  LoopClosure& operator=(const LoopClosure&) = delete;

  // Arena bytes init() needs for these options, a graph of up to max_nodes frames and
  // this search grid (0 iff loop closure is off).
  static std::size_t required_bytes(const SdpOptions& s, std::uint32_t max_nodes, const LoopSearchGeometry& geometry);
  // `icp` and `submaps` must outlive this object; counts go to *stats. False iff the
  // arena is too small.
  bool init(const SdpOptions& s, std::uint32_t max_nodes, const LoopSearchGeometry& geometry, Icp2d* icp,
            LoopSubmaps* submaps, LoopClosureStats* stats, Arena& arena);

  // The top level's skeleton match of an older and a newer submap (`skeleton`: the
  // newer frame in the older, from initial guess `guess`), refined on their obstacle
  // points (metres, submap frames); recorded when it passes loop_max_error_m,
  // loop_min_pairs and loop_max_correction_m.
  void refine(std::uint32_t older_level, const Point2* older, std::uint32_t older_count, std::uint32_t newer_level,
              const Point2* newer, std::uint32_t newer_count, const Pose2& guess, const Pose2& skeleton);

  // Pose graph: begin_adjustment() clears the graph for the owner's nodes (node k =
  // LoopSubmaps::node_index k); finish_adjustment() adds the constraints between held
  // levels and solves. False when there was nothing to solve: the frames stand as added.
  FrameGraph& begin_adjustment();
  bool finish_adjustment();

  // Wide search: one slice of work (once per processed scan, when the owner has no
  // other work pending).
  void search_step();

  std::uint32_t record_count() const { return count_; }
  const Record& record(std::uint32_t k) const { return records_[k]; }

  // The mutable state, for snapshots (core/state_io.h): what init() did not fix.
  void transfer_state(StateIo& io);

 private:
  bool record_dead(const Record& r) const;
  void record(const Record& r);
  Icp2dOptions icp_options() const;
  // The information of constraint z (source = newer submap's obstacle points, target =
  // older's) from the direction information of that pairing (loop_normal_radius_m).
  FrameInfo information(const Point2* target, std::uint32_t target_count, const Point2* source,
                        std::uint32_t source_count, const Pose2& z);
  // The record of a refined match (ICP result f of the newer submap's points on the older's).
  Record matched(std::uint32_t older_level, const Point2* older, std::uint32_t older_count, std::uint32_t newer_level,
                 const Point2* newer, std::uint32_t newer_count, const Icp2dResult& f, bool searched);
  void search_collect(std::uint32_t newer_level);
  void search_pair(std::uint32_t older_level, std::uint32_t newer_level);
  void search_continue();
  void search_accept(const Record& r);
  void keep_verified(const Record& r);
  CorrelativeOptions search_options(std::uint32_t older_level, std::uint32_t newer_level) const;
  void search_verdict(const Record& r);
  void recentre_verdict(const CorrelativeResult& c);
  bool centre_shift(const Record& r, double* dx_m, double* dy_m) const;
  bool moves_too_far(const Record& r) const;
  double drift_bound_m(std::uint32_t older_level, std::uint32_t newer_level) const;
  double search_window_m(std::uint32_t older_level, std::uint32_t newer_level) const;
  std::uint32_t level_hops(std::uint32_t older_level, std::uint32_t newer_level) const;

  SdpOptions options_{};
  LoopSearchGeometry geometry_{};
  Icp2d* icp_ = nullptr;
  LoopSubmaps* submaps_ = nullptr;
  LoopClosureStats* stats_ = nullptr;
  Record* records_ = nullptr;  // max_loop_constraints
  std::uint32_t count_ = 0U;
  FrameGraph graph_;
  CorrelativeMatcher matcher_;
  std::uint32_t search_level_ = 0U;     // next level whose submap is searched for loops
  std::uint32_t search_newer_ = 0U;     // level being searched
  std::uint32_t search_older_[SdpOptions::kMaxLoopSearchCandidates] = {};
  std::uint32_t search_count_ = 0U;
  std::uint32_t search_cursor_ = 0U;
  Point2* search_a_ = nullptr;  // loop_points: the pair being searched (older, newer)
  Point2* search_b_ = nullptr;
  std::uint32_t search_a_count_ = 0U;
  std::uint32_t search_b_count_ = 0U;
  std::uint32_t search_pair_older_ = 0U;
  std::uint32_t search_pair_newer_ = 0U;
  std::uint32_t* hops_ = nullptr;  // max_nodes (level_hops() scratch)
  bool recentring_ = false;  // the search in progress is centred on recentred_'s peak
  Record recentred_{};
  std::uint32_t max_nodes_ = 0U;
};

}  // namespace sdpslam
