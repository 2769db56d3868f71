#pragma once

namespace sdpslam {
// Library version, "MAJOR.MINOR.PATCH".
const char* version_string();
}  // namespace sdpslam
