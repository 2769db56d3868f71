#pragma once
// Writes CARMEN logs (the simulator's output, the `convert` subcommand's). Lines follow
// ../shared/datasets/README.md: ODOM x y theta tv rv accel ipc_ts host logger_ts, and
// FLASER / ROBOTLASER1 with the laser's geometry. Stamps are printed to the microsecond.
// The file is written to a temporary name and renamed into place on close() (atomic).
#include <cstdint>
#include <memory>
#include <string>

#include "sdpslam/io/log_reader.h"

namespace sdpslam::io {

// The line CarmenWriter::laser() writes for `r` (FLASER or ROBOTLASER1, '\n' included),
// for programs that stream a log line by line instead of writing it atomically.
std::string format_carmen_laser_line(const LaserRecord& r);

// What parse_carmen_line (default LogReaderOptions) reads back from
// format_carmen_laser_line(r), computed from the numbers without formatting any text (the writer prints every number
// so that it reads back exactly; what changes is the line's convention: no range_min, the
// mounting rebuilt as between(robot pose, laser pose), NaN / +inf beams as 0 / range_max,
// FLASER's fixed geometry). kDone: *scan (its stamp r.stamp_us) and *odom_pose are those
// values. kRefused: the reader refuses the line (fewer than 2 beams, a pose, the laser
// configuration or a stamp it cannot carry); the outputs are untouched. kUnknown: the line
// may be longer than the reader's line limit (numbers of extreme magnitude), so only its
// text can tell; the outputs are untouched.
enum class CarmenRoundTrip { kDone, kRefused, kUnknown };
CarmenRoundTrip carmen_laser_round_trip(const LaserRecord& r, RangeScan* scan, Pose2* odom_pose);

class CarmenWriter {
 public:
  CarmenWriter();
  ~CarmenWriter();  // abandons (removes) an unclosed temporary file
  CarmenWriter(const CarmenWriter&) = delete;
  CarmenWriter& operator=(const CarmenWriter&) = delete;

  bool open(const std::string& path, std::string* error);
  void comment(const std::string& text);
  void param(const std::string& name, const std::string& value);
  void odom(const OdomRecord& r);
  // FLASER when the scan covers exactly 180 deg from -90 deg with range_max equal to the
  // FLASER convention; otherwise ROBOTLASER1 so that the geometry is not lost.
  void laser(const LaserRecord& r);
  // Flushes, fsyncs and renames into place; false iff any write failed.
  bool close(std::string* error);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sdpslam::io
