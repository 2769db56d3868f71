#pragma once
// Helpers shared by the simulator tests.
#include <cstdint>
#include <string>
#include <vector>

#include "sdpslam/sim/simulator.h"

namespace sdpslam::test {

// Collects everything a simulation emits, plus a running FNV-1a hash of its bytes.
class RecordingSink : public sim::SimulationSink {
 public:
  void on_odom(const io::OdomRecord& r) override;
  void on_laser(const io::LaserRecord& r, const Pose2& true_pose) override;

  std::vector<io::OdomRecord> odoms;
  std::vector<Pose2> truth;       // ground truth at each scan
  std::vector<Pose2> odom_at_scan;
  std::vector<std::int64_t> scan_stamps_us;
  std::vector<std::vector<float>> ranges;
  std::uint64_t hash = 1469598103934665603ULL;
  bool keep_ranges = false;

 private:
  void mix(const void* data, std::size_t n);
};

// Options for tests that only look at the robot and odometry: a 2-beam laser (cheap).
sim::SimulationOptions cheap_laser_options();

// Position RMSE of `est` against `ref` after the best 2D rigid alignment of est onto ref
// (closed form, Horn 1987 reduced to SE(2)).
double aligned_rmse_m(const std::vector<Pose2>& est, const std::vector<Pose2>& ref);
double unaligned_rmse_m(const std::vector<Pose2>& est, const std::vector<Pose2>& ref);

std::string read_file_bytes(const std::string& path);

}  // namespace sdpslam::test
