#pragma once
// One DP-SLAM session (the bottom-level filter alone, mode dpslam) as both programs run
// it: `sdpslam run --mode dpslam` (run_offline.h) and sdpslamd in mode dpslam. It holds
// the one arena sized from the options (DpSlamFilter::required_arena_bytes) and the
// filter initialised in it, the poses the filter commits, and one record per scan fed;
// its outputs are built by slam_outputs.h. Memory as SdpSession's (sdp_session.h): with
// room reserved (reserve_records) feed() allocates nothing, later scans and committed
// poses beyond the room being counted instead of kept.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "sdpslam/core/arena.h"
#include "sdpslam/core/bottom/dpslam_filter.h"
#include "sdpslam/io/map_image.h"
#include "sdpslam/io/trajectory_io.h"
#include "sdpslam/slam/slam_outputs.h"

namespace sdpslam::slam {

class DpSlamSession final : private PoseSink {
 public:
  DpSlamSession() = default;
  DpSlamSession(const DpSlamSession&) = delete;
  DpSlamSession& operator=(const DpSlamSession&) = delete;

  // Sizes the arena and initialises the filter: false with *error ("invalid SLAM
  // options: reason", or why init failed) otherwise.
  bool create(const DpSlamOptions& options, std::uint64_t seed, std::string* error);
  // Room for this many scan records and committed poses, reserved now.
  void reserve_records(std::size_t max_scans);

  // One scan and its odometry: processed and recorded.
  StepResult feed(const OdometrySample& odom, const RangeScan& scan);

  // The best particle's path, one pose per recorded scan (*gaps may be null), and map.
  std::vector<io::StampedPose> trajectory(std::uint64_t* gaps) const;
  std::uint32_t map_image(io::OccupancyImage* image) const { return best_map_image(*filter_, image); }

  const DpSlamFilter& filter() const { return *filter_; }
  std::size_t arena_bytes() const { return arena_bytes_; }
  const std::vector<ScanRecord>& records() const { return scans_; }
  std::uint64_t unrecorded() const { return unrecorded_; }
  std::uint64_t committed_dropped() const { return committed_dropped_; }

 private:
  void on_committed(std::int64_t stamp_us, const Pose2& pose) override;

  std::size_t arena_bytes_ = 0U;
  std::unique_ptr<unsigned char[]> buffer_;
  std::unique_ptr<Arena> arena_;
  std::unique_ptr<DpSlamFilter> filter_;
  std::vector<io::StampedPose> committed_;
  std::vector<ScanRecord> scans_;
  bool bounded_ = false;
  std::uint64_t unrecorded_ = 0U;
  std::uint64_t committed_dropped_ = 0U;
};

}  // namespace sdpslam::slam
