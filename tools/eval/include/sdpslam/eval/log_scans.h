#pragma once
// The laser scans of a log as the relations metric needs them: one odometry pose per
// scan, keyed by the scan's exact stamp, in time order.
#include <cstddef>
#include <string>
#include <vector>

#include "sdpslam/io/log_reader.h"
#include "sdpslam/io/trajectory_io.h"

namespace sdpslam::eval {

struct LogScansReport {
  std::size_t laser_count = 0;             // laser records read
  std::size_t without_odometry_count = 0;  // left out: no odometry pose in the record
  std::size_t out_of_order_count = 0;      // scans whose stamp is earlier than the previous one's
  std::size_t malformed_line_count = 0;    // lines the reader skipped
  std::string first_malformed;             // "file:line: reason" of the first, if any
  io::LogFormat format = io::LogFormat::kAuto;
};

// Reads `log_path` and returns the odometry pose at every laser scan (LaserRecord::
// odom_pose; for the CARMEN FLASER lines of the benchmark logs this equals the laser pose
// field as well), sorted by stamp. CARMEN logs are not always in time order: intel.clf
// has 631 FLASER lines whose ipc_timestamp is earlier than the previous one's; they are
// counted in the report and sorted (stable). Malformed lines are skipped and counted.
// False iff the log cannot be opened, its stamps are synthetic (no real timestamps,
// e.g. DP-SLAM logs), no scan carries odometry, or two scans share a stamp (a relation
// could not tell them apart); `error` then says why, with file:line where there is one.
bool read_log_scan_odometry(const std::string& log_path, std::vector<io::StampedPose>* scans, LogScansReport* report,
                            std::string* error);

}  // namespace sdpslam::eval
