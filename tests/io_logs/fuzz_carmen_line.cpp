// libFuzzer: parse_carmen_line on arbitrary bytes must never crash, leak or hit UB, and a
// line it accepts must be consistent (beam count within capacity, finite ranges).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "sdpslam/io/log_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string line(reinterpret_cast<const char*>(data), size);
  sdpslam::io::LaserRecord laser;
  sdpslam::io::OdomRecord odom;
  sdpslam::io::ParamRecord param;
  std::string reason;
  const auto kind = sdpslam::io::parse_carmen_line(line, sdpslam::io::LogReaderOptions{}, &laser, &odom, &param, &reason);
  if (kind == sdpslam::io::LogReader::Next::kLaser) {
    if (!reason.empty() || laser.scan.beam_count < 2U || laser.scan.beam_count > sdpslam::capacity::kMaxBeams) std::abort();
    for (std::uint32_t i = 0; i < laser.scan.beam_count; ++i) {
      if (!std::isfinite(laser.scan.ranges_m[i]) || laser.scan.ranges_m[i] < 0.0F) std::abort();
    }
  }
  if (kind == sdpslam::io::LogReader::Next::kOdom && !std::isfinite(odom.pose.x_m)) std::abort();
  return 0;
}
