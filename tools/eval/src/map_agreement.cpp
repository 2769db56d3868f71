#include "sdpslam/eval/map_agreement.h"

#include <cmath>

#include "sdpslam/eval/stamp_match.h"
#include "sdpslam/io/log_reader.h"

namespace sdpslam::eval {

MapAgreement::MapAgreement(const io::OccupancyImage& map, double occupied_thresh)
    : map_(map), wall_(map.occupancy.size(), 0U) {
  for (std::size_t i = 0; i < map.occupancy.size(); ++i) {
    wall_[i] = map.occupancy[i] >= 0.0F && map.occupancy[i] > occupied_thresh ? 1U : 0U;
  }
}

bool MapAgreement::wall_near(double x_m, double y_m) const {
  const double fx = std::floor((x_m - map_.origin_x_m) / map_.resolution_m);
  const double fy = std::floor((y_m - map_.origin_y_m) / map_.resolution_m);
  if (!(fx >= -1.0 && fy >= -1.0 && fx <= map_.width && fy <= map_.height)) return false;
  const auto cx = static_cast<long>(fx);
  const auto cy = static_cast<long>(fy);
  for (long y = cy - 1; y <= cy + 1; ++y) {
    for (long x = cx - 1; x <= cx + 1; ++x) {
      if (x < 0 || y < 0 || x >= static_cast<long>(map_.width) || y >= static_cast<long>(map_.height)) continue;
      if (wall_[static_cast<std::size_t>(y) * map_.width + static_cast<std::size_t>(x)] != 0U) return true;
    }
  }
  return false;
}

void MapAgreement::add_scan(const Pose2& robot_pose, const RangeScan& scan) {
  const Pose2 laser = robot_pose.compose(scan.geometry.laser_in_base);
  ++result_.scans_cast;
  for (std::uint32_t i = 0; i < scan.beam_count; ++i) {
    if (scan.classify(i) != RangeScan::Beam::kReturn) continue;
    const double a = scan.beam_angle_rad(i);
    const double r = scan.ranges_m[i];
    double x = 0.0;
    double y = 0.0;
    laser.transform_point(r * std::cos(a), r * std::sin(a), x, y);
    ++result_.return_count;
    if (wall_near(x, y)) ++result_.on_wall_count;
  }
}

bool evaluate_map_agreement(const std::string& log_path, const std::vector<io::StampedPose>& trajectory,
                            const io::OccupancyImage& map, double occupied_thresh, std::int64_t tolerance_us,
                            MapAgreementResult* result, std::string* error) {
  io::LogReader reader;
  if (!reader.open(log_path, io::LogReaderOptions{}, error)) return false;
  MapAgreement agreement(map, occupied_thresh);
  std::size_t scans = 0U;
  for (io::LogReader::Next n = reader.next(); n != io::LogReader::Next::kEnd; n = reader.next()) {
    if (n != io::LogReader::Next::kLaser) continue;
    ++scans;
    const io::LaserRecord& r = reader.laser();
    std::size_t k = 0U;
    if (find_stamp(trajectory, r.stamp_us, tolerance_us, &k) == StampMatch::kNone) continue;
    agreement.add_scan(trajectory[k].pose, r.scan);
  }
  *result = agreement.result();
  result->scan_count = scans;
  return true;
}

}  // namespace sdpslam::eval
