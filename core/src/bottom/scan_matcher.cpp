#include "sdpslam/core/bottom/scan_matcher.h"

#include "sdpslam/core/det_math.h"

namespace sdpslam {
namespace {

// Streaming log-sum-exp (one det::exp per added term).
struct LogSumExp {
  double max = 0.0;
  double sum = 0.0;  // Σ exp(x − max)
  std::uint32_t count = 0U;

  void add(double x) {
    if (count == 0U) {
      max = x;
      sum = 1.0;
    } else if (x > max) {
      sum = sum * det::exp(max - x) + 1.0;
      max = x;
    } else {
      sum += det::exp(x - max);
    }
    ++count;
  }
  double log_mean() const { return count == 0U ? 0.0 : max + det::log(sum / static_cast<double>(count)); }
};

}  // namespace

ScanMatch match_scan(const BeamModel& model, const DpMap& map, NodeId particle, const ScanRays& rays,
                     const Pose2& initial, const ScanMatcherOptions& options, const MotionPrior* prior,
                     ViewCache* view) {
  if (view != nullptr && view->ready()) view->begin(map, particle);
  else view = nullptr;
  const std::uint32_t stride = options.beam_stride == 0U ? 1U : options.beam_stride;
  auto score_at = [&](const Pose2& pose, BeamScore* score) {
    return view != nullptr ? model.log_likelihood_strided(*view, map, rays, pose, stride, score)
                           : model.log_likelihood_strided(map, particle, rays, pose, stride, score);
  };
  auto log_prior = [prior](const Pose2& pose) { return prior != nullptr ? prior->log_density(pose) : 0.0; };
  ScanMatch m;
  m.pose = initial;
  BeamScore score;
  double best_likelihood = score_at(initial, &score);
  double best = best_likelihood + log_prior(initial);  // the objective: likelihood × prior
  m.evaluations = 1U;
  m.beams = score.beams;
  m.log_likelihood = best_likelihood;
  m.neighbourhood_log_likelihood = best;
  if (score.beams == 0U || score.beams < options.min_beams) {
    m.outcome = ScanMatch::Outcome::kTooFewBeams;
    return m;
  }
  if (static_cast<double>(score.known_beams) < options.min_known_fraction * static_cast<double>(score.beams)) {
    m.outcome = ScanMatch::Outcome::kMapTooEmpty;
    return m;
  }

  Pose2 pose = initial;
  double lin = options.linear_step_m;
  double ang = options.angular_step_rad;
  LogSumExp last_level;
  for (std::uint32_t level = 0; level <= options.refinements; ++level) {
    const bool finest = level == options.refinements;
    if (finest) last_level.add(best);
    for (std::uint32_t it = 0; it < options.max_iterations; ++it) {
      // Six neighbours in the robot frame: front, back, left, right, turn left, right.
      const Pose2 moves[6] = {Pose2{lin, 0.0, 0.0}, Pose2{-lin, 0.0, 0.0}, Pose2{0.0, lin, 0.0},
                              Pose2{0.0, -lin, 0.0}, Pose2{0.0, 0.0, ang}, Pose2{0.0, 0.0, -ang}};
      Pose2 step_best = pose;
      double step_score = best;
      double step_likelihood = best_likelihood;
      for (const Pose2& mv : moves) {
        const Pose2 cand = pose.compose(mv);
        const double l = score_at(cand, nullptr);
        const double s = l + log_prior(cand);
        ++m.evaluations;
        if (finest) last_level.add(s);
        if (s > step_score) {
          step_score = s;
          step_likelihood = l;
          step_best = cand;
        }
      }
      if (!(step_score > best)) break;
      best = step_score;
      best_likelihood = step_likelihood;
      pose = step_best;
    }
    lin *= 0.5;
    ang *= 0.5;
  }
  m.pose = pose;
  m.log_likelihood = best_likelihood;
  m.neighbourhood_log_likelihood = last_level.log_mean();
  const double temperature = model.options().likelihood_temperature;
  const double mean_per_beam = best_likelihood * temperature / static_cast<double>(score.beams);
  m.outcome = mean_per_beam >= options.min_mean_log_likelihood ? ScanMatch::Outcome::kMatched
                                                               : ScanMatch::Outcome::kScoreTooLow;
  return m;
}

}  // namespace sdpslam
