// libFuzzer: the trajectory reader (io::read_trajectory: "t x y theta" and TUM) over
// arbitrary file contents.
// Checks beyond the sanitizers: every pose read is finite with its heading in (-pi, pi]
// and its stamp prints and parses back to itself; a refusal names "fuzz.txt:N: reason"
// with N a line of the input, leaves the output untouched, and is the first problem (the
// first N - 1 lines are accepted).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "sdpslam/io/trajectory_io.h"
#include "fuzz_text.h"

namespace {

using sdpslam::test::fuzz::check;
using sdpslam::test::fuzz::error_line;
using sdpslam::test::fuzz::first_lines;
using sdpslam::test::fuzz::line_count;

const char* const kName = "fuzz.txt";
constexpr double kPi = 3.14159265358979323846;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::istringstream in(text);
  std::vector<sdpslam::io::StampedPose> poses(1);  // a refusal must leave it as it was
  std::string error;
  if (sdpslam::io::read_trajectory(in, kName, &poses, &error)) {
    check(poses.size() <= line_count(text));
    for (const sdpslam::io::StampedPose& p : poses) {
      check(std::isfinite(p.pose.x_m) && std::isfinite(p.pose.y_m));
      check(p.pose.heading_rad > -kPi && p.pose.heading_rad <= kPi);
      std::int64_t back = 0;
      check(sdpslam::io::parse_stamp_us(sdpslam::io::format_stamp_us(p.stamp_us), &back) && back == p.stamp_us);
    }
  } else {
    check(poses.size() == 1U);
    const std::size_t n = error_line(error, kName);
    check(n >= 1U && n <= line_count(text));
    std::istringstream before(first_lines(text, n - 1U));
    std::vector<sdpslam::io::StampedPose> kept;
    std::string again;
    check(sdpslam::io::read_trajectory(before, kName, &kept, &again));
  }
  return 0;
}
