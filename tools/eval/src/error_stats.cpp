#include "sdpslam/eval/error_stats.h"

#include <cmath>

namespace sdpslam::eval {

ErrorStats summarize(const std::vector<double>& values) {
  ErrorStats s;
  s.count = values.size();
  if (values.empty()) return s;
  double sum = 0.0;
  s.max = values.front();
  for (double v : values) {
    sum += v;
    if (v > s.max) s.max = v;
  }
  s.mean = sum / static_cast<double>(values.size());
  if (values.size() >= 2) {
    double sq = 0.0;
    for (double v : values) sq += (v - s.mean) * (v - s.mean);
    s.std_dev = std::sqrt(sq / static_cast<double>(values.size() - 1));
  }
  return s;
}

}  // namespace sdpslam::eval
