#pragma once
// Summary statistics of a set of errors: mean and sample standard deviation, as the
// relations metric reports them (Kümmerle et al. 2009, §VI).
#include <cstddef>
#include <vector>

namespace sdpslam::eval {

struct ErrorStats {
  std::size_t count = 0;
  double mean = 0.0;
  double std_dev = 0.0;  // sample standard deviation (n - 1); 0 when count < 2
  double max = 0.0;
};

// Two-pass mean and sample standard deviation, summed in input order (deterministic).
ErrorStats summarize(const std::vector<double>& values);

}  // namespace sdpslam::eval
