#pragma once
// What replay needs from a robot log (io::LogReader): the scans with their stamps and
// the odometry pose track (ODOM lines, or the odometry pose inside each laser record when
// the log has no ODOM line).
#include <string>
#include <vector>

#include "sdpslam/io/log_reader.h"
#include "sdpslam/replay/encoder_frames.h"
#include "sdpslam/replay/laser_emulator.h"

namespace sdpslam::replay {

struct ReplayLog {
  io::LogFormat format = io::LogFormat::kAuto;
  std::vector<ReplayScan> scans;
  std::vector<StampedPose> odometry;
  bool odometry_from_laser_records = false;
  std::vector<std::string> errors;  // "file:line: reason" of skipped lines
};

// False iff the log cannot be opened or holds neither scans nor odometry.
bool load_replay_log(const std::string& path, ReplayLog* out, std::string* error);

}  // namespace sdpslam::replay
