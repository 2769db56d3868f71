#include "top/top_particles.h"

#include "sdpslam/core/capacities.h"
#include "sdpslam/core/det_math.h"

namespace sdpslam {

TopParticleOptions TopParticleOptions::from(const SdpOptions& sdp) {
  TopParticleOptions o;
  o.particles = sdp.top_particles;
  o.max_levels = sdp.max_levels;
  o.topology = sdp.topology;
  o.segslam_window = sdp.segslam_window;
  o.elite_fraction = sdp.elite_fraction;
  o.worst_fraction = sdp.worst_fraction;
  o.diversify_levels = sdp.diversify_levels;
  o.follow_best_fraction = sdp.follow_best_fraction;
  o.prior_error_m = sdp.prior_error_m;
  return o;
}

bool TopParticleOptions::valid() const {
  const auto fraction = [](double f) { return f >= 0.0 && f <= 1.0; };
  return particles >= 1U && particles <= capacity::kMaxTopParticles && max_levels >= 2U &&
         max_levels <= capacity::kMaxPgsLevels && segslam_window >= 1U && fraction(elite_fraction) &&
         fraction(worst_fraction) && elite_fraction + worst_fraction <= 1.0 && diversify_levels >= 1U &&
         fraction(follow_best_fraction) && prior_error_m > 0.0 && prior_error_m < 1.0e300 &&
         (topology == TopologyMode::kSdp || topology == TopologyMode::kSegSlam);
}

std::size_t TopParticles::required_bytes(const TopParticleOptions& o) {
  if (!o.valid()) return 0U;
  const std::size_t t = o.particles;
  return Arena::bytes_for<std::uint16_t>(t * o.max_levels) + Arena::bytes_for<double>(t) +
         Arena::bytes_for<std::uint8_t>(t) + Arena::bytes_for<std::uint32_t>(t);
}

bool TopParticles::init(const TopParticleOptions& options, Arena& arena) {
  choices_ = nullptr;
  if (!options.valid() || arena.available_bytes() < required_bytes(options)) return false;
  const std::size_t t = options.particles;
  std::uint16_t* choices = arena.allocate_array<std::uint16_t>(t * options.max_levels);
  error_ = arena.allocate_array<double>(t);
  has_error_ = arena.allocate_array<std::uint8_t>(t);
  order_ = arena.allocate_array<std::uint32_t>(t);
  if (choices == nullptr || error_ == nullptr || has_error_ == nullptr || order_ == nullptr) return false;
  options_ = options;
  choices_ = choices;
  for (std::uint32_t p = 0; p < options.particles; ++p) {
    error_[p] = 0.0;
    has_error_[p] = 0U;
    order_[p] = p;
  }
  for (std::size_t i = 0; i < t * options.max_levels; ++i) choices_[i] = 0U;
  return true;
}

void TopParticles::error_summary(double* mean_m, double* std_m, std::uint32_t* count) const {
  double s = 0.0;
  double q = 0.0;
  std::uint32_t c = 0U;
  for (std::uint32_t p = 0; p < options_.particles; ++p) {
    if (has_error_[p] == 0U) continue;
    s += error_[p];
    q += error_[p] * error_[p];
    ++c;
  }
  const double m = c > 0U ? s / static_cast<double>(c) : 0.0;
  const double v = c > 0U ? q / static_cast<double>(c) - m * m : 0.0;
  if (mean_m != nullptr) *mean_m = m;
  if (std_m != nullptr) *std_m = v > 0.0 ? det::sqrt(v) : 0.0;
  if (count != nullptr) *count = c;
}

std::uint32_t TopParticles::rank() {
  const std::uint32_t n = options_.particles;
  for (std::uint32_t i = 0; i < n; ++i) order_[i] = i;
  // Insertion sort: stable, deterministic, T <= capacity::kMaxTopParticles.
  for (std::uint32_t i = 1; i < n; ++i) {
    const std::uint32_t v = order_[i];
    const double kv = key(v);
    std::uint32_t j = i;
    while (j > 0U && key(order_[j - 1U]) > kv) {
      order_[j] = order_[j - 1U];
      --j;
    }
    order_[j] = v;
  }
  return order_[0];
}

void TopParticles::resample_and_diversify(const SegmentGraph& graph, Rng& rng) {
  const std::uint32_t first = graph.first_live_level();
  const std::uint32_t end = graph.level_end();
  if (end <= first) return;
  const std::uint32_t n = options_.particles;
  const std::uint32_t L = options_.max_levels;
  const std::uint32_t best = rank();
  std::uint32_t elite = static_cast<std::uint32_t>(options_.elite_fraction * static_cast<double>(n));
  const std::uint32_t worst = static_cast<std::uint32_t>(options_.worst_fraction * static_cast<double>(n));
  if (elite > n) elite = n;
  // Worst ranks become copies of the elite (of the best when there is no elite).
  for (std::uint32_t k = 0; k < worst && k < n - elite; ++k) {
    const std::uint32_t dst = order_[n - 1U - k];
    const std::uint32_t src = order_[elite > 0U ? k % elite : 0U];
    if (dst == src) continue;
    for (std::uint32_t s = 0; s < L; ++s) choices_[dst * L + s] = choices_[src * L + s];
    error_[dst] = error_[src];
    has_error_[dst] = has_error_[src];
  }
  // Everyone but the elite diversifies.
  const bool segslam = options_.topology == TopologyMode::kSegSlam;
  std::uint32_t lo = first;
  if (segslam && end - first > options_.segslam_window) lo = end - options_.segslam_window;
  for (std::uint32_t r = elite; r < n; ++r) {
    const std::uint32_t p = order_[r];
    if (segslam) {
      // Local analysis: chains before the window follow the best sample.
      for (std::uint32_t lv = first; lv < lo; ++lv) set_choice(p, lv, choice(best, lv));
    }
    for (std::uint32_t k = 0; k < options_.diversify_levels; ++k) {
      const std::uint32_t lv = lo + rng.below(end - lo);
      const double u = rng.uniform();
      const PgsPick pick = lv == first ? graph.sample_first(u) : graph.sample_next(lv - 1U, choice(p, lv - 1U), u);
      if (pick.status == PgsStatus::kOk) set_choice(p, lv, pick.node);
    }
  }
}

void TopParticles::extend_to_level(std::uint32_t level, std::uint32_t bottom_best, const SegmentGraph& graph,
                                   Rng& rng) {
  const std::uint32_t n = options_.particles;
  rank();
  std::uint32_t follow = static_cast<std::uint32_t>(options_.follow_best_fraction * static_cast<double>(n) + 0.999999);
  if (follow > n) follow = n;
  for (std::uint32_t r = 0; r < n; ++r) {
    const std::uint32_t p = order_[r];
    if (r < follow) {
      set_choice(p, level, bottom_best);
      continue;
    }
    const double u = rng.uniform();
    const PgsPick pick = level == graph.first_live_level() ? graph.sample_first(u)
                                                           : graph.sample_next(level - 1U, choice(p, level - 1U), u);
    set_choice(p, level, pick.status == PgsStatus::kOk ? pick.node : bottom_best);
  }
}

}  // namespace sdpslam
