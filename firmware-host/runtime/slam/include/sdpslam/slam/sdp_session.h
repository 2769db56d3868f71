#pragma once
// One SDP-SLAM session as both programs run it: `sdpslam run` (run_sdp.h, a log) and
// sdpslamd in mode sdp (firmware-host slam_engine.h, the robot's drivers). It holds the
// one arena sized from the options (SdpSlam::required_arena_bytes: the whole SLAM state,
// the fixed memory budget) and the engine initialised in it, the path of the segments
// made permanent, one record per scan fed, optionally the top level's ICP error rounds,
// and the continuation of a saved session (session_continuation.h). Its outputs are
// built by slam_outputs.h; each program adds its own files and its own snapshot fields.
//
// Memory: create() allocates everything but the records; with record room reserved
// (reserve_records) feed() allocates nothing, scans beyond that room being processed
// but not recorded (counted). Rounds are collected only when asked (they grow with the
// run: the offline runner's icp_error.csv).
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "sdpslam/core/arena.h"
#include "sdpslam/core/sdp_slam.h"
#include "sdpslam/io/map_image.h"
#include "sdpslam/io/trajectory_io.h"
#include "sdpslam/slam/session_continuation.h"
#include "sdpslam/slam/slam_outputs.h"

namespace sdpslam::slam {

// One evaluation round of the top level that matched something (TopLevelListener).
struct IcpRound {
  std::int64_t stamp_us;
  double mean_m;
  double std_m;
  std::uint32_t samples;
};

class SdpSession final : private TopLevelListener {
 public:
  // A continued session (session_continuation.h): the window searched for the robot
  // and whether it most likely stayed where it was left (sdpslamd restarted).
  explicit SdpSession(double continuation_window_m = SessionContinuation::kDefaultWindowM,
                      bool stayed_likely = false);
  SdpSession(const SdpSession&) = delete;
  SdpSession& operator=(const SdpSession&) = delete;

  // Sizes the arena and initialises the engine: false with *error ("invalid SLAM
  // options: section.key: reason", or why init failed) otherwise. With collect_rounds
  // every round is kept (rounds()).
  bool create(const DpSlamOptions& bottom, const SdpOptions& sdp, std::uint64_t seed, bool collect_rounds,
              std::string* error);
  // Room for this many scan records, reserved now (and for the permanent path they
  // make); later scans are processed, not recorded (unrecorded()). Without it records
  // grow as scans come.
  void reserve_records(std::size_t max_scans);

  // One scan and its odometry. While a continued session looks for the robot the scan
  // is held back: false, nothing processed. Otherwise processed (*step), recorded, true.
  bool feed(const OdometrySample& odom, const RangeScan& scan, SdpStepResult* step);

  // The best combination's path, one pose per recorded scan (assemble_trajectory;
  // *gaps: scans filled from odometry), and its global map (known cells returned).
  std::vector<io::StampedPose> trajectory(std::uint64_t* gaps) const;
  std::uint32_t map_image(io::OccupancyImage* image) const;
  // Completes deferred work (SdpSlam::finish) before the final outputs.
  void finish() { slam_->finish(); }
  // The counters of stats.json / status.json shared by both programs (sdp_state_json).
  io::Json state_json(std::uint64_t path_gaps, std::uint32_t known_cells) const;

  SdpSlam& slam() { return *slam_; }
  const SdpSlam& slam() const { return *slam_; }
  std::size_t arena_bytes() const { return arena_bytes_; }
  // Records, the permanent path and the rounds: what a snapshot keeps besides the engine.
  std::vector<ScanRecord>& records() { return scans_; }
  const std::vector<ScanRecord>& records() const { return scans_; }
  SdpPermanentPath& permanent() { return permanent_; }
  const SdpPermanentPath& permanent() const { return permanent_; }
  std::vector<IcpRound>& rounds() { return rounds_; }
  const std::vector<IcpRound>& rounds() const { return rounds_; }
  std::uint64_t unrecorded() const { return unrecorded_; }
  void set_unrecorded(std::uint64_t n) { unrecorded_ = n; }
  SessionContinuation& continuation() { return continuation_; }
  const SessionContinuation& continuation() const { return continuation_; }
  // The last scan fed: its odometry (after the continuation's carry: the session's
  // frame) and the estimate (global frame).
  const Pose2& last_odom() const { return last_odom_; }
  void set_last_odom(const Pose2& odom) { last_odom_ = odom; }
  const Pose2& last_pose() const { return last_pose_; }

 private:
  void on_round(std::int64_t stamp_us, double mean_m, double std_m, std::uint32_t samples) override {
    rounds_.push_back(IcpRound{stamp_us, mean_m, std_m, samples});
  }

  std::size_t arena_bytes_ = 0U;
  std::unique_ptr<unsigned char[]> buffer_;
  std::unique_ptr<Arena> arena_;
  std::unique_ptr<SdpSlam> slam_;
  SdpPermanentPath permanent_;
  std::vector<ScanRecord> scans_;
  bool bounded_ = false;  // reserve_records(): records stop at the room reserved
  std::uint64_t unrecorded_ = 0U;
  std::vector<IcpRound> rounds_;
  SessionContinuation continuation_;
  std::unique_ptr<RangeScan> carried_ = std::make_unique<RangeScan>();  // the scan as fed
  Pose2 last_odom_{};
  Pose2 last_pose_{};
};

}  // namespace sdpslam::slam
