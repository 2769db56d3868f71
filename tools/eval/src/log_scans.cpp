#include "sdpslam/eval/log_scans.h"

#include <algorithm>
#include <cstdint>

namespace sdpslam::eval {

bool read_log_scan_odometry(const std::string& log_path, std::vector<io::StampedPose>* scans, LogScansReport* report,
                            std::string* error) {
  LogScansReport rep;
  auto finish = [&](bool ok) {
    if (report != nullptr) *report = rep;
    return ok;
  };
  io::LogReader reader;
  if (!reader.open(log_path, io::LogReaderOptions{}, error)) return finish(false);
  struct Scan {
    io::StampedPose pose;
    std::int64_t line;
  };
  std::vector<Scan> found;
  bool synthetic_stamps = false;
  for (io::LogReader::Next n = reader.next(); n != io::LogReader::Next::kEnd; n = reader.next()) {
    if (n != io::LogReader::Next::kLaser) continue;
    const io::LaserRecord& r = reader.laser();
    ++rep.laser_count;
    if (!r.has_stamp) synthetic_stamps = true;
    if (!r.has_odom_pose) {
      ++rep.without_odometry_count;
      continue;
    }
    if (!found.empty() && r.stamp_us < found.back().pose.stamp_us) ++rep.out_of_order_count;
    found.push_back(Scan{io::StampedPose{r.stamp_us, r.odom_pose}, r.line});
  }
  rep.format = reader.format();
  rep.malformed_line_count = reader.error_count();
  if (!reader.errors().empty()) rep.first_malformed = reader.errors().front().to_string();
  if (synthetic_stamps) {
    if (error != nullptr) {
      *error = log_path + ": the log carries no real timestamps (" + io::to_string(rep.format) +
               " format); its scans cannot be matched to relations";
    }
    return finish(false);
  }
  if (found.empty()) {
    if (error != nullptr) {
      *error = log_path + ": none of its " + std::to_string(rep.laser_count) + " laser scans carries an odometry pose";
    }
    return finish(false);
  }
  std::stable_sort(found.begin(), found.end(),
                   [](const Scan& a, const Scan& b) { return a.pose.stamp_us < b.pose.stamp_us; });
  for (std::size_t i = 1; i < found.size(); ++i) {
    if (found[i].pose.stamp_us == found[i - 1].pose.stamp_us) {
      const std::int64_t a = std::min(found[i].line, found[i - 1].line);
      const std::int64_t b = std::max(found[i].line, found[i - 1].line);
      if (error != nullptr) {
        *error = log_path + ":" + std::to_string(b) + ": laser stamp " + io::format_stamp_us(found[i].pose.stamp_us) +
                 " repeats the scan of line " + std::to_string(a);
      }
      return finish(false);
    }
  }
  scans->clear();
  scans->reserve(found.size());
  for (const Scan& s : found) scans->push_back(s.pose);
  return finish(true);
}

}  // namespace sdpslam::eval
