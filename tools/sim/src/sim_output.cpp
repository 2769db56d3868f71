#include "sdpslam/sim/sim_output.h"

#include <charconv>
#include <cmath>

#include "sdpslam/io/atomic_file.h"
#include "sdpslam/io/carmen_writer.h"
#include "sdpslam/io/map_image.h"
#include "sdpslam/io/output_set.h"

namespace sdpslam::sim {
namespace {

std::string num(double v) {
  char buf[32];
  const auto res = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, res.ptr);
}

class LogSink : public SimulationSink {
 public:
  LogSink(io::CarmenWriter* writer, SimulationOutputs* outputs, const std::function<void(double, double)>& progress)
      : writer_(writer), outputs_(outputs), progress_(progress) {}
  void on_odom(const io::OdomRecord& r) override { writer_->odom(r); }
  void on_laser(const io::LaserRecord& r, const Pose2& true_pose) override {
    writer_->laser(r);
    outputs_->ground_truth.push_back(io::StampedPose{r.stamp_us, true_pose});
    outputs_->odometry.push_back(io::StampedPose{r.stamp_us, r.odom_pose});
  }
  void on_progress(double done_m, double total_m) override {
    if (progress_) progress_(done_m, total_m);
  }

 private:
  io::CarmenWriter* writer_;
  SimulationOutputs* outputs_;
  const std::function<void(double, double)>& progress_;
};

void write_params(io::CarmenWriter* w, const std::string& world_name, const Route& route,
                  const SimulationOptions& o) {
  w->comment("sdpslam simulated log: ground truth in ground_truth.txt, walls in world.txt");
  w->param("sim_world", world_name);
  w->param("sim_route_length_m", num(route_length_m(route)));
  w->param("sim_seed", std::to_string(o.seed));
  w->param("sim_physics_rate_hz", std::to_string(o.physics_rate_hz));
  w->param("sim_odom_rate_hz", std::to_string(o.odom_rate_hz));
  w->param("sim_laser_rate_hz", std::to_string(o.laser.rate_hz));
  w->param("sim_max_speed_mps", num(o.robot.max_speed_mps));
  w->param("sim_max_accel_mps2", num(o.robot.max_accel_mps2));
  w->param("sim_max_angular_speed_radps", num(o.robot.max_angular_speed_radps));
  w->param("sim_max_angular_accel_radps2", num(o.robot.max_angular_accel_radps2));
  w->param("sim_wheel_base_m", num(o.robot.wheel_base_m));
  w->param("sim_odom_noise_trans_m_per_sqrt_m", num(o.odometry.trans_m_per_sqrt_m));
  w->param("sim_odom_noise_rot_rad_per_sqrt_rad", num(o.odometry.rot_rad_per_sqrt_rad));
  w->param("sim_odom_noise_rot_rad_per_sqrt_m", num(o.odometry.rot_rad_per_sqrt_m));
  w->param("sim_odom_scale_error", num(o.odometry.scale_error));
  w->param("sim_odom_wheel_radius_mismatch", num(o.odometry.wheel_radius_mismatch));
  w->param("sim_laser_beams", std::to_string(o.laser.beam_count));
  w->param("sim_laser_fov_deg", num(o.laser.fov_deg));
  w->param("sim_laser_range_noise_m", num(o.laser.range_noise_std_m));
  w->param("sim_laser_spurious_max_prob", num(o.laser.spurious_max_prob));
  // CARMEN's own names for the laser, as robot logs carry them.
  w->param("robot_front_laser_max", num(o.laser.max_range_m));
  w->param("robot_frontlaser_offset", "0.0");
}

}  // namespace

OutputFiles output_files(const std::string& dir) {
  const std::string base = dir.empty() ? std::string(".") : dir;
  OutputFiles f;
  f.log = base + "/sim.clf";
  f.ground_truth = base + "/ground_truth.txt";
  f.odometry = base + "/odometry.txt";
  f.world = base + "/world.txt";
  f.map_stem = base + "/world";
  f.map_png = base + "/world.png";
  return f;
}

OutputStatus simulate_to_directory(const World& world, const std::string& world_name, const Route& route,
                                   const SimulationOptions& options, double map_resolution_m,
                                   const std::string& dir, SimulationOutputs* outputs, std::string* error,
                                   const std::function<void(double, double)>& progress, const io::Painter& painter) {
  *outputs = SimulationOutputs{};
  if (!validate_simulation_options(options, error)) return OutputStatus::kBadOptions;
  if (route.waypoints.size() < 2) {
    *error = "route needs at least 2 waypoints";
    return OutputStatus::kBadOptions;
  }
  if (!(map_resolution_m > 0.0) || !std::isfinite(map_resolution_m)) {
    *error = "map resolution must be > 0 m";
    return OutputStatus::kBadOptions;
  }
  // Made, cleaned of an interrupted run's leftovers and proven writable before the
  // simulation; every file is staged and delivered as one set at the end.
  io::OutputSet set;
  if (!set.begin(dir.empty() ? std::string(".") : dir, error)) return OutputStatus::kIoError;
  const OutputFiles files = output_files(set.staging_dir());

  io::CarmenWriter writer;
  if (!writer.open(files.log, error)) return OutputStatus::kIoError;
  write_params(&writer, world_name, route, options);
  LogSink sink(&writer, outputs, progress);
  if (!run_simulation(world, route, options, &sink, &outputs->summary, error)) return OutputStatus::kBadOptions;
  if (!writer.close(error)) return OutputStatus::kIoError;

  if (!io::write_trajectory(files.ground_truth, outputs->ground_truth, error)) return OutputStatus::kIoError;
  if (!io::write_trajectory(files.odometry, outputs->odometry, error)) return OutputStatus::kIoError;
  if (!io::write_file_atomic(files.world, format_world(world), error)) return OutputStatus::kIoError;

  RasterOptions raster;
  raster.resolution_m = map_resolution_m;
  raster.free_seed_x_m = route.waypoints[0].x_m;
  raster.free_seed_y_m = route.waypoints[0].y_m;
  const io::OccupancyImage map = rasterize_world(world, raster);
  if (!io::write_map_pgm_yaml(files.map_stem, map, io::MapWriteOptions{}, error)) return OutputStatus::kIoError;
  io::MapFigure figure;
  figure.title = "Simulated world '" + world_name + "' and the ground-truth path";
  figure.map = &map;
  figure.path = &outputs->ground_truth;
  figure.path_label = "ground truth";
  if (!painter.map(files.map_png, figure, error)) return OutputStatus::kIoError;
  if (!set.commit(error)) return OutputStatus::kIoError;
  return OutputStatus::kOk;
}

double position_rmse_m(const std::vector<io::StampedPose>& a, const std::vector<io::StampedPose>& b) {
  const std::size_t n = std::min(a.size(), b.size());
  if (n == 0) return 0.0;
  double sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double dx = a[i].pose.x_m - b[i].pose.x_m;
    const double dy = a[i].pose.y_m - b[i].pose.y_m;
    sum += dx * dx + dy * dy;
  }
  return std::sqrt(sum / static_cast<double>(n));
}

}  // namespace sdpslam::sim
