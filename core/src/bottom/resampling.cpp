#include "sdpslam/core/bottom/resampling.h"

#include <limits>

#include "sdpslam/core/det_math.h"

namespace sdpslam {

bool normalize_log_weights(const double* log_weights, std::size_t n, double* out_weights) {
  double max_lw = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < n; ++i) {
    const double lw = log_weights[i];
    if (lw == lw && lw > max_lw) max_lw = lw;  // NaN never wins
  }
  if (n == 0U) return false;
  if (max_lw == -std::numeric_limits<double>::infinity() || max_lw == std::numeric_limits<double>::infinity()) {
    // No usable information (or an infinite weight, which cannot be normalised): uniform.
    const double u = 1.0 / static_cast<double>(n);
    for (std::size_t i = 0; i < n; ++i) out_weights[i] = u;
    return false;
  }
  double sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double lw = log_weights[i];
    const double w = (lw == lw) ? det::exp(lw - max_lw) : 0.0;
    out_weights[i] = w;
    sum += w;
  }
  const double inv = 1.0 / sum;  // sum >= 1: the maximum contributes exactly 1
  for (std::size_t i = 0; i < n; ++i) out_weights[i] *= inv;
  return true;
}

double effective_sample_size(const double* weights, std::size_t n) {
  double sq = 0.0;
  for (std::size_t i = 0; i < n; ++i) sq += weights[i] * weights[i];
  return sq > 0.0 ? 1.0 / sq : 0.0;
}

void low_variance_resample(const double* weights, std::size_t n, Rng& rng, std::uint32_t* out_indices) {
  if (n == 0U) return;
  const double step = 1.0 / static_cast<double>(n);
  const double r = rng.uniform() * step;
  double c = weights[0];
  std::size_t i = 0U;
  for (std::size_t m = 0; m < n; ++m) {
    const double u = r + static_cast<double>(m) * step;
    while (u > c && i + 1U < n) {
      ++i;
      c += weights[i];
    }
    out_indices[m] = static_cast<std::uint32_t>(i);
  }
}

}  // namespace sdpslam
