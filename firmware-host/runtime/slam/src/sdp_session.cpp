#include "sdpslam/slam/sdp_session.h"

namespace sdpslam::slam {

SdpSession::SdpSession(double continuation_window_m, bool stayed_likely)
    : continuation_(continuation_window_m, stayed_likely) {}

bool SdpSession::create(const DpSlamOptions& bottom, const SdpOptions& sdp, std::uint64_t seed, bool collect_rounds,
                        std::string* error) {
  char why[240];
  if (!SdpSlam::check_options(bottom, sdp, why, sizeof why)) {
    *error = std::string("invalid SLAM options: ") + why;
    return false;
  }
  arena_bytes_ = SdpSlam::required_arena_bytes(bottom, sdp);
  if (arena_bytes_ == 0U) {
    *error = "invalid SDP-SLAM options (arena size)";
    return false;
  }
  buffer_.reset(new unsigned char[arena_bytes_]);
  arena_ = std::make_unique<Arena>(buffer_.get(), arena_bytes_);
  slam_ = std::make_unique<SdpSlam>();
  if (!slam_->init(bottom, sdp, *arena_, seed)) {
    *error = std::string("SDP-SLAM init failed: ") + slam_->why();
    return false;
  }
  slam_->set_permanent_sink(&permanent_);
  if (collect_rounds) slam_->set_listener(this);
  return true;
}

void SdpSession::reserve_records(std::size_t max_scans) {
  // A level holds at least min_segment_scans processed scans.
  permanent_.reserve(max_scans, max_scans / slam_->options().min_segment_scans + 1U);
  scans_.reserve(max_scans);
  bounded_ = true;
}

bool SdpSession::feed(const OdometrySample& odom_in, const RangeScan& scan_in, SdpStepResult* step) {
  // A continued session's input does not follow it without a break: its odometry starts
  // from its own origin, its clock may have started again, and the robot may have been
  // moved (session_continuation.h carries all three across, on a copy of the scan: its
  // stamp may move).
  OdometrySample odom = odom_in;
  const RangeScan* scan = &scan_in;
  if (continuation_.active()) {
    *carried_ = scan_in;
    scan = carried_.get();
    if (!continuation_.carry(&odom, carried_.get(), *slam_)) return false;
  }
  last_odom_ = odom.pose;
  *step = slam_->process(odom, *scan);
  last_pose_ = step->pose;
  const bool processed = step->bottom.status == StepResult::Status::kProcessed;
  if (!bounded_ || scans_.size() < scans_.capacity()) {
    scans_.push_back(ScanRecord{scan->stamp_us, odom.pose, step->pose, processed});
  } else {
    ++unrecorded_;
  }
  return true;
}

std::vector<io::StampedPose> SdpSession::trajectory(std::uint64_t* gaps) const {
  return smooth_with_odometry(scans_, assemble_trajectory(scans_, sdp_best_path(*slam_, permanent_), gaps));
}

std::uint32_t SdpSession::map_image(io::OccupancyImage* image) const { return sdp_global_map_image(*slam_, image); }

io::Json SdpSession::state_json(std::uint64_t path_gaps, std::uint32_t known_cells) const {
  return sdp_state_json(*slam_, arena_bytes_, arena_->used_bytes(), path_gaps, known_cells);
}

}  // namespace sdpslam::slam
