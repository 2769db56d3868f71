#include "sdpslam/slam/localize_session.h"

namespace sdpslam::slam {

bool LocalizeSession::create(const LocalizerOptions& options, const std::string& map_yaml, std::uint64_t seed,
                             const Pose2* start, double sigma_xy_m, double sigma_theta_rad, std::string* error) {
  map_ = std::make_unique<LocalizationMap>();
  if (!load_localization_map(map_yaml, map_.get(), error)) return false;
  arena_bytes_ = MonteCarloLocalizer::required_arena_bytes(options, map_->map);
  if (arena_bytes_ == 0U) {
    *error = map_yaml + ": a map the localizer cannot hold (at least 2 x 2 cells, at most 65535 a side)";
    return false;
  }
  buffer_.reset(new unsigned char[arena_bytes_]);
  arena_ = std::make_unique<Arena>(buffer_.get(), arena_bytes_);
  mcl_ = std::make_unique<MonteCarloLocalizer>();
  char why[160];
  if (!mcl_->init(options, map_->map, *arena_, seed, why, sizeof why)) {
    *error = map_yaml + ": " + why;
    return false;
  }
  if (start != nullptr) {
    mcl_->start_at(*start, sigma_xy_m, sigma_theta_rad);
  } else {
    mcl_->start_global();
  }
  return true;
}

void LocalizeSession::reserve_records(std::size_t max_scans) {
  poses_.reserve(max_scans);
  bounded_ = true;
}

MonteCarloLocalizer::Step LocalizeSession::feed(const OdometrySample& odom, const RangeScan& scan) {
  const MonteCarloLocalizer::Step step = mcl_->update(odom, scan);
  if (converged_at_ < 0 && step.updated && step.spread_m < kConvergedSpreadM) {
    converged_at_ = static_cast<std::int64_t>(mcl_->stats().scans) - 1;
  }
  if (!bounded_ || poses_.size() < poses_.capacity()) {
    poses_.push_back(io::StampedPose{odom.stamp_us, step.pose});
  } else {
    ++unrecorded_;
  }
  return step;
}

}  // namespace sdpslam::slam
