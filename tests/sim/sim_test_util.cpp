#include "sim_test_util.h"

#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

namespace sdpslam::test {

void RecordingSink::mix(const void* data, std::size_t n) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < n; ++i) {
    hash ^= p[i];
    hash *= 1099511628211ULL;
  }
}

void RecordingSink::on_odom(const io::OdomRecord& r) {
  odoms.push_back(r);
  mix(&r.stamp_us, sizeof r.stamp_us);
  mix(&r.pose, sizeof r.pose);
  mix(&r.tv_mps, sizeof r.tv_mps);
  mix(&r.rv_radps, sizeof r.rv_radps);
}

void RecordingSink::on_laser(const io::LaserRecord& r, const Pose2& true_pose) {
  truth.push_back(true_pose);
  odom_at_scan.push_back(r.odom_pose);
  scan_stamps_us.push_back(r.stamp_us);
  if (keep_ranges) ranges.emplace_back(r.scan.ranges_m, r.scan.ranges_m + r.scan.beam_count);
  mix(&r.stamp_us, sizeof r.stamp_us);
  mix(&true_pose, sizeof true_pose);
  mix(&r.odom_pose, sizeof r.odom_pose);
  mix(r.scan.ranges_m, sizeof(float) * r.scan.beam_count);
}

sim::SimulationOptions cheap_laser_options() {
  sim::SimulationOptions o;
  o.laser.beam_count = 2;
  return o;
}

double unaligned_rmse_m(const std::vector<Pose2>& est, const std::vector<Pose2>& ref) {
  const std::size_t n = std::min(est.size(), ref.size());
  double sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    sum += (est[i].x_m - ref[i].x_m) * (est[i].x_m - ref[i].x_m) + (est[i].y_m - ref[i].y_m) * (est[i].y_m - ref[i].y_m);
  }
  return n == 0 ? 0.0 : std::sqrt(sum / static_cast<double>(n));
}

double aligned_rmse_m(const std::vector<Pose2>& est, const std::vector<Pose2>& ref) {
  const std::size_t n = std::min(est.size(), ref.size());
  if (n == 0) return 0.0;
  double ex = 0, ey = 0, rx = 0, ry = 0;
  for (std::size_t i = 0; i < n; ++i) {
    ex += est[i].x_m;
    ey += est[i].y_m;
    rx += ref[i].x_m;
    ry += ref[i].y_m;
  }
  const double dn = static_cast<double>(n);
  ex /= dn;
  ey /= dn;
  rx /= dn;
  ry /= dn;
  double sxx = 0, sxy = 0, syx = 0, syy = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double ax = est[i].x_m - ex, ay = est[i].y_m - ey;
    const double bx = ref[i].x_m - rx, by = ref[i].y_m - ry;
    sxx += ax * bx;
    sxy += ax * by;
    syx += ay * bx;
    syy += ay * by;
  }
  const double theta = std::atan2(sxy - syx, sxx + syy);
  const double c = std::cos(theta), s = std::sin(theta);
  double sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double ax = est[i].x_m - ex, ay = est[i].y_m - ey;
    const double px = c * ax - s * ay + rx;
    const double py = s * ax + c * ay + ry;
    sum += (px - ref[i].x_m) * (px - ref[i].x_m) + (py - ref[i].y_m) * (py - ref[i].y_m);
  }
  return std::sqrt(sum / dn);
}

std::string read_file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace sdpslam::test
