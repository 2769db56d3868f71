#pragma once
// The SLAM algorithm behind sdpslamd, as a small seam so that the modes of [slam] mode
// plug in alike: `dpslam` (the bottom-level DP-SLAM filter, core/dpslam_filter.h) and
// `sdp` (the SDP-SLAM top level, once the core provides it).
//
// An engine owns all of its memory, sized once at create time from the options; process()
// does not allocate except to append to the scan record, whose capacity is reserved at
// create time too (max_trajectory_scans; beyond it scans are still processed but no
// longer recorded, counted in unrecorded_scans()).
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "sdpslam/core/range_scan.h"
#include "sdpslam/daemon/daemon_config.h"
#include "sdpslam/io/map_image.h"
#include "sdpslam/io/trajectory_io.h"

namespace sdpslam::daemon {

struct EngineStep {
  bool processed = false;  // false: skipped by the filter (too little motion)
  Pose2 pose;              // best estimate at the scan, map frame
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
  // Engine counters as JSON members (`"key": value` pairs, comma separated, no braces).
  virtual std::string status_json() const = 0;
  virtual std::uint64_t unrecorded_scans() const = 0;
};

// Builds the engine the configuration asks for. Null (with *error) iff the mode is not
// available in this build or its memory cannot be set up.
std::unique_ptr<SlamEngine> make_engine(const DaemonConfig& config, std::string* error);

}  // namespace sdpslam::daemon
