#pragma once
// What the offline runners (run_offline.cpp, run_sdp.cpp) share: the log's scans paired
// with odometry, per-scan CPU time of this thread (meaningful on a loaded machine where
// wall time is not), and the percentiles and fixed-point text of stats.json. Used
// only in the runtime (POSIX clock), never in core/.
#include <sys/resource.h>
#include <time.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <cstdint>
#include <vector>

#include "sdpslam/core/range_scan.h"
#include "sdpslam/io/log_reader.h"

namespace sdpslam::slam::detail {

// Pairs each laser scan of a log with its odometry: the pose inside the laser message
// if it has one, else the latest ODOM line. Scans before any odometry cannot be placed:
// they are skipped and counted.
class ScanOdometryPairing {
 public:
  // Advances `reader` to the next scan that has odometry; false at the end of the log.
  // The scan is reader.laser(), its odometry `*od` (stamped with the scan's stamp).
  bool next(io::LogReader& reader, OdometrySample* od) {
    for (;;) {
      const io::LogReader::Next k = reader.next();
      if (k == io::LogReader::Next::kEnd) return false;
      if (k == io::LogReader::Next::kOdom) {
        last_odom_ = reader.odom().pose;
        have_odom_ = true;
        continue;
      }
      if (k != io::LogReader::Next::kLaser) continue;
      const io::LaserRecord& rec = reader.laser();
      od->stamp_us = rec.stamp_us;
      if (rec.has_odom_pose) {
        od->pose = rec.odom_pose;
      } else if (have_odom_) {
        od->pose = last_odom_;
      } else {
        ++scans_without_odom_;
        continue;
      }
      return true;
    }
  }
  std::uint64_t scans_without_odom() const { return scans_without_odom_; }

 private:
  Pose2 last_odom_;
  bool have_odom_ = false;
  std::uint64_t scans_without_odom_ = 0U;
};

// CPU time consumed by the calling thread, in milliseconds.
inline double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

// User + system CPU seconds of a getrusage() result: stats.json's "cpu_time_s".
inline double rusage_cpu_s(const rusage& ru) {
  return static_cast<double>(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) +
         static_cast<double>(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec) * 1e-6;
}

// Nearest-rank percentile (q in [0, 1]; 1 = maximum); 0 for an empty series.
inline double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const auto idx = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1U) + 0.5);
  return v[std::min(idx, v.size() - 1U)];
}

// One number through a printf format (e.g. "%.3f").
inline std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

}  // namespace sdpslam::slam::detail
