#include "sdpslam/daemon/input_recorder.h"

#include <cerrno>
#include <cstring>

#include "sdpslam/io/carmen_writer.h"

namespace sdpslam::daemon {
namespace {

bool same_bits(const void* a, const void* b, std::size_t n) { return std::memcmp(a, b, n) == 0; }

bool same_pose(const Pose2& a, const Pose2& b) {
  return same_bits(&a.x_m, &b.x_m, sizeof a.x_m) && same_bits(&a.y_m, &b.y_m, sizeof a.y_m) &&
         same_bits(&a.heading_rad, &b.heading_rad, sizeof a.heading_rad);
}

bool same_scan(const RangeScan& a, const RangeScan& b) {
  const ScanGeometry& g = a.geometry;
  const ScanGeometry& h = b.geometry;
  return a.stamp_us == b.stamp_us && a.beam_count == b.beam_count &&
         same_bits(&g.angle_min_rad, &h.angle_min_rad, sizeof g.angle_min_rad) &&
         same_bits(&g.angle_increment_rad, &h.angle_increment_rad, sizeof g.angle_increment_rad) &&
         same_bits(&g.range_min_m, &h.range_min_m, sizeof g.range_min_m) &&
         same_bits(&g.range_max_m, &h.range_max_m, sizeof g.range_max_m) && same_pose(g.laser_in_base, h.laser_in_base) &&
         same_bits(a.ranges_m, b.ranges_m, sizeof(float) * a.beam_count);
}

}  // namespace

InputRecorder::~InputRecorder() {
  if (file_ != nullptr) std::fclose(file_);
}

bool InputRecorder::open(const std::string& path, std::string* error) {
  if (file_ != nullptr) std::fclose(file_);
  path_ = path;
  file_ = std::fopen(path.c_str(), "w");
  if (file_ == nullptr) {
    *error = path + ": cannot create the input recording: " + std::strerror(errno);
    return false;
  }
  std::fputs(
      "# CARMEN log written by sdpslamd ([output] input_log): every scan handed to SLAM with the odometry\n"
      "# pose it was given. ipc_timestamp = the scan's stamp (CLOCK_MONOTONIC), logger_timestamp = when the\n"
      "# laser driver handed it out. Replay: sdpslam run input.clf --mode dpslam (same options and seed).\n"
      "# ROBOTLASER1 laser_type start_angle field_of_view angular_resolution maximum_range accuracy "
      "remission_mode num_readings [range_readings] num_remissions [remissions] laser_pose_x laser_pose_y "
      "laser_pose_theta robot_pose_x robot_pose_y robot_pose_theta laser_tv laser_rv forward_safety_dist "
      "side_safty_dist turn_axis ipc_timestamp ipc_hostname logger_timestamp\n",
      file_);
  if (std::fflush(file_) != 0) {
    *error = path + ": cannot write the input recording: " + std::strerror(errno);
    std::fclose(file_);
    file_ = nullptr;
    return false;
  }
  return true;
}

// A scan no CARMEN line can carry (the drivers produce none: 2..kMaxBeams beams, finite
// poses): counted, and fed as it is.
void InputRecorder::refuse(const OdometrySample& odom, const RangeScan& scan, OdometrySample* odom_out,
                           RangeScan* scan_out) {
  ++stats_.roundtrip_failures;
  last_error_ = "input recording: the reader refuses the line of the scan at " + std::to_string(odom.stamp_us) +
                " us: " + reason_;
  *odom_out = odom;
  *scan_out = scan;
}

bool InputRecorder::pass(const OdometrySample& odom, const RangeScan& scan, std::int64_t read_us,
                         OdometrySample* odom_out, RangeScan* scan_out) {
  ++stats_.scans;
  record_.stamp_us = odom.stamp_us;
  record_.logger_stamp_us = read_us;
  record_.scan = scan;
  record_.scan.stamp_us = odom.stamp_us;
  record_.odom_pose = odom.pose;
  record_.has_odom_pose = true;
  record_.has_laser_pose = false;
  // What SLAM gets is what the recording reads back as, recorded or not; it is computed
  // without text (io::carmen_laser_round_trip) unless the numbers are so extreme that only
  // the line can tell.
  const io::CarmenRoundTrip k = io::carmen_laser_round_trip(record_, scan_out, &odom_out->pose);
  odom_out->stamp_us = odom.stamp_us;
  const bool text = file_ != nullptr || k == io::CarmenRoundTrip::kUnknown;
  if (text) line_ = io::format_carmen_laser_line(record_);
  if (k == io::CarmenRoundTrip::kUnknown) {
    if (io::parse_carmen_line(line_, reader_options_, &parsed_, &odom_scratch_, &param_scratch_, &reason_) ==
        io::LogReader::Next::kLaser) {
      odom_out->stamp_us = parsed_.stamp_us;
      odom_out->pose = parsed_.odom_pose;
      *scan_out = parsed_.scan;
    } else {
      refuse(odom, scan, odom_out, scan_out);
    }
  } else if (k == io::CarmenRoundTrip::kRefused) {
    reason_ = "no CARMEN line carries it (fewer than 2 beams, or a pose, laser configuration or stamp out of range)";
    refuse(odom, scan, odom_out, scan_out);
  }
  if (!same_pose(odom_out->pose, odom.pose) || odom_out->stamp_us != odom.stamp_us || !same_scan(*scan_out, scan)) {
    ++stats_.changed_count;
  }

  if (file_ == nullptr) return true;
  errno = 0;
  const bool ok = std::fputs(line_.c_str(), file_) >= 0 && std::fflush(file_) == 0;
  if (!ok) {
    ++stats_.write_failures;
    last_error_ = path_ + ": write failed: " + std::strerror(errno != 0 ? errno : EIO);
    std::clearerr(file_);
    return false;
  }
  ++stats_.lines_written;
  stats_.bytes_written += line_.size();
  return true;
}

}  // namespace sdpslam::daemon
