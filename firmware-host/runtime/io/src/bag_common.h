#pragma once
// What ROS 1 and ROS 2 bags share once their messages are decoded (rosbag_source.h,
// ros2_bag.h): the choice of topics, the odometry at a scan's stamp, the laser's mounting
// from the static transforms, and a LaserScan as a LaserRecord (REP 117 ranges).
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "sdpslam/core/pose2.h"
#include "sdpslam/io/log_reader.h"

namespace sdpslam::io::detail {

// A sensor_msgs/LaserScan, decoded.
struct BagScan {
  std::int64_t stamp_us = 0;  // header.stamp
  std::string frame;
  float angle_min = 0.0F;
  float angle_increment = 0.0F;
  float range_min = 0.0F;
  float range_max = 0.0F;
  std::vector<float> ranges;
};

// One transform (geometry_msgs/TransformStamped) or odometry pose, decoded.
struct BagTransform {
  std::int64_t stamp_us = 0;
  std::string parent;
  std::string child;
  Pose2 pose;  // of the child in the parent
};

std::int64_t stamp_us_of(std::int64_t sec, std::uint32_t nanosec);
double yaw_of(double x, double y, double z, double w);  // heading of a unit quaternion
std::string frame_name(const std::string& f);          // without a leading '/'

// The topic of `type` among `topics` ((name, type) pairs): `wanted` if given (refused if
// absent or of another type), else the only one, else `preferred` among several. Empty
// with *error set when none can be chosen; empty without error when there is none and
// `required` is false.
std::string choose_topic(const std::vector<std::pair<std::string, std::string>>& topics, const std::string& type,
                         const std::string& wanted, const std::string& preferred, const char* what,
                         const char* option, bool required, std::string* error);

// True iff the file starts with the ROS 1 bag magic "#ROSBAG V2.0".
bool looks_like_rosbag(const std::string& path);
// A folder with a metadata.yaml or .db3 files, or a file that starts as SQLite 3 does.
bool looks_like_ros2_bag(const std::string& path);

// What LogReader opens a bag with: set by enable_bag_formats() (sdpslam_io_bags); null
// in a program that reads no bags. A maker returns null, with the reason in *error, when
// the bag plugin cannot be loaded.
class BagSource;
using BagSourceMaker = std::unique_ptr<BagSource> (*)(std::string* error);
extern BagSourceMaker g_make_ros1_source;
extern BagSourceMaker g_make_ros2_source;

// The odometry and the static transforms of a bag, and scans turned into records.
class BagAssembler {
 public:
  void set_base_frame(const std::string& frame) { base_frame_ = frame_name(frame); }
  const std::string& base_frame() const { return base_frame_; }
  void add_odometry(std::int64_t stamp_us, const Pose2& pose) { odometry_.emplace_back(stamp_us, pose); }
  void add_static(const BagTransform& t) { statics_[frame_name(t.child)] = {frame_name(t.parent), t.pose}; }
  // Sorts the odometry by stamp (one pose per stamp: the last given). False if there is none.
  bool finish_odometry();
  // The scan as a record: false with *reason if the core cannot take it; true with a
  // warning in *reason the first time a frame has no static chain to the base.
  bool to_record(const BagScan& scan, std::int64_t receive_us, LaserRecord* out, std::string* reason,
                 bool* warning);

 private:
  bool odometry_at(std::int64_t t_us, Pose2* out) const;
  std::pair<bool, Pose2> mount(const std::string& frame);

  std::string base_frame_ = "base_link";
  std::vector<std::pair<std::int64_t, Pose2>> odometry_;
  std::map<std::string, std::pair<std::string, Pose2>> statics_;  // child -> (parent, pose)
  std::map<std::string, std::pair<bool, Pose2>> mounts_;          // frame -> (found, in base)
};

// A bag read as a log (RosBagSource, Ros2BagSource): scan messages in time order.
class BagSource {
 public:
  enum class Got { kLaser, kSkipped, kEnd };
  virtual ~BagSource() = default;
  // False (with the reason) if the bag cannot be read or has no usable scan topic.
  virtual bool open(const std::string& path, const LogReaderOptions& options, std::string* error) = 0;
  // The next scan message: kLaser fills `laser` (a warning for it, if any, in *reason);
  // kSkipped sets *reason (and *warning: skipped on purpose rather than malformed).
  // *index is the message's 1-based position among the scan topic's messages.
  virtual Got next(LaserRecord* laser, std::string* reason, bool* warning, std::int64_t* index) = 0;
  // Progress: the share of the scan messages read, scaled to the bag's size in bytes.
  std::uint64_t offset() const;
  // What open() chose: "scan /scan, odometry /odom, base frame base_link".
  std::string description() const;

 protected:
  // The scan topic (into scan_topic_) and the odometry topic (empty: none, use /tf) among
  // the bag's (name, type) pairs, by `options`, with the message types of this kind of
  // bag; the base frame starts as options' (an Odometry's child_frame_id replaces it).
  // False with *error ("PATH: why") when no choice can be made.
  bool choose_topics(const std::vector<std::pair<std::string, std::string>>& topics, const char* scan_type,
                     const char* odom_type, const LogReaderOptions& options, const std::string& path,
                     std::string* odom_topic, std::string* error);

  // Set by the sources as they open and read.
  std::string scan_topic_;
  std::string odom_source_;  // the odometry topic, or "/tf (odom -> base_link)"
  std::uint64_t bag_bytes_ = 0U;
  std::uint64_t scan_count_ = 0U;
  std::uint64_t scans_read_ = 0U;
  BagAssembler assembler_;
};

// A log written as a bag (the ROS 2 writer behind io::Ros2BagWriter, sdpslam/io/bags.h,
// whose functions these are).
class BagWriter {
 public:
  virtual ~BagWriter() = default;  // abandons (removes) an unclosed bag
  virtual bool open(const std::string& folder, std::string* error) = 0;
  virtual void odom(const OdomRecord& r) = 0;
  virtual bool laser(const LaserRecord& r, std::string* error) = 0;
  virtual std::uint64_t scans_written() const = 0;
  virtual std::uint64_t scans_without_odometry() const = 0;
  virtual bool close(std::string* error) = 0;
};

// The bag plugin, sdpslam_bags.so (bag_plugin.cpp): the bag readers and writer with the
// ROS libraries they need, loaded by the program the first time it meets a bag, so that a
// run on any other log maps none of those libraries (they hold several MiB resident).
// The program and the plugin share these C++ types, so they must come from one build:
// `build` is compared with the program's own SDPSLAM_BAG_PLUGIN_BUILD before anything is used.
struct BagPlugin {
  const char* build;
  std::unique_ptr<BagSource> (*make_ros1_source)();
  std::unique_ptr<BagSource> (*make_ros2_source)();
  std::unique_ptr<BagWriter> (*make_ros2_writer)();
  bool ros2_supported;  // built with libsqlite3 and Fast-CDR (else its makers refuse)
};
// The file (found through the program's run path), and its one exported function.
constexpr const char* kBagPluginFile = "sdpslam_bags.so";
constexpr const char* kBagPluginEntry = "sdpslam_bag_plugin_v1";
using BagPluginEntry = const BagPlugin* (*)();

}  // namespace sdpslam::io::detail
