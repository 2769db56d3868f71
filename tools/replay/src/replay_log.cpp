#include "sdpslam/replay/replay_log.h"

namespace sdpslam::replay {

bool load_replay_log(const std::string& path, ReplayLog* out, std::string* error) {
  *out = ReplayLog{};
  io::LogReader reader;
  io::LogReaderOptions options;
  if (!reader.open(path, options, error)) return false;
  std::vector<StampedPose> laser_odom;
  for (;;) {
    const io::LogReader::Next n = reader.next();
    if (n == io::LogReader::Next::kEnd) break;
    if (n == io::LogReader::Next::kOdom) {
      out->odometry.push_back(StampedPose{reader.odom().stamp_us, reader.odom().pose});
    } else if (n == io::LogReader::Next::kLaser) {
      const io::LaserRecord& l = reader.laser();
      out->scans.push_back(ReplayScan{l.stamp_us, l.scan});
      if (l.has_odom_pose) laser_odom.push_back(StampedPose{l.stamp_us, l.odom_pose});
    }
  }
  out->format = reader.format();
  for (const io::LogError& e : reader.errors()) out->errors.push_back(e.to_string());
  if (out->odometry.empty()) {
    out->odometry = std::move(laser_odom);
    out->odometry_from_laser_records = true;
  }
  if (out->scans.empty() && out->odometry.empty()) {
    *error = path + ": no laser scans and no odometry";
    return false;
  }
  return true;
}

}  // namespace sdpslam::replay
