// `sdpslam simulate`: the synthetic benchmarks. A robot drives a built-in world (the
// SDP-SLAM paper's nested 28 m / 80 m loops, §IV, or a large building:
// tools/sim/include/sdpslam/sim/builtin_worlds.h) or a world and route of your own, and
// the run is written as a CARMEN log with its ground truth.
//
//   sdpslam simulate [--world paper|large|FILE] [--route FILE] [--seed N] [--out DIR] ...
//
// A built-in world brings its own route and its robot and sensors (a preset); an option
// given on the command line wins over the preset. A world file needs --route. A world
// file named like a built-in world is given with a path (./large).
// Writes DIR/sim.clf, DIR/ground_truth.txt, DIR/odometry.txt, DIR/world.txt and
// DIR/world.pgm + .yaml + .png (tools/sim/include/sdpslam/sim/sim_output.h), then prints
// a summary. Same arguments and seed → byte-identical files.
// Exit codes (cli_common.h): unreadable or malformed world/route file → kExitBadInput
// (file:line: reason); out-of-range option → kExitUsage; unwritable output → kExitIo.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "cli_common.h"
#include "sdpslam/sim/builtin_worlds.h"
#include "sdpslam/sim/sim_output.h"
#include "sdpslam/sim/world.h"

namespace sdpslam::cli {
namespace {

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

// "paper, large"
std::string builtin_world_names() {
  std::string names;
  for (const sim::BuiltinWorld& w : sim::builtin_worlds()) names += (names.empty() ? "" : ", ") + std::string(w.name);
  return names;
}

struct SimulateArgs {
  std::string world = "paper";  // a built-in world's name or a world file
  bool quiet = false;
  std::string route_path;
  std::string out_dir = "sim";
  double map_resolution_m = 0.05;
  sim::SimulationOptions options;  // as parsed: defaults plus what the user gave
  // One per option bound to `options`: copies the user's value over `out` iff the option
  // was given on the command line.
  std::vector<std::function<void(const sim::SimulationOptions& given, sim::SimulationOptions* out)>> keep_given;
  // One per option bound to `options`: " --name value" iff `preset` differs from the
  // default there, else "" (for --help).
  std::vector<std::function<std::string(const sim::SimulationOptions& preset)>> preset_change;
};

int run_simulate(const SimulateArgs& args) {
  sim::World world;
  sim::Route route;
  std::string error;
  sim::SimulationOptions options = args.options;
  const sim::BuiltinWorld* builtin = sim::find_builtin_world(args.world);
  if (builtin != nullptr) {
    world = builtin->world();
    route = builtin->route();
    options = builtin->preset(args.options);
    for (const auto& keep : args.keep_given) keep(args.options, &options);
  } else {
    if (args.route_path.empty()) {
      std::fprintf(stderr,
                   "sdpslam simulate: the world file %s needs --route (a built-in route fits only its own world; "
                   "built-in worlds: %s)\n",
                   args.world.c_str(), builtin_world_names().c_str());
      return kExitUsage;
    }
    if (!sim::load_world_file(args.world, &world, &error)) {
      std::fprintf(stderr, "sdpslam simulate: %s\n", error.c_str());
      return kExitBadInput;
    }
  }
  if (!args.route_path.empty() && !sim::load_route_file(args.route_path, &route, &error)) {
    std::fprintf(stderr, "sdpslam simulate: %s\n", error.c_str());
    return kExitBadInput;
  }
  const std::string& world_name = args.world;
  if (!sim::validate_simulation_options(options, &error)) {
    std::fprintf(stderr, "sdpslam simulate: %s\n", error.c_str());
    return kExitUsage;
  }

  const double route_m = sim::route_length_m(route);
  Progress progress("metres", static_cast<std::uint64_t>(std::ceil(route_m)), args.quiet);
  const auto on_progress = [&progress](double done_m, double /*total_m*/) {
    progress.update(static_cast<std::uint64_t>(done_m));
  };
  const auto t0 = std::chrono::steady_clock::now();
  sim::SimulationOutputs out;
  const sim::OutputStatus status = sim::simulate_to_directory(world, world_name, route, options,
                                                              args.map_resolution_m, args.out_dir, &out, &error,
                                                              on_progress, figure_painter());
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
              static_cast<unsigned long long>(options.seed));
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

// Binds `--name` to the SimulationOptions field `field` picks and records how to keep
// the user's value over a built-in world's preset.
template <typename Field>
void add_sim_option(CLI::App& app, SimulateArgs* args, const std::string& name, Field field,
                    const std::string& help) {
  CLI::Option* option = app.add_option(name, field(args->options), help)->capture_default_str();
  using Value = std::remove_reference_t<decltype(field(args->options))>;
  if constexpr (std::is_integral_v<Value> && std::is_unsigned_v<Value> && !std::is_same_v<Value, bool>) {
    option->check(whole_number(std::numeric_limits<Value>::max()));
  }
  args->keep_given.push_back([option, field](const sim::SimulationOptions& given, sim::SimulationOptions* out) {
    if (option->count() > 0) field(*out) = field(given);
  });
  args->preset_change.push_back([name, field](const sim::SimulationOptions& preset) {
    const sim::SimulationOptions defaults;
    if (field(preset) == field(defaults)) return std::string();
    std::ostringstream text;
    text << ' ' << name << ' ' << field(preset);
    return text.str();
  });
}

// The built-in worlds with the options each one's preset sets.
std::string world_help(const SimulateArgs& args) {
  std::string help = "a built-in world, with its route, robot and laser (options given here win; the defaults "
                     "shown are the paper world's):";
  for (const sim::BuiltinWorld& w : sim::builtin_worlds()) {
    std::string sets;
    for (const auto& change : args.preset_change) sets += change(w.preset(sim::SimulationOptions{}));
    help += std::string("\n  ") + w.name + ": " + w.description + (sets.empty() ? "" : "; sets" + sets);
  }
  help += "\nor a world file, one wall 'x1 y1 x2 y2' per line (needs --route)";
  return help;
}

std::function<int()> setup_simulate(CLI::App& app) {
  auto args = std::make_shared<SimulateArgs>();
  SimulateArgs* a = args.get();
  CLI::Option* world = app.add_option("--world", args->world)->capture_default_str();
  app.add_option("--route", args->route_path,
                 "route file: one waypoint 'x y' per line (default: the built-in world's)");
  add_sim_option(app, a, "--seed", [](auto& o) -> auto& { return o.seed; }, "random seed");
  app.add_option("--out", args->out_dir, "output directory")->capture_default_str()->check(non_empty());
  app.add_flag("--quiet", args->quiet, "no progress display (errors, warnings and the summary still print)");
  add_sim_option(app, a, "--speed", [](auto& o) -> auto& { return o.robot.max_speed_mps; }, "top speed, m/s");
  add_sim_option(app, a, "--accel", [](auto& o) -> auto& { return o.robot.max_accel_mps2; },
                 "acceleration limit, m/s^2");
  add_sim_option(app, a, "--turn-rate", [](auto& o) -> auto& { return o.robot.max_angular_speed_radps; },
                 "angular speed limit, rad/s");
  add_sim_option(app, a, "--wheel-base", [](auto& o) -> auto& { return o.robot.wheel_base_m; },
                 "wheel separation, m");
  add_sim_option(app, a, "--physics-rate", [](auto& o) -> auto& { return o.physics_rate_hz; },
                 "simulation steps per second");
  add_sim_option(app, a, "--odom-rate", [](auto& o) -> auto& { return o.odom_rate_hz; }, "ODOM records per second");
  add_sim_option(app, a, "--laser-rate", [](auto& o) -> auto& { return o.laser.rate_hz; }, "laser scans per second");
  add_sim_option(app, a, "--beams", [](auto& o) -> auto& { return o.laser.beam_count; }, "beams per scan");
  add_sim_option(app, a, "--fov-deg", [](auto& o) -> auto& { return o.laser.fov_deg; },
                 "laser field of view, degrees");
  add_sim_option(app, a, "--max-range", [](auto& o) -> auto& { return o.laser.max_range_m; },
                 "laser maximum range, m");
  add_sim_option(app, a, "--range-noise", [](auto& o) -> auto& { return o.laser.range_noise_std_m; },
                 "range noise std, m");
  add_sim_option(app, a, "--spurious-prob", [](auto& o) -> auto& { return o.laser.spurious_max_prob; },
                 "probability of a spurious max-range reading");
  add_sim_option(app, a, "--odom-noise-trans", [](auto& o) -> auto& { return o.odometry.trans_m_per_sqrt_m; },
                 "along-track random walk, m per sqrt(m) travelled");
  add_sim_option(app, a, "--odom-noise-rot", [](auto& o) -> auto& { return o.odometry.rot_rad_per_sqrt_rad; },
                 "heading random walk, rad per sqrt(rad) turned");
  add_sim_option(app, a, "--odom-noise-rot-dist", [](auto& o) -> auto& { return o.odometry.rot_rad_per_sqrt_m; },
                 "heading random walk, rad per sqrt(m) travelled");
  add_sim_option(app, a, "--odom-drift", [](auto& o) -> auto& { return o.odometry.wheel_radius_mismatch; },
                 "wheel radius mismatch (r_right - r_left)/r: steady heading drift");
  add_sim_option(app, a, "--odom-scale", [](auto& o) -> auto& { return o.odometry.scale_error; },
                 "odometry distance scale error (fraction)");
  add_sim_option(app, a, "--max-duration", [](auto& o) -> auto& { return o.max_duration_s; },
                 "stop after this many simulated seconds (0: automatic)");
  app.add_option("--map-resolution", args->map_resolution_m, "ground-truth map cell size, m")->capture_default_str();
  world->description(world_help(*args));
  return [args]() { return run_simulate(*args); };
}

}  // namespace

SDPSLAM_REGISTER_COMMAND(simulate, "simulate",
                         "simulate a benchmark world (the paper's nested loops, a large building, or your own): "
                         "CARMEN log + ground truth + map",
                         10,
                         setup_simulate);

}  // namespace sdpslam::cli
