#include "sdpslam/core/version.h"

namespace sdpslam {
const char* version_string() { return "0.1.0"; }
}  // namespace sdpslam
