// Trajectory files (see trajectory_io.h).
//
// Number formats, chosen so that output is byte-identical for identical poses (glibc's
// printf rounds exactly) and fine enough to be lossless for evaluation:
//  - stamps: integer microseconds printed as "sec.uuuuuu" with integer arithmetic only;
//  - x, y: "%.6f" (1 µm);
//  - theta: "%.9f" (1 nrad; at 100 m lever arm that is 0.1 µm, below the x/y digit);
//  - TUM quaternion components: "%.9f".
#include "sdpslam/io/trajectory_io.h"

#include <algorithm>
#include <cerrno>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "sdpslam/io/atomic_file.h"
#include "sdpslam/io/text_table.h"

namespace sdpslam::io {
namespace {

constexpr std::int64_t kMicrosPerSecond = 1000000;

bool parse_double(const std::string& token, double* value) {
  if (token.empty()) return false;
  const char* begin = token.c_str();
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(begin, &end);
  if (end != begin + token.size() || errno == ERANGE || !std::isfinite(v)) return false;
  *value = v;
  return true;
}

bool all_finite(const Pose2& p) {
  return std::isfinite(p.x_m) && std::isfinite(p.y_m) && std::isfinite(p.heading_rad);
}

// Shared body of the two writers: validates every pose first so that nothing is written
// (and the old file stays) when the input is bad.
template <typename FormatLine>
bool write_lines(const std::string& path, const std::vector<StampedPose>& poses, const char* header,
                 FormatLine format_line, std::string* error) {
  for (std::size_t i = 0; i < poses.size(); ++i) {
    if (!all_finite(poses[i].pose)) {
      if (error != nullptr) {
        *error = "cannot write '" + path + "': pose " + std::to_string(i) + " (stamp " +
                 format_stamp_us(poses[i].stamp_us) + ") is not finite";
      }
      return false;
    }
  }
  AtomicOutputFile out;
  if (!out.open(path, error)) return false;
  std::fputs(header, out.stream());
  char line[256];
  for (const StampedPose& sp : poses) {
    format_line(sp, line, sizeof line);
    std::fputs(line, out.stream());
  }
  return out.commit(error);
}

}  // namespace

std::string format_stamp_us(std::int64_t stamp_us) {
  // Magnitude in unsigned arithmetic so that INT64_MIN is representable.
  const bool negative = stamp_us < 0;
  const std::uint64_t magnitude =
      negative ? static_cast<std::uint64_t>(-(stamp_us + 1)) + 1U : static_cast<std::uint64_t>(stamp_us);
  char buf[40];
  std::snprintf(buf, sizeof buf, "%s%" PRIu64 ".%06" PRIu64, negative ? "-" : "",
                magnitude / static_cast<std::uint64_t>(kMicrosPerSecond),
                magnitude % static_cast<std::uint64_t>(kMicrosPerSecond));
  return buf;
}

bool parse_stamp_us(const std::string& text, std::int64_t* stamp_us) {
  // Grammar: [+-] digits [ '.' digits ] | [+-] '.' digits. No exponent, no spaces.
  std::size_t i = 0;
  bool negative = false;
  if (i < text.size() && (text[i] == '+' || text[i] == '-')) {
    negative = text[i] == '-';
    ++i;
  }
  // Accumulate the magnitude in microseconds as unsigned; reject overflow of int64.
  const std::uint64_t limit = negative ? static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()) + 1U
                                       : static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max());
  std::uint64_t seconds = 0;
  std::size_t int_digits = 0;
  for (; i < text.size() && text[i] >= '0' && text[i] <= '9'; ++i, ++int_digits) {
    const auto d = static_cast<std::uint64_t>(text[i] - '0');
    if (seconds > (limit / static_cast<std::uint64_t>(kMicrosPerSecond) - d) / 10U) return false;
    seconds = seconds * 10U + d;
  }
  std::uint64_t micros = 0;
  std::size_t frac_digits = 0;
  bool round_up = false;
  if (i < text.size() && text[i] == '.') {
    ++i;
    for (; i < text.size() && text[i] >= '0' && text[i] <= '9'; ++i, ++frac_digits) {
      if (frac_digits < 6) {
        micros = micros * 10U + static_cast<std::uint64_t>(text[i] - '0');
      } else if (frac_digits == 6) {
        round_up = text[i] >= '5';  // half away from zero: only the 7th digit decides
      }
    }
  }
  if (i != text.size() || int_digits + frac_digits == 0) return false;
  for (std::size_t k = frac_digits; k < 6; ++k) micros *= 10U;
  if (round_up) ++micros;
  const std::uint64_t total = seconds * static_cast<std::uint64_t>(kMicrosPerSecond) + micros;
  if (total > limit) return false;
  if (negative) {
    *stamp_us = total == 0 ? 0 : -static_cast<std::int64_t>(total - 1U) - 1;
  } else {
    *stamp_us = static_cast<std::int64_t>(total);
  }
  return true;
}

bool write_trajectory(const std::string& path, const std::vector<StampedPose>& poses, std::string* error) {
  return write_lines(
      path, poses, "# t x y theta (s, m, m, rad)\n",
      [](const StampedPose& sp, char* line, std::size_t size) {
        std::snprintf(line, size, "%s %.6f %.6f %.9f\n", format_stamp_us(sp.stamp_us).c_str(), sp.pose.x_m,
                      sp.pose.y_m, sp.pose.heading_rad);
      },
      error);
}

bool write_trajectory_tum(const std::string& path, const std::vector<StampedPose>& poses, std::string* error) {
  return write_lines(
      path, poses, "# timestamp tx ty tz qx qy qz qw\n",
      [](const StampedPose& sp, char* line, std::size_t size) {
        // Rotation about z by theta: q = (0, 0, sin(theta/2), cos(theta/2)).
        const double half = 0.5 * sp.pose.heading_rad;
        std::snprintf(line, size, "%s %.6f %.6f 0.000000 0.000000000 0.000000000 %.9f %.9f\n",
                      format_stamp_us(sp.stamp_us).c_str(), sp.pose.x_m, sp.pose.y_m, std::sin(half),
                      std::cos(half));
      },
      error);
}

bool read_trajectory(const std::string& path, std::vector<StampedPose>* poses, std::string* error) {
  std::ifstream in;
  return open_for_reading(path, &in, error) && read_trajectory(in, path, poses, error);
}

bool read_trajectory(std::istream& in, const std::string& path, std::vector<StampedPose>* poses, std::string* error) {
  std::vector<StampedPose> result;
  std::size_t columns_seen = 0;  // the first data line fixes the format for the file
  const bool read = read_table(in, path, [&](const std::vector<std::string>& tokens, std::int64_t) -> std::string {
    if (tokens.size() != 4 && tokens.size() != 8) {
      return "expected 4 columns (t x y theta) or 8 (TUM: t x y z qx qy qz qw), found " +
             std::to_string(tokens.size());
    }
    if (columns_seen == 0) columns_seen = tokens.size();
    if (tokens.size() != columns_seen) {
      return "found " + std::to_string(tokens.size()) + " columns where earlier lines have " +
             std::to_string(columns_seen);
    }
    StampedPose sp;
    if (!parse_stamp_us(tokens[0], &sp.stamp_us)) return "bad timestamp '" + tokens[0] + "'";
    double v[7] = {};
    for (std::size_t k = 1; k < tokens.size(); ++k) {
      if (!parse_double(tokens[k], &v[k - 1])) {
        return "column " + std::to_string(k + 1) + " '" + tokens[k] + "' is not a finite number";
      }
    }
    sp.pose.x_m = v[0];
    sp.pose.y_m = v[1];
    if (tokens.size() == 4) {
      sp.pose.heading_rad = normalize_angle_rad(v[2]);
    } else {
      double qx = v[3];
      double qy = v[4];
      double qz = v[5];
      double qw = v[6];
      const double scale = std::max({std::fabs(qx), std::fabs(qy), std::fabs(qz), std::fabs(qw)});
      if (!(scale > 0.0)) return "zero quaternion";
      // The yaw does not change with the quaternion's scale: huge or tiny components are
      // brought near 1 first, so that their squares neither overflow nor vanish.
      if (scale > 1e100 || scale < 1e-100) {
        qx /= scale;
        qy /= scale;
        qz /= scale;
        qw /= scale;
      }
      const double norm2 = qx * qx + qy * qy + qz * qz + qw * qw;
      // Yaw of a general quaternion (z-y-x convention); exact for yaw-only ones. atan2
      // gives -pi for a negative zero sine: wrapped to (-pi, pi] like the other format.
      sp.pose.heading_rad =
          normalize_angle_rad(std::atan2(2.0 * (qw * qz + qx * qy), norm2 - 2.0 * (qy * qy + qz * qz)));
    }
    result.push_back(sp);
    return std::string();
  }, error);
  if (!read) return false;
  *poses = std::move(result);
  return true;
}

}  // namespace sdpslam::io
