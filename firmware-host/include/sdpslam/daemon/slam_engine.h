#pragma once
// The SLAM algorithm behind sdpslamd, as a small seam so that the modes of [slam] mode
// plug in alike: `dpslam` (the bottom-level DP-SLAM filter, core/bottom/dpslam_filter.h),
// `sdp` (Segmented DP-SLAM, core/sdp_slam.h, with the [sdp] options) and `localize`
// (Monte Carlo localization on a saved map, core/localization, with [localize]).
//
// Each mode runs the session of the offline runner (runtime/slam dpslam_session.h,
// sdp_session.h, localize_session.h: the arena, the engine, what is fed and recorded)
// and writes what it writes from the same state, through the same code
// (slam_outputs.h): dpslam the best particle's path and map, sdp the best combination's
// path (permanent segments + live chain) and global map, localize the path on its map.
//
// An engine owns all of its memory, sized once at create time from the options; process()
// does not allocate except to append to the scan record and the committed-pose record,
// whose capacities are reserved at create time too (max_trajectory_scans; beyond it scans
// are still processed but no longer recorded, counted in unrecorded_scans() and
// "committed_poses_dropped"). trajectory() and map_image() allocate: output steps only.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "sdpslam/core/range_scan.h"
#include "sdpslam/daemon/daemon_config.h"
#include "sdpslam/io/json_text.h"
#include "sdpslam/io/map_image.h"
#include "sdpslam/io/trajectory_io.h"

namespace sdpslam::daemon {

// The spread of the particles behind an estimate, map frame: the sample covariance of
// their positions (m²) and the variance of their headings about their circular mean
// (rad²). It measures the filter's own dispersion (dpslam and sdp: the bottom-level
// particles, whose segment frame is turned into the map frame; localize: the
// localizer's), not the top level's choice among submaps.
struct PoseSpread {
  double var_x = 0.0;
  double cov_xy = 0.0;
  double var_y = 0.0;
  double var_heading = 0.0;
};

struct EngineStep {
  bool processed = false;  // false: skipped by the filter (too little motion)
  Pose2 pose;              // best estimate at the scan, map frame
  bool placed = true;      // false: held back, no estimate (sdp, after a resume: the robot
                           // is being looked for in the saved map; pose is meaningless)
};

class SlamEngine {
 public:
  virtual ~SlamEngine() = default;
  virtual const char* name() const = 0;
  virtual EngineStep process(const OdometrySample& odom, const RangeScan& scan) = 0;
  // One pose per recorded scan, from the current best estimate of the whole path.
  virtual std::vector<io::StampedPose> trajectory() const = 0;
  // The current best map; returns its known cells (image width 0 when empty).
  virtual std::uint32_t map_image(io::OccupancyImage* image) const = 0;
  // The spread behind the last process()'s estimate (computed on demand: O(particles)).
  virtual PoseSpread spread() const { return PoseSpread{}; }
  // Engine counters: the members of status.json's "engine" object.
  virtual io::Json status_json() const = 0;
  virtual std::uint64_t unrecorded_scans() const = 0;
  // The input has ended: complete deferred work so that the final outputs are those of
  // the offline runner at the end of its log (sdp: SdpSlam::finish(), the pending
  // skeletons and global-map transfer; not bounded by the per-scan budget). Call once,
  // before the last trajectory()/map_image(); the periodic outputs never call it, so
  // they do not change what later scans do.
  virtual void finish() {}
  // A line for the journal once, when something happened that a person should know
  // (sdp: where a resumed session found the robot); empty otherwise.
  virtual std::string take_notice() { return std::string(); }

  // ---- snapshots (io/snapshot_file.h) -----------------------------------------------
  // The engine's whole state (the SLAM state and its records of the scans), so that a
  // restarted daemon continues the same map and trajectory. Only sdp mode has them;
  // the others return false with *error saying so. `fingerprint` names the options
  // (DaemonConfig::slam_fingerprint): a snapshot of other options, another version or a
  // damaged one is refused by resume_snapshot() (false, *error says why), after which
  // the engine may be unusable: make a new one.
  virtual bool has_snapshots() const { return false; }
  virtual bool save_snapshot(const std::string& path, std::uint64_t fingerprint, std::uint64_t* file_bytes,
                             std::string* error) {
    (void)path, (void)fingerprint, (void)file_bytes;
    *error = std::string("mode ") + name() + " has no snapshots";
    return false;
  }
  // On success *scans is the number of scans the snapshot's session had recorded.
  virtual bool resume_snapshot(const std::string& path, std::uint64_t fingerprint, std::uint64_t* scans,
                               std::string* error) {
    (void)path, (void)fingerprint, (void)scans;
    *error = std::string("mode ") + name() + " has no snapshots";
    return false;
  }
};

// Bytes of the one arena the configured engine carves its state from at create time
// (DpSlamFilter / SdpSlam / MonteCarloLocalizer::required_arena_bytes; localize reads the
// map to size it); 0 iff the options are invalid or the map cannot be read. The
// scan record (max_trajectory_scans × ~64 B) comes on top.
std::size_t engine_arena_bytes(const DaemonConfig& config);

// Builds the engine the configuration asks for. Null (with *error) iff the mode is not
// available in this build or its memory cannot be set up.
std::unique_ptr<SlamEngine> make_engine(const DaemonConfig& config, std::string* error);

}  // namespace sdpslam::daemon
