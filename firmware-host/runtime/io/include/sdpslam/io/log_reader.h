#pragma once
// Streaming readers of robot logs: CARMEN (.clf, optionally .gz), tinySLAM's one-line-
// per-scan format, and DP-SLAM's Odometry/Laser format. Part of the runtime (POSIX files), not core/.
//
// The reader hands out one record at a time and never holds the whole log. A malformed
// line never stops the read: it is skipped and reported as a LogError naming the file,
// the 1-based line number and the reason; every good record before and after it is
// delivered. Nothing is silently misread: a line either parses completely and passes
// its consistency checks, or it is an error.
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "sdpslam/core/pose2.h"
#include "sdpslam/core/range_scan.h"

namespace sdpslam::io {

enum class LogFormat {
  kAuto,      // from content: CARMEN keywords, "Odometry"/"Laser", or tinySLAM numeric lines
  kCarmen,
  kTinySlam,
  kDpSlam,
  kRosBag,    // a ROS 1 bag (format 2.0): LaserScan + Odometry or /tf (src/rosbag_source.h)
  kRos2Bag,   // a ROS 2 bag (rosbag2 folder or .db3: SQLite + CDR), the same messages (ros2_bag.h)
};

const char* to_string(LogFormat f);

struct LogError {
  std::string file;
  std::int64_t line = 0;  // 1-based
  std::string reason;
  // True when the line was skipped on purpose rather than malformed (a CARMEN message
  // type this reader does not know); counted with the errors all the same.
  bool warning = false;
  std::string to_string() const;  // "file:line: reason"
};

// Writes the skipped lines to `out`, one "file:line: reason" each: the first max_each
// malformed lines and the first max_each warnings (lines skipped on purpose), then
// "... and N more skipped lines" for the rest of `total` (every skipped line, of which
// `errors` holds the first ones). Every command that reads a log reports this way.
void write_log_errors(std::FILE* out, const std::vector<LogError>& errors, std::size_t total, std::size_t max_each);

// A laser scan with everything the log says about it.
struct LaserRecord {
  std::string keyword;              // FLASER, RLASER, ROBOTLASER1, tinyslam, dpslam
  std::int64_t stamp_us = 0;        // CARMEN ipc_timestamp, exact to the microsecond;
                                    // tinySLAM: field 1; DP-SLAM: synthetic, index * 100 ms
  std::int64_t logger_stamp_us = 0; // CARMEN logger_timestamp (0 when the format has none)
  bool has_stamp = true;            // false for DP-SLAM logs (stamps are synthetic)
  RangeScan scan;                   // ranges and beam geometry; scan.stamp_us == stamp_us
  Pose2 laser_pose;                 // CARMEN: pose of the laser in the log's world frame
  bool has_laser_pose = false;
  Pose2 odom_pose;                  // robot odometry pose at the scan
  bool has_odom_pose = false;
  double tv_mps = 0.0;              // ROBOTLASER1: the measured translational velocity
  bool has_tv = false;
  std::int64_t line = 0;
};

struct OdomRecord {
  std::int64_t stamp_us = 0;
  std::int64_t logger_stamp_us = 0;
  Pose2 pose;
  double tv_mps = 0.0;
  double rv_radps = 0.0;
  std::int64_t line = 0;
};

struct ParamRecord {
  std::string name;
  std::string value;
  std::int64_t line = 0;
};

// Robot constants for formats that carry raw wheel ticks (tinySLAM). Defaults are the
// "MinesRover" of tinyslam-exp2.dat: 2000 ticks/rev, wheel radius 77 mm, half axle 165 mm.
struct WheelOdometryParams {
  double ticks_per_rev = 2000.0;
  double wheel_radius_m = 0.077;
  double wheel_separation_m = 0.330;
};

struct LogReaderOptions {
  LogFormat format = LogFormat::kAuto;
  WheelOdometryParams wheels;
  // A beam reading at or above this is treated as "no return" when the log does not
  // carry a maximum range itself (FLASER, DP-SLAM). Metres.
  float default_range_max_m = 50.0F;
  // Errors kept in errors(); more are counted in error_count() only.
  std::size_t max_errors_kept = 1000;
  // CARMEN FLASER/RLASER lines carry neither the laser's mounting nor its range limit.
  // These are used instead; PARAM robot_frontlaser_offset, robot_rearlaser_offset,
  // robot_frontlaser_max / robot_front_laser_max (and the rear ones) in the log override
  // them from that line on. A max of 0 means default_range_max_m.
  double front_laser_offset_m = 0.0;
  double rear_laser_offset_m = 0.0;
  float front_laser_max_m = 0.0F;
  float rear_laser_max_m = 0.0F;
  // tinySLAM: the URG's forward offset from the wheel axle (BreezySLAM examples/mines.py,
  // MinesLaser: 145 mm).
  double tinyslam_laser_offset_m = 0.145;
  // Plausibility of the odometry ([log] keys): an increment between two consecutive
  // odometry poses (ODOM and the lasers' odometry poses, in file order) that moves
  // farther than max_speed_mps × Δt + 0.5 m, or turns more than max_turn_rate_radps ×
  // Δt + 0.5 rad, is no motion a wheeled robot makes: a reset or a corrupt line. It is
  // reported (file:line) and not applied: the chain goes on from the pose before it.
  // Checked where the log has real timestamps; 0 = not checked.
  double max_speed_mps = 5.0;
  double max_turn_rate_radps = 10.0;
  // ROS 1 and ROS 2 bags: the sensor_msgs/LaserScan topic and the nav_msgs/Odometry topic (empty:
  // the bag's only one, or /scan and /odom among several); without an Odometry topic the
  // odom_frame -> base_frame transforms of /tf are the odometry. The laser's mounting is
  // the /tf_static chain from the base frame (the Odometry's child_frame_id, else
  // base_frame) to the scan's frame_id.
  std::string bag_scan_topic;
  std::string bag_odom_topic;
  std::string bag_odom_frame = "odom";
  std::string bag_base_frame = "base_link";
};

class LogReader {
 public:
  enum class Next { kLaser, kOdom, kParam, kEnd };

  LogReader();
  ~LogReader();
  LogReader(const LogReader&) = delete;
  LogReader& operator=(const LogReader&) = delete;

  // Opens `path` (".gz" read through zlib). False iff it cannot be opened or the format
  // cannot be detected; `error` then says why.
  bool open(const std::string& path, const LogReaderOptions& options, std::string* error);

  // Advances to the next good record, skipping (and recording) malformed lines.
  //
  // Reversed odometry (CARMEN): ODOM and ROBOTLASER1 carry the integrated odometry pose
  // and, beside it, the measured translational velocity tv. Some bases integrate the
  // speed's magnitude, so while the robot drives backwards (tv < 0) their pose still
  // advances along its heading: the two measurements of one motion disagree in sign,
  // and SLAM fed that pose builds its map a metre off after every reverse manoeuvre.
  // The velocity is the direct measurement, so an increment between consecutive
  // velocity-carrying poses whose forward component has the opposite sign of tv is
  // mirrored (-dx, -dy, same turn) and counted (odometry_reversals_repaired()). From the
  // first repair on, every odometry pose the reader returns (ODOM, and the odometry and
  // laser poses of FLASER, RLASER and ROBOTLASER1) is placed on the repaired chain; the
  // poses of a log that never contradicts itself are returned exactly as written.
  //
  // Impossible input: scans whose timestamp is before the previous scan of the same laser
  // are counted (scans_stamped_backwards()) and returned in file order, the order the
  // sensors delivered them (the Intel log has single lines stamped up to 0.9 s ahead of
  // their neighbours); an odometry increment
  // beyond the plausible speed or turn rate (LogReaderOptions) is reported and not
  // applied, so that a reset or a corrupt pose never teleports the robot: every later
  // odometry pose is moved by the same rigid transform, and their increments stay as
  // written.
  Next next();

  // The current record; valid until the next call to next().
  const LaserRecord& laser() const;
  const OdomRecord& odom() const;
  const ParamRecord& param() const;

  LogFormat format() const;
  const std::vector<LogError>& errors() const;
  std::size_t error_count() const;    // every skipped line, warnings included
  std::size_t warning_count() const;  // the part of error_count() that are warnings
  // Odometry increments mirrored because they ran against the log's own measured
  // velocity (see LogReader::next()); 0 for a log whose odometry is self-consistent.
  std::size_t odometry_reversals_repaired() const;
  // Odometry increments beyond LogReaderOptions' plausible speed or turn rate, not
  // applied (each also in errors()).
  std::size_t odometry_jumps_removed() const;
  // Laser scans stamped before the previous scan of the same laser, and the line of the
  // first: they are returned in file order, stamps as written.
  std::size_t scans_stamped_backwards() const;
  std::int64_t first_backwards_line() const;
  std::int64_t lines_read() const;
  // Bytes of the input file consumed so far (compressed bytes for .gz), for progress.
  std::uint64_t input_offset() const;
  // For a ROS bag: the topics and frames it is read through ("scan /scan, odometry
  // /odom, base frame base_link"); empty for text logs.
  std::string source_description() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Parses one line of a CARMEN log in isolation (exposed for tests and the fuzzer).
// Returns kLaser/kOdom/kParam on success, kEnd for a blank line or comment or an
// ignored message type (e.g. SYNC, TRUEPOS), and sets *reason (non-empty) iff the line
// is malformed or its message type is unknown ("unknown message type 'X'", which the
// reader reports as a warning). Lines over 64 KiB, bytes outside printable ASCII/tab,
// NaN/inf, negative ranges and beam counts outside [2, kMaxBeams] are malformed.
LogReader::Next parse_carmen_line(const std::string& line, const LogReaderOptions& options,
                                  LaserRecord* laser, OdomRecord* odom, ParamRecord* param,
                                  std::string* reason);

// Reads a whole log into memory (for tools and tests; the core never does this).
struct LogContents {
  std::vector<LaserRecord> lasers;
  std::vector<OdomRecord> odoms;
  std::vector<ParamRecord> params;
  std::vector<LogError> errors;
  std::size_t error_count = 0;
  std::size_t warning_count = 0;
  LogFormat format = LogFormat::kAuto;
};
bool read_whole_log(const std::string& path, const LogReaderOptions& options, LogContents* out,
                    std::string* error);

}  // namespace sdpslam::io
