#include <string>

#include "sdpslam/io/log_reader.h"

namespace sdpslam::io {

const char* to_string(LogFormat f) {
  switch (f) {
    case LogFormat::kAuto: return "auto";
    case LogFormat::kCarmen: return "carmen";
    case LogFormat::kTinySlam: return "tinyslam";
    case LogFormat::kDpSlam: return "dpslam";
  }
  return "unknown";
}

std::string LogError::to_string() const { return file + ":" + std::to_string(line) + ": " + reason; }

}  // namespace sdpslam::io
