#pragma once
// Shared pieces of the `sdpslam` command line: exit codes, subcommand registration and
// a progress line for long work.
#include <CLI/CLI.hpp>

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>

#include "sdpslam/io/figures.h"
#include "sdpslam/io/log_reader.h"

namespace sdpslam::cli {

// Exit codes: scripts can tell bad input from a fault of the program.
enum ExitCode : int {
  kExitOk = 0,
  kExitInternal = 1,   // a bug or an unexpected failure inside sdpslam
  kExitUsage = 2,      // bad command line (CLI11 parse errors)
  kExitBadInput = 3,   // unreadable, malformed or inconsistent input data
  kExitIo = 4,         // an output could not be written
};

// Checks for option values CLI11 would take wrongly without a word: it reads "-1" into
// an unsigned option as the type's largest value (two's complement) and a number beyond
// the type's range as that largest value too. whole_number(max) accepts decimal
// digits only, at most `max`; non_empty() refuses "" (an empty --out is a usage error,
// not a failed write). A refused value exits kExitUsage with the option's name.
CLI::Validator whole_number(std::uint64_t max);
CLI::Validator non_empty();

// How the commands draw their figures: plot::painter() (titles, axes, legends, scale
// bars; tools/plot), or io::plain_painter() in a build without cairo.
io::Painter figure_painter();

// Size of a file in KiB (of a folder's files for a folder; 0 when it cannot be read), a
// progress total.
std::uint64_t file_size_kib(const std::string& path);

// Skipped log lines named on stderr, of each kind (malformed, skipped on purpose), before
// the rest are only counted (io::write_log_errors).
inline constexpr std::size_t kLogErrorsShown = 20U;

// A subcommand: `setup` adds options to its CLI::App and returns the function that runs
// it after parsing (the function returns an ExitCode).
using CommandSetup = std::function<std::function<int()>(CLI::App&)>;

struct CommandInfo {
  const char* name;
  const char* description;
  int order;  // position in --help
  CommandSetup setup;
};

// Called by SDPSLAM_REGISTER_COMMAND at static-initialisation time.
bool register_command(const CommandInfo& info);

#define SDPSLAM_REGISTER_COMMAND(ident, name, description, order, setup_fn) \
  static const bool sdpslam_cli_registered_##ident =                        \
      ::sdpslam::cli::register_command(::sdpslam::cli::CommandInfo{name, description, order, setup_fn})

// The progress display of every long command, on stderr ("KiB 1200/13631  8.8%  412 KiB/s
// ETA 0:31").
class Progress {
 public:
  // On a terminal: one line redrawn at most every 200 ms (done/total, percent, rate,
  // ETA). Otherwise (a file, a pipe, a journal): the same figures as a plain line every
  // kPlainInterval, so logs stay readable. `quiet` (--quiet): nothing at all.
  static constexpr std::chrono::seconds kPlainInterval{10};
  Progress(std::string what, std::uint64_t total, bool quiet);
  ~Progress();
  void update(std::uint64_t done);
  void finish();

 private:
  std::string what_;
  std::uint64_t total_;
  bool terminal_;
  bool quiet_;
  bool finished_ = false;
  std::uint64_t drawn_ = 0;  // done at the last draw
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
};

// ROS bag input (io/log_reader.h, LogReaderOptions::bag_*): the topics a bag is read
// through, for every command that reads a log.
struct BagTopics {
  std::string scan_topic;
  std::string odom_topic;
  void apply(io::LogReaderOptions* o) const {
    o->bag_scan_topic = scan_topic;
    o->bag_odom_topic = odom_topic;
  }
};
inline void add_bag_options(CLI::App& app, BagTopics* t) {
  app.add_option("--scan-topic", t->scan_topic,
                 "ROS bag: the sensor_msgs/LaserScan topic (default: the bag's only one, or /scan)");
  app.add_option("--odom-topic", t->odom_topic,
                 "ROS bag: the nav_msgs/Odometry topic (default: the bag's only one, or /odom; with none, the "
                 "odom -> base_link transforms on /tf)");
}

}  // namespace sdpslam::cli
