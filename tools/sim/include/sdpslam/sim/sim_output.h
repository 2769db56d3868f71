#pragma once
// Runs a simulation and writes its outputs into one directory:
//   sim.clf           CARMEN log: PARAM lines describing the simulation, ODOM records,
//                     laser records carrying the odometry pose (io::CarmenWriter)
//   ground_truth.txt  true laser pose at every laser stamp, "t x y theta"
//   odometry.txt      raw odometry pose at every laser stamp, same format
//   world.txt         the walls (world.h text format)
//   world.pgm/.yaml   ground-truth occupancy (world_raster.h), map_server convention
//   world.png         the same with the ground-truth trajectory drawn
// Every file is written atomically. The log is produced as the simulation runs; the
// trajectories are kept in memory (one pose per scan).
#include <functional>
#include <string>
#include <vector>

#include "sdpslam/io/figures.h"
#include "sdpslam/io/trajectory_io.h"
#include "sdpslam/sim/simulator.h"
#include "sdpslam/sim/world_raster.h"

namespace sdpslam::sim {

struct OutputFiles {
  std::string log;
  std::string ground_truth;
  std::string odometry;
  std::string world;
  std::string map_stem;  // + ".pgm" / ".yaml"
  std::string map_png;
};
OutputFiles output_files(const std::string& dir);

enum class OutputStatus { kOk, kBadOptions, kIoError };

struct SimulationOutputs {
  SimulationSummary summary;
  std::vector<io::StampedPose> ground_truth;
  std::vector<io::StampedPose> odometry;
};

// `world_name` is recorded in the log's PARAM sim_world. `map_resolution_m` is the ground
// truth map's cell size. kBadOptions iff the options or route are invalid (nothing is
// written); kIoError iff the directory or a file cannot be written (`error` names it).
OutputStatus simulate_to_directory(const World& world, const std::string& world_name, const Route& route,
                                   const SimulationOptions& options, double map_resolution_m,
                                   const std::string& dir, SimulationOutputs* outputs, std::string* error,
                                   const std::function<void(double, double)>& progress = {},
                                   const io::Painter& painter = io::plain_painter());

// Position RMSE between two trajectories matched by index (same stamps), without
// alignment. Returns 0 for empty input; uses the shorter length.
double position_rmse_m(const std::vector<io::StampedPose>& a, const std::vector<io::StampedPose>& b);

}  // namespace sdpslam::sim
