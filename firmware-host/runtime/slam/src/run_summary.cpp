// run_summary() (run_summary.h).
#include "sdpslam/slam/run_summary.h"

namespace sdpslam::slam {

RunSummary run_summary(const io::LogReader& reader, const std::string& log_path, std::uint64_t scans,
                       std::uint64_t processed, double wall_time_s) {
  RunSummary s;
  s.scans = scans;
  s.processed = processed;
  s.log_error_count = reader.error_count();
  s.log_errors = reader.errors();
  s.odometry_reversals_repaired = reader.odometry_reversals_repaired();
  s.odometry_jumps_removed = reader.odometry_jumps_removed();
  s.scans_stamped_backwards = reader.scans_stamped_backwards();
  if (reader.scans_stamped_backwards() > 0U) {
    s.first_backwards_at = log_path + ":" + std::to_string(reader.first_backwards_line());
  }
  s.wall_time_s = wall_time_s;
  return s;
}

}  // namespace sdpslam::slam
