#pragma once
// The simulation loop: a robot drives a Route through a World at a fixed physics rate;
// wheel odometry and laser scans are emitted at their own rates to a sink.
//
// Time: step k is at start_stamp_us + k * (1e6 / physics_rate_hz) µs (integer
// arithmetic, so stamps are exact and deterministic). At a step where a sensor is due,
// its record is emitted for the state at that instant, before the robot moves on. The
// laser sits at the robot's origin, so the ground-truth pose handed with each scan is
// both the robot's and the laser's true pose at that scan's stamp. The odometry frame
// coincides with the world frame at the start.
// Deterministic: the same World, Route and options (seed included) give the same
// sequence of records bit for bit.
#include <cstdint>
#include <functional>
#include <string>

#include "sdpslam/core/pose2.h"
#include "sdpslam/io/log_reader.h"
#include "sdpslam/sim/diff_drive.h"
#include "sdpslam/sim/laser_model.h"
#include "sdpslam/sim/odometry_model.h"
#include "sdpslam/sim/world.h"

namespace sdpslam::sim {

struct SimulationOptions {
  std::uint64_t seed = 1;
  std::uint32_t physics_rate_hz = 100;  // must divide 1e6; sensor rates must divide it
  std::uint32_t odom_rate_hz = 20;
  // 1000000000.000000 s: a fixed epoch so that logs are byte-identical run to run.
  std::int64_t start_stamp_us = 1000000000LL * 1000000LL;
  // 0 = automatic: 3 x route length / max speed + 60 s.
  double max_duration_s = 0.0;
  RobotLimits robot;
  FollowerOptions follower;
  OdometryNoise odometry;
  LaserOptions laser;
};

// Range-checks every option. False iff one is out of range; `error` names it and why.
bool validate_simulation_options(const SimulationOptions& options, std::string* error);

// Receives the simulation's records in time order.
class SimulationSink {
 public:
  virtual ~SimulationSink() = default;
  virtual void on_odom(const io::OdomRecord& record) = 0;
  // `true_pose`: ground truth of the laser at record.stamp_us.
  virtual void on_laser(const io::LaserRecord& record, const Pose2& true_pose) = 0;
  // Called at every laser scan with the distance driven so far (for progress displays).
  virtual void on_progress(double /*route_progress_m*/, double /*route_length_m*/) {}
};

struct SimulationSummary {
  bool reached_goal = false;   // false iff max_duration_s ran out first
  double duration_s = 0.0;     // simulated time
  double distance_m = 0.0;     // true distance driven
  double rotation_rad = 0.0;   // true total |rotation|
  std::uint64_t steps = 0;
  std::uint64_t scan_count = 0;
  std::uint64_t odom_count = 0;
  Pose2 final_true;
  Pose2 final_odom;
  double end_position_error_m = 0.0;  // |odometry - truth| at the end
  double end_heading_error_rad = 0.0;
  double min_wall_clearance_m = 0.0;  // smallest robot-centre distance to a wall, at scan times
};

// Runs the simulation. False iff the options are invalid or the route has < 2 waypoints
// (`error` says which); the sink then received nothing.
bool run_simulation(const World& world, const Route& route, const SimulationOptions& options,
                    SimulationSink* sink, SimulationSummary* summary, std::string* error);

}  // namespace sdpslam::sim
