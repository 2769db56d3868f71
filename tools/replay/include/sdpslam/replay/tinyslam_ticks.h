#pragma once
// Raw wheel-encoder counters of a tinySLAM log (openslam_tinyslam test/exp2.dat): one
// line per scan: 0-based field 0 = timestamp (µs), fields 2 and 3 = left / right
// cumulative ticks (the same fields io::LogReader and BreezySLAM's log reader use; field 1
// is not an encoder: in exp2.dat it stays near 14550 while the wheels turn). LogReader
// integrates the ticks into poses; replay needs the counters themselves.
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "sdpslam/replay/encoder_frames.h"

namespace sdpslam::replay {

struct TinySlamTicks {
  std::vector<TickSample> samples;  // the raw counters as logged (not made relative)
  std::vector<std::string> errors;  // "file:line: reason" for every skipped line
  std::int64_t first_left_raw = 0;  // the counters of the first good line
  std::int64_t first_right_raw = 0;
};

// Reads every line; a line with fewer than 4 fields, a non-integer field, a NUL byte, or
// a stamp not after the previous good one is skipped and listed in errors. Returns false iff the
// file cannot be opened or holds no good line (*error says why).
bool read_tinyslam_ticks(const std::string& path, TinySlamTicks* out, std::string* error);
// The same from an open stream read to its end (not closed); `name` stands for the file in
// messages.
bool read_tinyslam_ticks(std::FILE* stream, const std::string& name, TinySlamTicks* out, std::string* error);

}  // namespace sdpslam::replay
