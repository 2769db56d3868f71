#include "sdpslam/slam/slam_outputs.h"

namespace sdpslam::slam {

std::vector<io::StampedPose> assemble_trajectory(const std::vector<ScanRecord>& scans,
                                                 const std::vector<io::StampedPose>& path,
                                                 std::uint64_t* path_gaps) {
  std::vector<io::StampedPose> trajectory;
  trajectory.reserve(scans.size());
  std::size_t pi = 0U;
  bool anchored = false;
  Pose2 anchor_pose;
  Pose2 anchor_odom;
  std::uint64_t gaps = 0U;
  for (const ScanRecord& s : scans) {
    Pose2 pose;
    bool from_path = false;
    if (s.processed) {
      while (pi < path.size() && path[pi].stamp_us < s.stamp_us) ++pi;
      if (pi < path.size() && path[pi].stamp_us == s.stamp_us) {
        pose = path[pi].pose;
        ++pi;
        from_path = true;
      } else {
        ++gaps;
      }
    }
    if (!from_path) pose = anchored ? anchor_pose.compose(between(anchor_odom, s.odom)) : s.online;
    if (from_path || !anchored) {
      anchor_pose = pose;
      anchor_odom = s.odom;
      anchored = true;
    }
    trajectory.push_back({s.stamp_us, pose});
  }
  if (path_gaps != nullptr) *path_gaps = gaps;
  return trajectory;
}

std::uint32_t best_map_image(const DpSlamFilter& filter, io::OccupancyImage* image) {
  const DpMap& map = filter.map();
  *image = io::OccupancyImage{};
  image->resolution_m = map.resolution_m();
  CellRect rect;
  if (!map.touched_bounds(&rect)) return 0U;
  std::vector<CellObservation> values(static_cast<std::size_t>(rect.width) * rect.height);
  std::vector<std::uint8_t> known(values.size(), 0U);
  const std::uint32_t known_cells = map.fill_rect(filter.best_node(), rect, values.data(), known.data());
  image->width = rect.width;
  image->height = rect.height;
  image->origin_x_m = map.options().origin_x_m + rect.ix0 * map.resolution_m();
  image->origin_y_m = map.options().origin_y_m + rect.iy0 * map.resolution_m();
  image->occupancy.resize(values.size());
  for (std::size_t i = 0; i < values.size(); ++i) {
    image->occupancy[i] = known[i] != 0U ? static_cast<float>(filter.occupancy(values[i])) : -1.0F;
  }
  return known_cells;
}

bool write_trajectory_and_map(const std::string& out_dir, const std::vector<io::StampedPose>& trajectory,
                              const io::OccupancyImage& image, std::string* error) {
  if (!io::write_trajectory(out_dir + "/trajectory.txt", trajectory, error)) return false;
  if (image.width > 0U) {
    if (!io::write_map_pgm_yaml(out_dir + "/map", image, io::MapWriteOptions{}, error)) return false;
    if (!io::write_map_png(out_dir + "/map.png", image, trajectory, error)) return false;
  }
  return true;
}

}  // namespace sdpslam::slam
