// `sdpslam simulate`: the synthetic benchmark of the SDP-SLAM paper (§IV): a robot drives
// the nested 28 m / 80 m loops of the built-in world (or a world and route of your own)
// and the run is written as a CARMEN log with its ground truth.
//
//   sdpslam simulate [--world FILE --route FILE] [--seed N] [--out DIR] [--speed M/S] ...
//
// Writes DIR/sim.clf, DIR/ground_truth.txt, DIR/odometry.txt, DIR/world.txt and
// DIR/world.pgm + .yaml + .png (tools/sim/include/sdpslam/sim/sim_output.h), then prints
// a summary. Same arguments and seed → byte-identical files.
// Exit codes (cli_common.h): unreadable or malformed world/route file → kExitBadInput
// (file:line: reason); out-of-range option → kExitUsage; unwritable output → kExitIo.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "cli_common.h"
#include "sdpslam/sim/sim_output.h"
#include "sdpslam/sim/world.h"

namespace sdpslam::cli {
namespace {

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

struct SimulateArgs {
  std::string world_path;
  std::string route_path;
  std::string out_dir = "sim";
  double map_resolution_m = 0.05;
  sim::SimulationOptions options;
};

int run_simulate(const SimulateArgs& args) {
  sim::World world;
  sim::Route route;
  std::string error;
  std::string world_name = "builtin";
  if (!args.world_path.empty()) {
    if (args.route_path.empty()) {
      std::fprintf(stderr, "sdpslam simulate: --world needs --route (the built-in route fits only the built-in world)\n");
      return kExitUsage;
    }
    if (!sim::load_world_file(args.world_path, &world, &error)) {
      std::fprintf(stderr, "sdpslam simulate: %s\n", error.c_str());
      return kExitBadInput;
    }
    world_name = args.world_path;
  } else {
    world = sim::builtin_world();
  }
  if (!args.route_path.empty()) {
    if (!sim::load_route_file(args.route_path, &route, &error)) {
      std::fprintf(stderr, "sdpslam simulate: %s\n", error.c_str());
      return kExitBadInput;
    }
  } else {
    route = sim::builtin_route();
  }
  if (!sim::validate_simulation_options(args.options, &error)) {
    std::fprintf(stderr, "sdpslam simulate: %s\n", error.c_str());
    return kExitUsage;
  }

  const double route_m = sim::route_length_m(route);
  Progress progress("metres", static_cast<std::uint64_t>(std::ceil(route_m)));
  const auto on_progress = [&progress](double done_m, double /*total_m*/) {
    progress.update(static_cast<std::uint64_t>(done_m));
  };
  const auto t0 = std::chrono::steady_clock::now();
  sim::SimulationOutputs out;
  const sim::OutputStatus status = sim::simulate_to_directory(world, world_name, route, args.options,
                                                              args.map_resolution_m, args.out_dir, &out, &error,
                                                              on_progress);
  progress.finish();
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (status == sim::OutputStatus::kBadOptions) {
    std::fprintf(stderr, "sdpslam simulate: %s\n", error.c_str());
    return kExitUsage;
  }
  if (status == sim::OutputStatus::kIoError) {
    std::fprintf(stderr, "sdpslam simulate: %s\n", error.c_str());
    return kExitIo;
  }

  const sim::SimulationSummary& s = out.summary;
  const sim::OutputFiles files = sim::output_files(args.out_dir);
  std::printf("world %s: %zu walls; route %.3f m; seed %llu\n", world_name.c_str(), world.segments.size(), route_m,
              static_cast<unsigned long long>(args.options.seed));
  std::printf("simulated %.1f s, driven %.2f m, %llu scans, %llu odometry records%s\n", s.duration_s, s.distance_m,
              static_cast<unsigned long long>(s.scan_count), static_cast<unsigned long long>(s.odom_count),
              s.reached_goal ? "" : " (time ran out before the end of the route)");
  std::printf("odometry drift at the end: %.3f m, %.2f deg; odometry position RMSE vs ground truth %.3f m "
              "(no alignment)\n",
              s.end_position_error_m, s.end_heading_error_rad * kRadToDeg,
              sim::position_rmse_m(out.odometry, out.ground_truth));
  std::printf("closest approach to a wall: %.2f m\n", s.min_wall_clearance_m);
  std::printf("wrote %s, %s, %s, %s, %s.pgm/.yaml, %s in %.2f s\n", files.log.c_str(), files.ground_truth.c_str(),
              files.odometry.c_str(), files.world.c_str(), files.map_stem.c_str(), files.map_png.c_str(), wall_s);
  if (!s.reached_goal) {
    std::fprintf(stderr, "sdpslam simulate: warning: the robot did not reach the end of the route within %.0f s\n",
                 s.duration_s);
  }
  return kExitOk;
}

std::function<int()> setup_simulate(CLI::App& app) {
  auto args = std::make_shared<SimulateArgs>();
  sim::SimulationOptions& o = args->options;
  app.add_option("--world", args->world_path, "world file: one wall 'x1 y1 x2 y2' per line (default: built-in)");
  app.add_option("--route", args->route_path, "route file: one waypoint 'x y' per line (default: built-in)");
  app.add_option("--seed", o.seed, "random seed")->capture_default_str();
  app.add_option("--out", args->out_dir, "output directory")->capture_default_str();
  app.add_option("--speed", o.robot.max_speed_mps, "top speed, m/s")->capture_default_str();
  app.add_option("--accel", o.robot.max_accel_mps2, "acceleration limit, m/s^2")->capture_default_str();
  app.add_option("--turn-rate", o.robot.max_angular_speed_radps, "angular speed limit, rad/s")->capture_default_str();
  app.add_option("--wheel-base", o.robot.wheel_base_m, "wheel separation, m")->capture_default_str();
  app.add_option("--physics-rate", o.physics_rate_hz, "simulation steps per second")->capture_default_str();
  app.add_option("--odom-rate", o.odom_rate_hz, "ODOM records per second")->capture_default_str();
  app.add_option("--laser-rate", o.laser.rate_hz, "laser scans per second")->capture_default_str();
  app.add_option("--beams", o.laser.beam_count, "beams per scan")->capture_default_str();
  app.add_option("--fov-deg", o.laser.fov_deg, "laser field of view, degrees")->capture_default_str();
  app.add_option("--max-range", o.laser.max_range_m, "laser maximum range, m")->capture_default_str();
  app.add_option("--range-noise", o.laser.range_noise_std_m, "range noise std, m")->capture_default_str();
  app.add_option("--spurious-prob", o.laser.spurious_max_prob, "probability of a spurious max-range reading")
      ->capture_default_str();
  app.add_option("--odom-noise-trans", o.odometry.trans_m_per_sqrt_m,
                 "along-track random walk, m per sqrt(m) travelled")
      ->capture_default_str();
  app.add_option("--odom-noise-rot", o.odometry.rot_rad_per_sqrt_rad, "heading random walk, rad per sqrt(rad) turned")
      ->capture_default_str();
  app.add_option("--odom-noise-rot-dist", o.odometry.rot_rad_per_sqrt_m,
                 "heading random walk, rad per sqrt(m) travelled")
      ->capture_default_str();
  app.add_option("--odom-drift", o.odometry.wheel_radius_mismatch,
                 "wheel radius mismatch (r_right - r_left)/r: steady heading drift")
      ->capture_default_str();
  app.add_option("--odom-scale", o.odometry.scale_error, "odometry distance scale error (fraction)")
      ->capture_default_str();
  app.add_option("--max-duration", o.max_duration_s, "stop after this many simulated seconds (0: automatic)")
      ->capture_default_str();
  app.add_option("--map-resolution", args->map_resolution_m, "ground-truth map cell size, m")->capture_default_str();
  return [args]() { return run_simulate(*args); };
}

}  // namespace

SDPSLAM_REGISTER_COMMAND(simulate, "simulate",
                         "simulate the paper's nested-loop benchmark: CARMEN log + ground truth + map", 10,
                         setup_simulate);

}  // namespace sdpslam::cli
