#pragma once
// Timing and number formatting shared by the offline runners (run_offline.cpp,
// run_sdp.cpp): per-scan CPU time of this thread, which stays meaningful on a loaded
// machine where wall time does not, and the percentiles and fixed-point text of
// stats.json. Host-side only (POSIX clock), never in core/.
#include <sys/resource.h>
#include <time.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

namespace sdpslam::slam::detail {

// CPU time consumed by the calling thread, in milliseconds.
inline double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

// User + system CPU seconds of a getrusage() result: stats.json's "cpu_time_s".
inline double rusage_cpu_s(const rusage& ru) {
  return static_cast<double>(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) +
         static_cast<double>(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec) * 1e-6;
}

// Nearest-rank percentile (q in [0, 1]; 1 = maximum); 0 for an empty series.
inline double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const auto idx = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1U) + 0.5);
  return v[std::min(idx, v.size() - 1U)];
}

// One number through a printf format (e.g. "%.3f").
inline std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

}  // namespace sdpslam::slam::detail
