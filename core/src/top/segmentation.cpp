#include "top/segmentation.h"

#include "sdpslam/core/det_math.h"

namespace sdpslam {

const char* to_string(SegmentEnd reason) {
  switch (reason) {
    case SegmentEnd::kNone: return "none";
    case SegmentEnd::kPeriod: return "period";
    case SegmentEnd::kDispersion: return "dispersion";
    case SegmentEnd::kMaxLength: return "max_length";
    case SegmentEnd::kWindow: return "window";
    case SegmentEnd::kPool: return "pool";
  }
  return "?";
}

void Segmenter::start(std::int64_t stamp_us, const Pose2& odom) {
  start_stamp_us_ = stamp_us;
  last_odom_ = odom;
  scans_ = 0U;
  travel_m_ = 0.0;
  last_dispersion_m_ = 0.0;
}

double Segmenter::dispersion_m(const Pose2* poses, std::uint32_t n) {
  if (poses == nullptr || n < 2U) return 0.0;
  double mx = 0.0;
  double my = 0.0;
  for (std::uint32_t i = 0; i < n; ++i) {
    mx += poses[i].x_m;
    my += poses[i].y_m;
  }
  mx /= static_cast<double>(n);
  my /= static_cast<double>(n);
  double s = 0.0;
  for (std::uint32_t i = 0; i < n; ++i) {
    const double dx = poses[i].x_m - mx;
    const double dy = poses[i].y_m - my;
    s += dx * dx + dy * dy;
  }
  return det::sqrt(s / static_cast<double>(n));
}

SegmentEnd Segmenter::on_processed(std::int64_t stamp_us, const Pose2& odom, const Pose2* particle_poses,
                                   std::uint32_t particle_count) {
  ++scans_;
  const double dx = odom.x_m - last_odom_.x_m;
  const double dy = odom.y_m - last_odom_.y_m;
  travel_m_ += det::sqrt(dx * dx + dy * dy);
  last_odom_ = odom;
  if (options_.segmentation == SegmentationMode::kDispersion) {
    last_dispersion_m_ = dispersion_m(particle_poses, particle_count);
  }
  if (scans_ >= options_.max_segment_scans) return SegmentEnd::kMaxLength;
  if (scans_ < options_.min_segment_scans) return SegmentEnd::kNone;
  if (options_.segmentation == SegmentationMode::kDispersion) {
    return last_dispersion_m_ > options_.dispersion_threshold_m ? SegmentEnd::kDispersion : SegmentEnd::kNone;
  }
  const double elapsed_s = static_cast<double>(stamp_us - start_stamp_us_) * 1.0e-6;
  if (options_.period_travel_m > 0.0 && travel_m_ >= options_.period_travel_m) return SegmentEnd::kPeriod;
  if (options_.period_time_s > 0.0 && elapsed_s >= options_.period_time_s) return SegmentEnd::kPeriod;
  if (options_.period_scans > 0U && scans_ >= options_.period_scans) return SegmentEnd::kPeriod;
  return SegmentEnd::kNone;
}

void Segmenter::transfer_state(StateIo& io) {
  io.section("segmenter");
  io.value(start_stamp_us_);
  io.value(last_odom_);
  io.value(scans_);
  io.value(travel_m_);
  io.value(last_dispersion_m_);
}

}  // namespace sdpslam
