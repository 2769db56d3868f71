#pragma once
// INI configuration of the bottom-level filter (tools/slam/default.ini documents every
// key). Sections and keys mirror DpSlamOptions; `[log] default_range_max_m` sets the
// log reader's no-return threshold for formats that do not carry one.
#include <string>

#include "sdpslam/core/dpslam_options.h"
#include "sdpslam/io/log_reader.h"

namespace sdpslam::slam {

struct SlamConfig {
  DpSlamOptions filter;
  io::LogReaderOptions log;
};

// Applies the keys of `path` on top of *config (keys not in the file keep their value).
// False iff the file cannot be read, a line is malformed, a section/key is unknown, a
// value is not a finite number of the right kind, or a value makes the options invalid;
// `error` is then "file:line: reason".
bool load_config_ini(const std::string& path, SlamConfig* config, std::string* error);

}  // namespace sdpslam::slam
