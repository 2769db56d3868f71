#pragma once
// Offline runner: reads a robot log through sdpslam::io::LogReader, feeds every laser
// scan with its odometry to the bottom-level DP-SLAM filter, and writes into out_dir:
//  - trajectory.txt  one "t x y theta" line per laser scan (t = the scan's log stamp);
//                    processed scans take the final best particle's path, the others
//                    that pose composed with the odometry since (map frame: the first
//                    scan's pose is the origin);
//  - trajectory.tum  the same poses in TUM format (slam_outputs.h write_trajectories);
//  - map.pgm/.yaml   the best particle's occupancy grid (map_server convention), and
//    map.png         with the trajectory drawn;
//  - stats.json      counts, pool high-water marks, exhaustion counters, state memory
//                    vs a naive per-particle map copy; the "timing" object holds the
//                    only non-deterministic fields (wall time, per-scan times, RSS).
// Same log, options and seed -> bit-identical trajectory.txt and map files.
// All files are written atomically.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "sdpslam/io/figures.h"
#include "sdpslam/slam/config_ini.h"
#include "sdpslam/slam/run_summary.h"

namespace sdpslam::slam {

enum class RunMode { kDpSlam };

struct RunOptions {
  RunMode mode = RunMode::kDpSlam;
  SlamConfig config;
  std::uint64_t seed = 1U;
  // Called after every scan with the bytes of the log read so far (compressed bytes for
  // .gz; io::LogReader::input_offset()), for a progress display; may be empty.
  std::function<void(std::uint64_t input_bytes)> progress;
  // Draws map.png (figures.h; the sdpslam CLI: plot::painter()).
  io::Painter painter = io::plain_painter();
};

enum class RunStatus { kOk, kBadInput, kIoError, kInternal };

// Bytes of the DP-SLAM filter's state these options ask for (the arena run_offline
// allocates: DpSlamFilter::required_arena_bytes), known before any work.
std::size_t dpslam_state_bytes(const RunOptions& options);

RunStatus run_offline(const std::string& log_path, const RunOptions& options, const std::string& out_dir,
                      RunSummary* summary, std::string* error);

}  // namespace sdpslam::slam
