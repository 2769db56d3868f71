#pragma once
// ROS 1 bags (format 2.0) as a log: each sensor_msgs/LaserScan of the scan topic becomes
// a laser record whose odometry pose is the robot's odometry at the scan's header stamp,
// and whose laser mounting comes from the static transforms.
//
//   - Scan topic: LogReaderOptions::bag_scan_topic, else the bag's only LaserScan topic
//     (with several, "/scan" if present; otherwise the reader refuses and names them).
//   - Odometry: the nav_msgs/Odometry topic (bag_odom_topic, else the only one, "/odom"
//     among several); with none, the odom -> base transforms of /tf (tf2_msgs/TFMessage;
//     frames bag_odom_frame and bag_base_frame). Every odometry message is read at open
//     (a few tens of bytes each) and the pose at a scan's stamp is interpolated between
//     the two around it (linear in x, y, shortest way in heading), exact when a message
//     has the scan's stamp. A scan outside the odometry's time span has none: the runner
//     skips and counts it, as a CARMEN scan before any odometry.
//   - Mounting: the chain of /tf_static transforms from the base frame (the odometry's
//     child_frame_id, else bag_base_frame) to the scan's frame_id; identity, with one
//     warning, when the bag has no such chain.
//   - Ranges (REP 117): +inf is no return (range_max), NaN and -inf are invalid (0, below
//     range_min); a scan of more than capacity::kMaxBeams beams is skipped with an error.
//   - Stamps: header.stamp (µs, truncated); the record's logger stamp is the bag's
//     receive time.
// Messages are read in the bag's time order through rosbag_storage (Debian
// librosbag-storage-dev), whose chunked, bz2 and lz4 files it reads; message types
// through the Debian message packages (libsensor-msgs-dev, libnav-msgs-dev,
// libtf2-msgs-dev). A build without them refuses bags with a message that says so.
#include <cstdint>
#include <memory>
#include <string>

#include "bag_common.h"

namespace sdpslam::io::detail {

class RosBagSource final : public BagSource {
 public:
  RosBagSource();
  ~RosBagSource() override;
  RosBagSource(const RosBagSource&) = delete;
  RosBagSource& operator=(const RosBagSource&) = delete;

  bool open(const std::string& path, const LogReaderOptions& options, std::string* error) override;
  Got next(LaserRecord* laser, std::string* reason, bool* warning, std::int64_t* index) override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sdpslam::io::detail
