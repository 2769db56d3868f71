// CARMEN log writer. Numbers are printed as the shortest decimal that reads back to the
// same float/double (std::to_chars), so a log written here and read by LogReader gives
// back exactly the ranges and poses that went in; stamps are exact microseconds.
#include "sdpslam/io/carmen_writer.h"

#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

#include "log_parse.h"
#include "sdpslam/io/atomic_file.h"

namespace sdpslam::io {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr const char* kHost = "sdpslam";

// FLASER carries neither mounting nor range limit: only a scan that LogReader would
// rebuild identically from FLASER (default options) is written as one.
bool fits_flaser(const LaserRecord& r) {
  const ScanGeometry& g = r.scan.geometry;
  const std::uint32_t n = r.scan.beam_count;
  if (n < 2U) return false;
  const LogReaderOptions defaults;
  return g.angle_min_rad == static_cast<float>(-kPi / 2.0) &&
         g.angle_increment_rad == static_cast<float>(kPi / static_cast<double>(n - 1U)) && g.range_min_m == 0.0F &&
         g.range_max_m == defaults.default_range_max_m && g.laser_in_base.x_m == defaults.front_laser_offset_m &&
         g.laser_in_base.y_m == 0.0 && g.laser_in_base.heading_rad == 0.0;
}

std::string one_line(const std::string& text) {
  std::string out = text;
  for (char& c : out) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return out;
}

// The writer's mapping of a beam: RangeScan allows NaN and negative values as invalid
// beams and +inf as no return; the reader takes neither, so they are written as 0
// (invalid) and range_max (no return).
float carmen_range(float r, float range_max_m) {
  if (std::isinf(r) && r > 0.0F && std::isfinite(range_max_m)) return range_max_m;
  if (!std::isfinite(r) || r < 0.0F) return 0.0F;
  return r;
}

// An upper bound on the characters detail::format_exact prints for a finite v (fixed
// notation, the shortest digits that read back): sign, "0.", the zeros an exponent of
// magnitude |e10| adds, and at most `digits` significant digits.
std::size_t exact_width_bound(double v, int digits) {
  if (v == 0.0) return 2U;
  int e2 = 0;
  (void)std::frexp(v, &e2);
  const int e10 = (e2 < 0 ? -e2 : e2) * 30103 / 100000 + 2;
  return static_cast<std::size_t>(3 + digits + e10);
}

bool finite_pose(const Pose2& p) { return std::isfinite(p.x_m) && std::isfinite(p.y_m) && std::isfinite(p.heading_rad); }

// The reader takes at most 12 digits of seconds (detail::parse_stamp_us).
bool stamp_fits(std::int64_t stamp_us) {
  const std::uint64_t mag = stamp_us < 0 ? 0U - static_cast<std::uint64_t>(stamp_us) : static_cast<std::uint64_t>(stamp_us);
  return mag / 1000000U < 1000000000000U;
}

// The robot (odometry) and laser poses a laser line carries, each derived from the other
// when the record lacks it.
void line_poses(const LaserRecord& r, Pose2* robot, Pose2* laser_pose) {
  const ScanGeometry& g = r.scan.geometry;
  *robot = r.odom_pose;
  *laser_pose = r.laser_pose;
  if (!r.has_odom_pose) *robot = r.has_laser_pose ? r.laser_pose.compose(g.laser_in_base.inverse()) : Pose2{};
  if (!r.has_laser_pose) *laser_pose = robot->compose(g.laser_in_base);
}

// One line being formatted.
struct LineBuilder {
  std::string line;

  void num(double v) {
    line += detail::format_exact(v);
    line += ' ';
  }
  void numf(float v) {
    line += detail::format_exact(v);
    line += ' ';
  }
  void range(float r, float range_max_m) { numf(carmen_range(r, range_max_m)); }
  void pose(const Pose2& p) {
    num(p.x_m);
    num(p.y_m);
    num(p.heading_rad);
  }
  void trailer(std::int64_t ipc_us, std::int64_t logger_us) {
    line += detail::format_stamp(ipc_us);
    line += ' ';
    line += kHost;
    line += ' ';
    line += detail::format_stamp(logger_us);
    line += '\n';
  }
};

}  // namespace

std::string format_carmen_laser_line(const LaserRecord& r) {
  LineBuilder s;
  const RangeScan& scan = r.scan;
  const ScanGeometry& g = scan.geometry;
  Pose2 robot;
  Pose2 laser_pose;
  line_poses(r, &robot, &laser_pose);
  const std::uint32_t n = scan.beam_count <= capacity::kMaxBeams ? scan.beam_count : capacity::kMaxBeams;

  if (fits_flaser(r)) {
    s.line = "FLASER " + std::to_string(n) + " ";
    for (std::uint32_t i = 0; i < n; ++i) s.range(scan.ranges_m[i], g.range_max_m);
    s.pose(laser_pose);
    s.pose(robot);
  } else {
    s.line = "ROBOTLASER1 0 ";
    s.numf(g.angle_min_rad);
    s.numf(g.angle_increment_rad * static_cast<float>(n > 0U ? n - 1U : 0U));  // field of view
    s.numf(g.angle_increment_rad);
    s.numf(g.range_max_m);
    s.num(0.0);  // accuracy
    s.line += "0 " + std::to_string(n) + " ";  // remission_mode, num_readings
    for (std::uint32_t i = 0; i < n; ++i) s.range(scan.ranges_m[i], g.range_max_m);
    s.line += "0 ";  // num_remissions
    s.pose(laser_pose);
    s.pose(robot);
    s.line += "0 0 0 0 0 ";  // tv rv forward_safety_dist side_safety_dist turn_axis
  }
  s.trailer(r.stamp_us, r.logger_stamp_us);
  return std::move(s.line);
}

CarmenRoundTrip carmen_laser_round_trip(const LaserRecord& r, RangeScan* scan, Pose2* odom_pose) {
  const RangeScan& in = r.scan;
  const ScanGeometry& g = in.geometry;
  const std::uint32_t n = in.beam_count <= capacity::kMaxBeams ? in.beam_count : capacity::kMaxBeams;
  Pose2 robot;
  Pose2 laser_pose;
  line_poses(r, &robot, &laser_pose);
  if (n < 2U || !finite_pose(robot) || !finite_pose(laser_pose) || !stamp_fits(r.stamp_us) ||
      !stamp_fits(r.logger_stamp_us)) {
    return CarmenRoundTrip::kRefused;
  }
  const bool flaser = fits_flaser(r);
  const float fov = g.angle_increment_rad * static_cast<float>(n - 1U);
  if (!flaser && (!std::isfinite(g.angle_min_rad) || !std::isfinite(fov) || !std::isfinite(g.angle_increment_rad) ||
                  !std::isfinite(g.range_max_m) || !(g.range_max_m > 0.0F))) {
    return CarmenRoundTrip::kRefused;
  }
  // The line's length: keyword, counts, constants and trailer in 128 characters, then
  // every number at its widest.
  std::size_t width = 128U;
  for (std::uint32_t i = 0; i < n; ++i) width += exact_width_bound(carmen_range(in.ranges_m[i], g.range_max_m), 9) + 1U;
  const double poses[6] = {laser_pose.x_m, laser_pose.y_m, laser_pose.heading_rad,
                           robot.x_m,      robot.y_m,      robot.heading_rad};
  for (double v : poses) width += exact_width_bound(v, 17) + 1U;
  const float config[4] = {g.angle_min_rad, fov, g.angle_increment_rad, g.range_max_m};
  for (float v : config) width += flaser ? 0U : exact_width_bound(v, 9) + 1U;
  if (width > detail::kMaxLineBytes) return CarmenRoundTrip::kUnknown;

  const LogReaderOptions defaults;  // what parse_flaser / parse_robotlaser set
  for (std::uint32_t i = 0; i < n; ++i) scan->ranges_m[i] = carmen_range(in.ranges_m[i], g.range_max_m);
  scan->beam_count = n;
  scan->stamp_us = r.stamp_us;
  ScanGeometry& out = scan->geometry;
  out.range_min_m = 0.0F;
  if (flaser) {
    out.angle_min_rad = static_cast<float>(-kPi / 2.0);
    out.angle_increment_rad = static_cast<float>(kPi / static_cast<double>(n - 1U));
    out.range_max_m = defaults.front_laser_max_m > 0.0F ? defaults.front_laser_max_m : defaults.default_range_max_m;
    out.laser_in_base = Pose2{defaults.front_laser_offset_m, 0.0, 0.0};
  } else {
    out.angle_min_rad = g.angle_min_rad;
    out.angle_increment_rad = g.angle_increment_rad;
    out.range_max_m = g.range_max_m;
    out.laser_in_base = between(robot, laser_pose);
  }
  *odom_pose = robot;
  return CarmenRoundTrip::kDone;
}

struct CarmenWriter::Impl {
  AtomicOutputFile file;
  bool open = false;

  void put(const std::string& s) {
    if (open) std::fputs(s.c_str(), file.stream());
  }
};

CarmenWriter::CarmenWriter() : impl_(std::make_unique<Impl>()) {}
CarmenWriter::~CarmenWriter() = default;  // AtomicOutputFile removes an uncommitted temporary

bool CarmenWriter::open(const std::string& path, std::string* error) {
  impl_ = std::make_unique<Impl>();
  if (!impl_->file.open(path, error)) return false;
  impl_->open = true;
  impl_->put(
      "# CARMEN log written by sdpslam\n"
      "# message_name [message contents] ipc_timestamp ipc_hostname logger_timestamp\n"
      "# message formats defined: PARAM ODOM FLASER ROBOTLASER1\n"
      "# PARAM param_name param_value\n"
      "# ODOM x y theta tv rv accel\n"
      "# FLASER num_readings [range_readings] x y theta odom_x odom_y odom_theta\n"
      "# ROBOTLASER1 laser_type start_angle field_of_view angular_resolution maximum_range accuracy "
      "remission_mode num_readings [range_readings] num_remissions [remissions] laser_pose_x laser_pose_y "
      "laser_pose_theta robot_pose_x robot_pose_y robot_pose_theta laser_tv laser_rv forward_safety_dist "
      "side_safty_dist turn_axis\n");
  return true;
}

void CarmenWriter::comment(const std::string& text) { impl_->put("# " + one_line(text) + "\n"); }

void CarmenWriter::param(const std::string& name, const std::string& value) {
  impl_->put("PARAM " + one_line(name) + " " + one_line(value) + " 0.000000 " + kHost + " 0.000000\n");
}

void CarmenWriter::odom(const OdomRecord& r) {
  LineBuilder s;
  s.line = "ODOM ";
  s.pose(r.pose);
  s.num(r.tv_mps);
  s.num(r.rv_radps);
  s.num(0.0);  // accel
  s.trailer(r.stamp_us, r.logger_stamp_us);
  impl_->put(s.line);
}

void CarmenWriter::laser(const LaserRecord& r) { impl_->put(format_carmen_laser_line(r)); }

bool CarmenWriter::close(std::string* error) {
  Impl& s = *impl_;
  if (!s.open) {
    if (error != nullptr) *error = "CarmenWriter::close: no file is open";
    return false;
  }
  s.open = false;
  return s.file.commit(error);
}

}  // namespace sdpslam::io
