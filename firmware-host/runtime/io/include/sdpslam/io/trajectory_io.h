#pragma once
// Trajectory files: one pose per laser scan.
//  - "t x y theta" (the project's own): t in seconds printed to the microsecond from the
//    integer stamp, x y in metres, theta in radians.
//  - TUM: "t x y z qx qy qz qw" with z = 0 and a yaw-only quaternion.
#include <cstdint>
#include <istream>
#include <string>
#include <vector>

#include "sdpslam/core/pose2.h"

namespace sdpslam::io {

using sdpslam::StampedPose;  // core/pose2.h

// Formats a microsecond stamp as seconds with exactly six decimals ("976052905.167303"),
// exactly, without passing through floating point.
std::string format_stamp_us(std::int64_t stamp_us);
// Parses a decimal seconds string into microseconds exactly (up to 6 decimals, more are
// rounded half away from zero); false iff it is not a number.
bool parse_stamp_us(const std::string& text, std::int64_t* stamp_us);

bool write_trajectory(const std::string& path, const std::vector<StampedPose>& poses, std::string* error);
bool write_trajectory_tum(const std::string& path, const std::vector<StampedPose>& poses, std::string* error);
// Reads the "t x y theta" format (and TUM, detected by column count). Lines starting
// with '#' are comments. False iff the file cannot be read or a line is malformed
// (`error` says file:line: reason).
bool read_trajectory(const std::string& path, std::vector<StampedPose>* poses, std::string* error);
// The same from a stream read to its end; `name` stands for the file in messages.
bool read_trajectory(std::istream& in, const std::string& name, std::vector<StampedPose>* poses, std::string* error);

}  // namespace sdpslam::io
