#pragma once
// ROS 2 bags (rosbag2, SQLite 3 storage, CDR messages) as a log: the same messages and
// rules as ROS 1 bags (rosbag_source.h, bag_common.h), from a rosbag2 folder (its
// metadata.yaml names the .db3 files, read in that order; without it, the folder's .db3
// files by name) or one .db3 file. Message types sensor_msgs/msg/LaserScan,
// nav_msgs/msg/Odometry and tf2_msgs/msg/TFMessage, serialisation "cdr"; a message
// that does not decode is named and skipped. Through libsqlite3 and Fast-CDR (Debian
// libsqlite3-dev, libfastcdr-dev); a build without them refuses with what to install.
#include <cstdint>
#include <memory>
#include <string>

#include "bag_common.h"

namespace sdpslam::io::detail {

class Ros2BagSource final : public BagSource {
 public:
  Ros2BagSource();
  ~Ros2BagSource() override;
  Ros2BagSource(const Ros2BagSource&) = delete;
  Ros2BagSource& operator=(const Ros2BagSource&) = delete;

  bool open(const std::string& path, const LogReaderOptions& options, std::string* error) override;
  Got next(LaserRecord* laser, std::string* reason, bool* warning, std::int64_t* index) override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The writer behind io::Ros2BagWriter (ros2_bag.cpp), and whether this build has ROS 2
// bags at all (false: ros2_bag_none.cpp, whose reader and writer refuse with what to install).
std::unique_ptr<BagWriter> make_ros2_writer();
bool ros2_bags_built();

}  // namespace sdpslam::io::detail
