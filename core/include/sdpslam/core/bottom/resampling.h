#pragma once
// Weight normalisation and low-variance (systematic) resampling (Thrun, Burgard & Fox,
// "Probabilistic Robotics" 2005, Table 4.4), used by the bottom-level filter after
// weighting (paper §III, Algorithm 1 line 3: "Then, the resampling is made").
//
// Weights are kept in the log domain (a scan of 180 beams multiplies 180 likelihoods,
// far below the smallest double); normalisation subtracts the maximum before
// exponentiating, so at least one weight is exactly 1 before the division and nothing
// underflows to an all-zero set. Resampling happens only when the effective sample size
// N_eff = 1 / Σ w_i² drops below threshold·N (Doucet et al. 2000; GMapping), which keeps
// diversity when the weights carry little information.
// Cost: O(N); no heap; deterministic (det_math exp, one uniform draw per resampling).
#include <cstddef>
#include <cstdint>

#include "sdpslam/core/rng.h"

namespace sdpslam {

// Converts log weights to normalised linear weights (Σ = 1) in `out_weights`. Entries
// that are -inf or NaN get weight 0. If every entry is -inf/NaN the weights become
// uniform (returns false, so callers can count it); true otherwise.
bool normalize_log_weights(const double* log_weights, std::size_t n, double* out_weights);

// 1 / Σ w_i² for normalised weights: N for uniform weights, 1 when one particle has it all.
double effective_sample_size(const double* weights, std::size_t n);

// Low-variance resampling: draws `n` indices into `out_indices` (non-decreasing) with one
// uniform offset r ∈ [0, 1/n): index i is chosen floor or ceil of n·w_i times.
// `weights` must be normalised. O(n).
void low_variance_resample(const double* weights, std::size_t n, Rng& rng, std::uint32_t* out_indices);

}  // namespace sdpslam
