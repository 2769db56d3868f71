#pragma once
// One localization session on a saved map (mode localize) as both programs run it:
// `sdpslam localize` (run_localize.h) and sdpslamd in mode localize. It holds the map
// read from its map.yaml, the one arena sized for it (MonteCarloLocalizer::
// required_arena_bytes) and the localizer initialised in it and started, and the pose
// given at each scan fed (localization does not revise the past). Memory as
// SdpSession's (sdp_session.h): with room reserved feed() allocates nothing, later scans
// being counted instead of recorded.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "sdpslam/core/arena.h"
#include "sdpslam/core/localization/monte_carlo_localizer.h"
#include "sdpslam/io/trajectory_io.h"
#include "sdpslam/slam/run_localize.h"

namespace sdpslam::slam {

class LocalizeSession {
 public:
  LocalizeSession() = default;
  LocalizeSession(const LocalizeSession&) = delete;
  LocalizeSession& operator=(const LocalizeSession&) = delete;

  // Reads the map, sizes the arena for it and initialises the localizer, started around
  // *start (spread sigma_xy_m, sigma_theta_rad) or globally when start is null. False
  // with *error ("map.yaml[:line]: why") otherwise.
  bool create(const LocalizerOptions& options, const std::string& map_yaml, std::uint64_t seed, const Pose2* start,
              double sigma_xy_m, double sigma_theta_rad, std::string* error);
  void reserve_records(std::size_t max_scans);

  // One scan and its odometry: the localizer's update, the pose recorded.
  MonteCarloLocalizer::Step feed(const OdometrySample& odom, const RangeScan& scan);

  const std::vector<io::StampedPose>& trajectory() const { return poses_; }
  // The scan (0-based, of those fed) at which the particles first gathered within
  // kConvergedSpreadM; -1 while they have not.
  std::int64_t converged_at() const { return converged_at_; }
  const MonteCarloLocalizer& localizer() const { return *mcl_; }
  const LocalizationMap& map() const { return *map_; }
  std::size_t arena_bytes() const { return arena_bytes_; }
  std::size_t arena_used_bytes() const { return arena_->used_bytes(); }
  std::uint64_t unrecorded() const { return unrecorded_; }

 private:
  std::unique_ptr<LocalizationMap> map_;
  std::size_t arena_bytes_ = 0U;
  std::unique_ptr<unsigned char[]> buffer_;
  std::unique_ptr<Arena> arena_;
  std::unique_ptr<MonteCarloLocalizer> mcl_;
  std::vector<io::StampedPose> poses_;
  bool bounded_ = false;
  std::int64_t converged_at_ = -1;
  std::uint64_t unrecorded_ = 0U;
};

}  // namespace sdpslam::slam
