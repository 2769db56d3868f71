#pragma once
// sdpslamd's input recording ([output] input_log): every scan handed to SLAM, with the
// odometry pose and stamp it was given, as one CARMEN ROBOTLASER1 line
// (io::format_carmen_laser_line: ranges, beam geometry and laser mounting, robot pose,
// ipc_timestamp = the scan's stamp on our monotonic clock, logger_timestamp = when the
// laser driver handed the scan out). `sdpslam run input.clf --mode dpslam` with the same
// options and seed then reproduces sdpslamd's trajectory exactly.
//
// Exactness: a CARMEN line does not carry everything a RangeScan does (no range_min; the
// mounting is rebuilt as between(robot pose, laser pose), which may differ in the last
// bit; NaN / inf beams become 0 / range_max). So pass() always hands SLAM what a reader
// parses back from the scan's line, whether or not a file is being written: what SLAM sees
// does not depend on the switch, and the recording holds exactly the values SLAM used.
// Those values come from io::carmen_laser_round_trip, without formatting the line, so a
// robot that does not record formats no text per scan. stats().changed_count says how many
// scans the round trip altered at all (bitwise).
//
// Streaming: the file is created (truncated) by open() and each line is appended and
// flushed as the scan is fed, so a recording survives a crash up to its last scan. It is
// a record, not an output snapshot; it is not written atomically. A failed write is
// counted and remembered (the scan is still processed; later lines are tried again).
//
// Memory: one RangeScan-sized record and one line buffer inside the object. Without a
// recording pass() allocates nothing; with one, the line is built in a std::string.
#include <cstdint>
#include <cstdio>
#include <string>

#include "sdpslam/core/range_scan.h"
#include "sdpslam/io/log_reader.h"

namespace sdpslam::daemon {

struct InputRecorderStats {
  std::uint64_t scans = 0U;               // scans passed
  std::uint64_t lines_written = 0U;
  std::uint64_t bytes_written = 0U;
  std::uint64_t write_failures = 0U;
  std::uint64_t changed_count = 0U;       // scans the CARMEN round trip altered (bitwise)
  std::uint64_t roundtrip_failures = 0U;  // lines the reader refused (then the input is fed as is)
};

class InputRecorder {
 public:
  InputRecorder() = default;
  ~InputRecorder();
  InputRecorder(const InputRecorder&) = delete;
  InputRecorder& operator=(const InputRecorder&) = delete;

  // Creates (truncates) the recording at `path` and writes its comment header. False
  // (with *error naming the path and errno's text) iff the file cannot be created.
  bool open(const std::string& path, std::string* error);
  bool is_open() const { return file_ != nullptr; }

  // The scan and odometry SLAM is to use: *odom_out / *scan_out receive what the CARMEN
  // line of (odom, scan) reads back as; the line is appended to the recording when one
  // is open. read_us is the driver's hand-out time (logger_timestamp). Returns false iff
  // a write failed (counted; last_error() says why); the outputs are valid either way.
  // The outputs may not alias the inputs.
  bool pass(const OdometrySample& odom, const RangeScan& scan, std::int64_t read_us, OdometrySample* odom_out,
            RangeScan* scan_out);

  const InputRecorderStats& stats() const { return stats_; }
  const std::string& last_error() const { return last_error_; }
  const std::string& path() const { return path_; }

 private:
  void refuse(const OdometrySample& odom, const RangeScan& scan, OdometrySample* odom_out, RangeScan* scan_out);

  std::FILE* file_ = nullptr;
  std::string path_;
  std::string line_;
  std::string reason_;
  io::LaserRecord record_;
  io::LaserRecord parsed_;
  io::OdomRecord odom_scratch_;
  io::ParamRecord param_scratch_;
  io::LogReaderOptions reader_options_;
  InputRecorderStats stats_;
  std::string last_error_;
};

}  // namespace sdpslam::daemon
