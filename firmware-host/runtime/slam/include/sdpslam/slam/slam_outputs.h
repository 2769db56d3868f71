#pragma once
// Outputs of a DP-SLAM run, shared by the offline runner (`sdpslam run`) and the onboard
// program (sdpslamd), so both write the same trajectory and map from the same filter
// state:
//  - assemble_trajectory: one pose per laser scan. Processed scans take the best
//    particle's path (committed poses + its uncommitted ones); the others (skipped for
//    lack of motion, or gaps left by path exhaustion) take the last anchored pose
//    composed with the odometry since.
//  - best_map_image: the best particle's occupancy grid over every tile ever written.
//  - write_trajectory_and_map: trajectory.txt, map.pgm/.yaml and map.png (with the
//    trajectory drawn) in out_dir, each atomically (firmware-host/runtime/io).
// and of an SDP-SLAM run (core/sdp_slam.h; `sdpslam run --mode sdp`, sdpslamd
// [slam] mode = sdp), so both write the best combination's path and global map:
//  - sdp_best_path: the best combination's poses, the input of assemble_trajectory;
//  - sdp_global_map_image: the best combination's global map;
//  - sdp_state_json: the deterministic counters, pools and memory of stats.json.
#include <cstdint>
#include <string>
#include <vector>

#include "sdpslam/core/bottom/dpslam_filter.h"
#include "sdpslam/core/sdp_slam.h"
#include "sdpslam/io/figures.h"
#include "sdpslam/io/json_text.h"
#include "sdpslam/io/map_image.h"
#include "sdpslam/io/snapshot_file.h"
#include "sdpslam/io/trajectory_io.h"

namespace sdpslam::slam {

// One laser scan as the filter saw it.
struct ScanRecord {
  std::int64_t stamp_us = 0;
  Pose2 odom;            // odometry pose given with the scan
  Pose2 online;          // StepResult::pose at that step
  bool processed = false;
};

// `best_path`: the filter's committed poses followed by the best particle's uncommitted
// ones, oldest first (stamps increasing). `path_gaps` (may be null) receives the number of
// processed scans whose pose was missing from the path.
std::vector<io::StampedPose> assemble_trajectory(const std::vector<ScanRecord>& scans,
                                                 const std::vector<io::StampedPose>& best_path,
                                                 std::uint64_t* path_gaps);

// The trajectory smoothed with the odometry. A processed scan's pose carries the scan
// match's own error and the proposal's sample noise (core/dpslam_options.h): centimetres
// and tenths of a degree that change from one processed scan to the next, more than
// the odometry errs between scans a metre apart. So each pose p_i becomes the mean of
// the poses its neighbours give it through the odometry between them,
// p_j ⊕ (o_j⁻¹ ⊕ o_i), weighted by a Gaussian of the travel between them along the
// trajectory (σ = kSmoothSigmaM; a radian of turn counts kSmoothTurnM; neighbours
// within 2σ). A neighbour whose odometry puts p_i more than kSmoothGateM from where the
// trajectory has it is left out: a wheel slip, or a log without odometry, is not
// averaged in. What the map fixes over longer stretches, loops included, stays as it
// was. `trajectory` must be assemble_trajectory()'s for `scans` (a pose per scan, in
// order); anything else is returned unchanged. Deterministic (det:: math, fixed order).
inline constexpr double kSmoothSigmaM = 0.5;
inline constexpr double kSmoothTurnM = 0.3;
inline constexpr double kSmoothGateM = 0.2;
std::vector<io::StampedPose> smooth_with_odometry(const std::vector<ScanRecord>& scans,
                                                  const std::vector<io::StampedPose>& trajectory);

// The best particle's map. Returns the number of known cells; `image` stays empty
// (width 0) when nothing was ever written.
std::uint32_t best_map_image(const DpSlamFilter& filter, io::OccupancyImage* image);

// Writes the trajectory twice: out_dir/trajectory.txt ("t x y theta") and
// out_dir/trajectory.tum (TUM RGB-D: "t x y z qx qy qz qw", z = 0, a rotation about z),
// which evo and the TUM tools read. False (with `error`) at the first write that failed.
bool write_trajectories(const std::string& out_dir, const std::vector<io::StampedPose>& trajectory,
                        std::string* error);

// The map's cells hold the share of the beams that reached them and ended there (hits /
// (hits + misses), DP-SLAM's count model, the same as GMapping's). A wall cell that the
// robot mostly sees at a grazing angle is crossed by many beams in front of the wall
// surface and ends a quarter or a third of them, far below map_server's default
// occupied_thresh of 0.65, at which corridor walls would read as unknown or free. So the
// YAML says what GMapping's map output says for the same model: occupied above 0.25
// (its occ_thresh); free_thresh stays 0.196.
inline constexpr double kSlamOccupiedThreshold = 0.25;
io::MapWriteOptions slam_map_thresholds();

// Writes the trajectories (write_trajectories) and, when the image is not empty,
// out_dir/map.pgm, map.yaml (slam_map_thresholds()) and map.png. False (with `error`) at
// the first write that failed; the files already written and the previous versions of the
// others stay complete. map.png is drawn by `painter` (figures.h; null: the plain one).
bool write_trajectory_and_map(const std::string& out_dir, const std::vector<io::StampedPose>& trajectory,
                              const io::OccupancyImage& image, std::string* error,
                              const io::Painter* painter = nullptr);

// ---- SDP-SLAM ------------------------------------------------------------------------

// The path of SDP-SLAM's permanent segments (SdpSlam::set_permanent_sink): each pose
// in its level's frame, and each level's latest frame in the global frame (loop closure
// moves them). With a capacity (reserve()), poses beyond it are counted in `dropped`
// instead of stored, so the onboard program's memory stays bounded.
class SdpPermanentPath final : public SdpPathSink {
 public:
  struct LocalPose {
    std::uint32_t level;
    std::int64_t stamp_us;
    Pose2 local;
  };
  void reserve(std::size_t poses, std::size_t levels) {
    poses_.reserve(poses);
    frames_.reserve(levels);
    bounded_ = true;
  }
  void on_pose(std::uint32_t level, std::int64_t stamp_us, const Pose2& local) override;
  void on_frame(std::uint32_t level, const Pose2& frame_in_global) override;
  // The poses in the global frame, oldest first.
  std::vector<io::StampedPose> global_poses() const;
  std::uint64_t dropped() const { return dropped_; }
  // Its contents in a snapshot (io/snapshot_file.h), and back; read_state() is false
  // iff the snapshot does not hold them whole.
  void write_state(io::SnapshotOut& out) const;
  bool read_state(io::SnapshotIn& in);

 private:
  std::vector<LocalPose> poses_;
  std::vector<Pose2> frames_;  // by level
  bool bounded_ = false;
  std::uint64_t dropped_ = 0U;
};

// The best combination's path, oldest first: the permanent segments (in their latest
// frames) followed by the live levels' chosen submaps and the current segment's best
// particle (SdpSlam::for_each_best_pose).
std::vector<io::StampedPose> sdp_best_path(const SdpSlam& slam, const SdpPermanentPath& permanent);

// loops.tsv: the loop constraints SDP-SLAM holds at the end of a run, one per line (in
// the store's order), with the origin of both levels (SdpSlam::level_origin), so that a
// ground truth can say which constraints were right (`sdpslam evaluate --loops`):
//   older newer source used error_m z_x z_y z_theta
//     older_stamp older_x older_y older_theta newer_stamp newer_x newer_y newer_theta
// source: search (the wide loop search) or icp (the top level's ICP); used: 1 when both
// levels are in the pose graph. Stamps in seconds (six decimals), poses in m and rad; a
// level whose origin is no longer held has stamp "-" and zero pose.
std::string sdp_loops_tsv(const SdpSlam& slam);

// segments.tsv: the segments of the path, one per line, oldest first: the level each
// became (the current one: the level it will become) and the stamp it started at
// (SdpSlam::level_origin, SdpSlam::current_segment):
//   level start_stamp
// A level holds the scans after its start stamp up to the next line's start stamp,
// included, so that `sdpslam evaluate --segments` can tell the relations within one
// submap from those across two (eval/frame_fit.h). Levels no longer held (forgotten
// permanent levels) are left out: their scans count with the line before. Stamps in
// seconds (six decimals). Empty of lines before the first processed scan.
std::string sdp_segments_tsv(const SdpSlam& slam);

// The best combination's global map (paper Fig. 3 (j)-(l)), rendered through the core's
// API (SdpSlam::global_map_grid, for_each_global_cell): the permanent map (each cell
// moved with its level's frame as loop closure corrected it) plus each chosen submap's
// DP-map view moved into the global frame (nearest cell), hits and misses summed per
// cell; aligned to the DP map's grid, at its resolution or, once the permanent map was
// coarsened, at the permanent map's cell size. Returns the known cells; `image` stays
// empty (width 0) when nothing was ever written. Allocates the image: an output step,
// not a per-scan one.
std::uint32_t sdp_global_map_image(const SdpSlam& slam, io::OccupancyImage* image);

// The bottom filter's members of a stats.json "pools" object (ancestry nodes, path
// entries, observations, tiles: capacity, peak, exhausted), in that order; the caller adds
// its own after them. Shared by the DP-SLAM and SDP-SLAM stats.
io::Json filter_pools_json(const DpSlamFilter& filter);

// How the bottom filter's particles were drawn with the improved proposal (a stats.json
// "proposal" object): around a scan match, or by the odometry model when the match could
// not be made (too few return beams, a map too empty, a score too low), and the matcher's
// observation-model calls. All zero with the odometry proposal. Shared by the DP-SLAM and
// SDP-SLAM stats.
io::Json proposal_json(const DpSlamStats& stats);

// The deterministic part of an SDP-SLAM stats.json: the members "segments" through
// "memory", in order, for the caller to append to its object (sdpslamd's status.json
// "engine" takes the same). `arena_bytes` / `arena_used_bytes`: the arena given to init()
// and its used bytes; `path_gaps`: from assemble_trajectory; `known_cells`: from
// sdp_global_map_image.
io::Json sdp_state_json(const SdpSlam& slam, std::size_t arena_bytes, std::size_t arena_used_bytes,
                        std::uint64_t path_gaps, std::uint32_t known_cells);

}  // namespace sdpslam::slam
