#include "sdpslam/slam/dpslam_session.h"

namespace sdpslam::slam {

bool DpSlamSession::create(const DpSlamOptions& options, std::uint64_t seed, std::string* error) {
  char why[200];
  if (!options.validate(why, sizeof why)) {
    *error = std::string("invalid SLAM options: ") + why;
    return false;
  }
  arena_bytes_ = DpSlamFilter::required_arena_bytes(options);
  buffer_.reset(new unsigned char[arena_bytes_]);
  arena_ = std::make_unique<Arena>(buffer_.get(), arena_bytes_);
  filter_ = std::make_unique<DpSlamFilter>();
  if (!filter_->init(options, *arena_, seed)) {
    *error = std::string("filter init failed: ") + filter_->why();
    return false;
  }
  filter_->set_pose_sink(this);
  return true;
}

void DpSlamSession::reserve_records(std::size_t max_scans) {
  committed_.reserve(max_scans);
  scans_.reserve(max_scans);
  bounded_ = true;
}

void DpSlamSession::on_committed(std::int64_t stamp_us, const Pose2& pose) {
  if (!bounded_ || committed_.size() < committed_.capacity()) {
    committed_.push_back({stamp_us, pose});
  } else {
    ++committed_dropped_;
  }
}

StepResult DpSlamSession::feed(const OdometrySample& odom, const RangeScan& scan) {
  const StepResult r = filter_->process(odom, scan);
  const bool processed = r.status == StepResult::Status::kProcessed;
  if (!bounded_ || scans_.size() < scans_.capacity()) {
    scans_.push_back(ScanRecord{odom.stamp_us, odom.pose, r.pose, processed});
  } else {
    ++unrecorded_;
  }
  return r;
}

std::vector<io::StampedPose> DpSlamSession::trajectory(std::uint64_t* gaps) const {
  // The final best particle's path: committed poses, then its own uncommitted ones.
  std::vector<io::StampedPose> path = committed_;
  filter_->for_each_best_pose([&](std::int64_t s, const Pose2& p) { path.push_back({s, p}); });
  return assemble_trajectory(scans_, path, gaps);
}

}  // namespace sdpslam::slam
