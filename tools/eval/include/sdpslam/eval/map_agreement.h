#pragma once
// Agreement of a map with a trajectory: cast every laser scan of the log from the pose the
// trajectory gives it and count the returns that end on the map's walls (within one cell
// of an occupied cell). A map drawn where the trajectory says the robot was scores high;
// a map whose parts lag the trajectory (or a trajectory that drifted from its own map)
// scores lower. It needs no ground truth, so it also compares maps of different systems
// on the same log. Returns in unknown or free space, or outside the image, count as off
// the walls: the figure is a share of all returns, not of those the map covers.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "sdpslam/core/pose2.h"
#include "sdpslam/core/range_scan.h"
#include "sdpslam/io/map_image.h"
#include "sdpslam/io/trajectory_io.h"

namespace sdpslam::eval {

struct MapAgreementResult {
  std::size_t scan_count = 0;        // laser scans in the log
  std::size_t scans_cast = 0;        // ... that the trajectory has a pose for
  std::size_t return_count = 0;      // returns (range_min <= r < range_max) of those scans
  std::size_t on_wall_count = 0;     // ... ending within one cell of an occupied cell
  double share() const { return return_count > 0U ? static_cast<double>(on_wall_count) / static_cast<double>(return_count) : 0.0; }
};

class MapAgreement {
 public:
  // Cells with occupancy > occupied_thresh are walls (map_server's rule).
  MapAgreement(const io::OccupancyImage& map, double occupied_thresh);
  // Casts `scan` from `robot_pose` (the laser at robot_pose ⊕ scan.geometry.laser_in_base).
  void add_scan(const Pose2& robot_pose, const RangeScan& scan);
  const MapAgreementResult& result() const { return result_; }
  MapAgreementResult& result() { return result_; }

 private:
  bool wall_near(double x_m, double y_m) const;
  const io::OccupancyImage& map_;
  std::vector<std::uint8_t> wall_;
  MapAgreementResult result_;
};

// Reads `log_path` and casts each of its scans from the pose of `trajectory` (sorted by
// stamp) with the scan's stamp (within tolerance_us); scans without one are counted and
// left out. False iff the log cannot be read; `error` then says why.
bool evaluate_map_agreement(const std::string& log_path, const std::vector<io::StampedPose>& trajectory,
                            const io::OccupancyImage& map, double occupied_thresh, std::int64_t tolerance_us,
                            MapAgreementResult* result, std::string* error);

}  // namespace sdpslam::eval
