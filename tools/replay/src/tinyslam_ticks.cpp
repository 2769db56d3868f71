#include "sdpslam/replay/tinyslam_ticks.h"

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace sdpslam::replay {

namespace {

// Parses the next whitespace-separated integer at *p. False iff there is none or it is
// not an integer (a decimal point, garbage, overflow).
bool next_int(const char** p, long long* v) {
  const char* s = *p;
  while (*s == ' ' || *s == '\t') ++s;
  if (*s == '\0' || *s == '\n' || *s == '\r') return false;
  char* end = nullptr;
  errno = 0;
  const long long x = std::strtoll(s, &end, 10);
  if (end == s || errno == ERANGE) return false;
  if (*end != ' ' && *end != '\t' && *end != '\n' && *end != '\r' && *end != '\0') return false;
  *v = x;
  *p = end;
  return true;
}

}  // namespace

bool read_tinyslam_ticks(const std::string& path, TinySlamTicks* out, std::string* error) {
  *out = TinySlamTicks{};
  std::FILE* f = std::fopen(path.c_str(), "r");
  if (f == nullptr) {
    *error = path + ": cannot open: " + std::strerror(errno);
    return false;
  }
  const bool ok = read_tinyslam_ticks(f, path, out, error);
  std::fclose(f);
  return ok;
}

bool read_tinyslam_ticks(std::FILE* f, const std::string& path, TinySlamTicks* out, std::string* error) {
  *out = TinySlamTicks{};
  // Lines carry ~700 numbers; only the first three are needed, the rest is skipped.
  std::string line;
  long long line_no = 0;
  int c = 0;
  while (c != EOF) {
    line.clear();
    while ((c = std::fgetc(f)) != EOF && c != '\n') line.push_back(static_cast<char>(c));
    if (c == EOF && line.empty()) break;
    ++line_no;
    const char* p = line.c_str();
    while (*p == ' ' || *p == '\t') ++p;
    const std::string where = path + ":" + std::to_string(line_no) + ": ";
    // The parser sees the text up to a NUL byte only: such a line is not what it looks like.
    if (line.find('\0') != std::string::npos) {
      out->errors.push_back(where + "NUL byte in the line (not a text file?)");
      continue;
    }
    if (*p == '\0' || *p == '\r' || *p == '#') continue;
    long long stamp = 0, unused = 0, left = 0, right = 0;
    if (!next_int(&p, &stamp) || !next_int(&p, &unused) || !next_int(&p, &left) || !next_int(&p, &right)) {
      out->errors.push_back(where + "fields 1, 3, 4 (stamp us, left ticks, right ticks) are not integers");
      continue;
    }
    if (!out->samples.empty() && stamp <= out->samples.back().stamp_us) {
      out->errors.push_back(where + "timestamp " + std::to_string(stamp) + " not after the previous line's");
      continue;
    }
    if (out->samples.empty()) {
      out->first_left_raw = left;
      out->first_right_raw = right;
    }
    out->samples.push_back(TickSample{stamp, left, right});
  }
  if (std::ferror(f) != 0) {
    *error = path + ": read error";
    return false;
  }
  if (out->samples.empty()) {
    *error = path + ": no line with a stamp and two tick counters";
    return false;
  }
  return true;
}

}  // namespace sdpslam::replay
