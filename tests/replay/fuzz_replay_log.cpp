// libFuzzer: the replay log loader (replay::load_replay_log: format detection and every
// log format through io::LogReader, .gz included, then the odometry track replay uses)
// over arbitrary file contents, written to a scratch file.
// Checks beyond the sanitizers: an accepted log has scans or odometry, a detected format,
// scans with at most kMaxBeams beams and finite odometry poses; the odometry track comes
// from the laser records only when the log has no ODOM line, and then has at most one
// pose per scan; every kept error names the file; a refusal names the file.
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "sdpslam/replay/replay_log.h"
#include "fuzz_text.h"

namespace {

using sdpslam::test::fuzz::check;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = [] {
    const char* tmp = std::getenv("TMPDIR");
    return std::string(tmp != nullptr ? tmp : "/tmp") + "/fuzz_replay_log." + std::to_string(::getpid()) + ".log";
  }();
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) return 0;
  std::fwrite(data, 1, size, f);
  std::fclose(f);
  sdpslam::replay::ReplayLog log;
  std::string error;
  if (sdpslam::replay::load_replay_log(path, &log, &error)) {
    check(!log.scans.empty() || !log.odometry.empty());
    check(log.format != sdpslam::io::LogFormat::kAuto);
    for (const sdpslam::replay::ReplayScan& s : log.scans) {
      check(s.scan.beam_count <= sdpslam::capacity::kMaxBeams);
    }
    for (const sdpslam::replay::StampedPose& p : log.odometry) {
      check(std::isfinite(p.pose.x_m) && std::isfinite(p.pose.y_m) && std::isfinite(p.pose.heading_rad));
    }
    if (log.odometry_from_laser_records) check(log.odometry.size() <= log.scans.size());
    for (const std::string& e : log.errors) check(e.compare(0, path.size(), path) == 0);
  } else {
    check(error.compare(0, path.size(), path) == 0);
  }
  std::remove(path.c_str());
  return 0;
}
