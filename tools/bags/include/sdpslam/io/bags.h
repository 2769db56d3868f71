#pragma once
// ROS bags as logs, in the programs that link sdpslam_io_bags (the `sdpslam` command; not
// the robot program, which reads no bags and links none of their libraries): after
// enable_bag_formats(), LogReader reads ROS 1 bags (src/rosbag_source.h) and ROS 2 bags
// (src/ros2_bag_source.h); before it, or in a program without it, a bag is refused.
//
// The readers and the writer, with the ROS libraries they need, live in a plugin,
// sdpslam_bags.so (src/bag_common.h: BagPlugin), installed beside the program's libraries
// in LIBDIR/sdpslam and loaded the first time a bag is opened: a run on any other log
// maps none of those libraries. A missing plugin, or one from another build, is refused
// with what went wrong. Each kind of bag needs its Debian packages at build time
// (tools/bags/CMakeLists.txt); a build without them refuses that kind with what to install.
//
// ROS 2 bags (rosbag2, SQLite 3 storage): a folder holding metadata.yaml and
// NAME_0.db3, messages serialised as CDR (little-endian XCDR1, as rmw_fastrtps writes
// them). LogReader reads them (LogFormat::kRos2Bag, the folder or a .db3 file: the
// topics, odometry and mounting as for ROS 1 bags, see LogReaderOptions::bag_*); this
// writer makes one from any log, for `sdpslam convert --to ros2`.
//
// Written: /scan sensor_msgs/msg/LaserScan (frame "laser"; a laser whose mounting changes
// gets a frame of its own, "laser_2", ...), /odom nav_msgs/msg/Odometry (odom ->
// base_link) at every scan's stamp with the odometry the scan was paired with (its own
// pose, else the latest odometry record), /tf tf2_msgs/msg/TFMessage with the same
// transform, /tf_static with base_link -> laser. Each heading's quaternion is chosen
// (within a few ulps of the exact one) so that LogReader gives the heading back bit for
// bit: a log written as a bag runs as the log. The folder appears whole at close()
// (written under a temporary name, then renamed); an existing OUT is refused.
//
// Through Debian's libsqlite3-dev and libfastcdr-dev; a build without them refuses with
// what to install (ros2_bags_supported()).
#include <cstdint>
#include <memory>
#include <string>

#include "sdpslam/io/log_reader.h"

namespace sdpslam::io {

namespace detail {
class BagWriter;
}

void enable_bag_formats();
// Loads the plugin now rather than at the first bag (a program that wants its
// allocations made early, or to report a broken install at start); false with the reason.
bool load_bag_plugin(std::string* error);
bool ros2_bags_supported();  // the plugin loads and was built with libsqlite3 and Fast-CDR

class Ros2BagWriter {
 public:
  Ros2BagWriter();
  ~Ros2BagWriter();  // abandons (removes) an unclosed bag
  Ros2BagWriter(const Ros2BagWriter&) = delete;
  Ros2BagWriter& operator=(const Ros2BagWriter&) = delete;

  bool open(const std::string& folder, std::string* error);
  // The latest odometry (used for scans that carry none).
  void odom(const OdomRecord& r);
  // False (with the reason) iff the message could not be written.
  bool laser(const LaserRecord& r, std::string* error);
  std::uint64_t scans_written() const;
  std::uint64_t scans_without_odometry() const;  // before any odometry: not written
  // Writes metadata.yaml and moves the folder into place; false iff any step failed.
  bool close(std::string* error);

 private:
  std::unique_ptr<detail::BagWriter> impl_;  // from the plugin, at open()
};

}  // namespace sdpslam::io
