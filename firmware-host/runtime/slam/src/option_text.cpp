#include "sdpslam/slam/option_text.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace sdpslam::slam {

bool parse_real_text(const char* text, double* out) {
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(text, &end);
  if (end == text || *end != '\0' || errno == ERANGE || !std::isfinite(v)) return false;
  *out = v;
  return true;
}

bool parse_u32_text(const char* text, std::uint32_t* out) {
  if (*text < '0' || *text > '9') return false;  // no sign, no blank
  errno = 0;
  char* end = nullptr;
  const unsigned long long v = std::strtoull(text, &end, 10);
  if (end == text || *end != '\0' || errno == ERANGE || v > 0xFFFFFFFFULL) return false;
  *out = static_cast<std::uint32_t>(v);
  return true;
}

bool parse_bool_text(const char* text, bool* out) {
  static const char* const kTrue[] = {"true", "yes", "on", "1"};
  static const char* const kFalse[] = {"false", "no", "off", "0"};
  for (const char* t : kTrue) {
    if (std::strcmp(text, t) == 0) {
      *out = true;
      return true;
    }
  }
  for (const char* f : kFalse) {
    if (std::strcmp(text, f) == 0) {
      *out = false;
      return true;
    }
  }
  return false;
}

std::string real_text(double v) {
  char buf[40];
  if (v == std::trunc(v) && std::fabs(v) < 1.0e15) {  // whole numbers in full, not as 1e+01
    std::snprintf(buf, sizeof buf, "%.0f", v);
    return buf;
  }
  for (int precision = 1; precision <= 17; ++precision) {
    std::snprintf(buf, sizeof buf, "%.*g", precision, v);
    if (std::strtod(buf, nullptr) == v) break;
  }
  return buf;
}

std::string ini_option_line(const char* key, const std::string& value, const char* unit, const std::string& range,
                            const char* doc) {
  std::string line = std::string(key) + " = " + value;
  if (line.size() < 40U) line.resize(40U, ' ');
  return line + " ; " + (unit[0] != '\0' ? std::string(unit) + ", " : std::string()) + range + ": " + doc + "\n";
}

}  // namespace sdpslam::slam
