#pragma once
// CARMEN line parsing on already split fields (internal to sdpslam_io): the reader splits
// each line once into a reused vector; parse_carmen_line() is the standalone wrapper.
#include <string>
#include <string_view>
#include <vector>

#include "sdpslam/io/log_reader.h"

namespace sdpslam::io::detail {

// Same contract as parse_carmen_line() for a line that passed check_text() and was split
// by split_fields(). On failure the output records may be partly overwritten.
LogReader::Next parse_carmen_fields(const std::vector<std::string_view>& fields, const LogReaderOptions& options,
                                    LaserRecord* laser, OdomRecord* odom, ParamRecord* param, std::string* reason);

}  // namespace sdpslam::io::detail
