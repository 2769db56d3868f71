// `sdpslam convert IN OUT`: any supported log (CARMEN, tinySLAM, DP-SLAM, optionally .gz;
// ROS 1 and ROS 2 bags) to a CARMEN log of ODOM and FLASER/ROBOTLASER1 lines, or with
// `--to ros2` to a ROS 2 bag (io/bags.h). Malformed input lines are
// skipped and listed ("file:line: reason"); an input with no scan and no odometry left
// is refused (exit 3) and OUT is not written.

#include <cstdio>
#include <memory>
#include <string>

#include "cli_common.h"
#include "sdpslam/io/carmen_writer.h"
#include "sdpslam/io/log_reader.h"
#include "sdpslam/io/bags.h"

namespace sdpslam::cli {
namespace {

constexpr std::size_t kErrorsPrinted = 20;

struct ConvertArgs {
  std::string in;
  bool quiet = false;
  std::string out;
  std::string format = "auto";
  std::string to = "carmen";
  io::WheelOdometryParams wheels;
  BagTopics bag;
};

// `--to ros2`: a rosbag2 folder (io/bags.h); the log's odometry records only pair
// with its scans, whose odometry the bag carries.
int convert_to_ros2(const ConvertArgs& a, io::LogReader& reader) {
  io::Ros2BagWriter writer;
  std::string error;
  if (!writer.open(a.out, &error)) {
    std::fprintf(stderr, "sdpslam convert: %s\n", error.c_str());
    return io::ros2_bags_supported() ? kExitIo : kExitUsage;
  }
  Progress progress("KiB", file_size_kib(a.in), a.quiet);
  for (;;) {
    const io::LogReader::Next n = reader.next();
    if (n == io::LogReader::Next::kEnd) break;
    if (n == io::LogReader::Next::kOdom) writer.odom(reader.odom());
    if (n == io::LogReader::Next::kLaser) {
      if (!writer.laser(reader.laser(), &error)) {
        std::fprintf(stderr, "sdpslam convert: %s\n", error.c_str());
        return kExitIo;
      }
    }
    progress.update(reader.input_offset() / 1024U);
  }
  progress.finish();
  io::write_log_errors(stderr, reader.errors(), reader.error_count(), kLogErrorsShown);
  if (writer.scans_written() == 0U) {
    std::fprintf(stderr, "sdpslam convert: %s: no laser scan with odometry in it: nothing to convert\n",
                 a.in.c_str());
    return kExitBadInput;  // the writer abandons its folder
  }
  if (!writer.close(&error)) {
    std::fprintf(stderr, "sdpslam convert: %s\n", error.c_str());
    return kExitIo;
  }
  std::printf("converted %s (%s): %llu scans (%llu before any odometry, left out) -> ROS 2 bag %s\n", a.in.c_str(),
              io::to_string(reader.format()), static_cast<unsigned long long>(writer.scans_written()),
              static_cast<unsigned long long>(writer.scans_without_odometry()), a.out.c_str());
  return kExitOk;
}

int run_convert(const ConvertArgs& a) {
  io::LogReaderOptions options;
  options.wheels = a.wheels;
  options.max_errors_kept = kErrorsPrinted;
  a.bag.apply(&options);
  if (a.format == "carmen") options.format = io::LogFormat::kCarmen;
  if (a.format == "tinyslam") options.format = io::LogFormat::kTinySlam;
  if (a.format == "dpslam") options.format = io::LogFormat::kDpSlam;
  if (a.format == "rosbag") options.format = io::LogFormat::kRosBag;
  if (a.format == "ros2bag") options.format = io::LogFormat::kRos2Bag;

  io::LogReader reader;
  std::string error;
  if (!reader.open(a.in, options, &error)) {
    std::fprintf(stderr, "sdpslam convert: %s\n", error.c_str());
    return kExitBadInput;
  }
  if (a.to == "ros2") return convert_to_ros2(a, reader);
  io::CarmenWriter writer;
  if (!writer.open(a.out, &error)) {
    std::fprintf(stderr, "sdpslam convert: %s\n", error.c_str());
    return kExitIo;
  }
  writer.comment("converted by sdpslam from " + a.in + " (" + io::to_string(reader.format()) + ")");

  Progress progress("KiB", file_size_kib(a.in), a.quiet);
  std::uint64_t lasers = 0;
  std::uint64_t odoms = 0;
  std::uint64_t params = 0;
  // Formats without ODOM lines (tinySLAM, ROS bags) get one per scan from the scan's odometry pose.
  const bool synth_odom = reader.format() == io::LogFormat::kTinySlam || reader.format() == io::LogFormat::kRosBag ||
                          reader.format() == io::LogFormat::kRos2Bag;
  for (;;) {
    const io::LogReader::Next n = reader.next();
    if (n == io::LogReader::Next::kEnd) break;
    if (n == io::LogReader::Next::kLaser) {
      const io::LaserRecord& l = reader.laser();
      if (synth_odom && l.has_odom_pose) {
        io::OdomRecord o;
        o.stamp_us = l.stamp_us;
        o.logger_stamp_us = l.logger_stamp_us;
        o.pose = l.odom_pose;
        writer.odom(o);
        ++odoms;
      }
      writer.laser(l);
      ++lasers;
    } else if (n == io::LogReader::Next::kOdom) {
      writer.odom(reader.odom());
      ++odoms;
    } else {
      writer.param(reader.param().name, reader.param().value);
      ++params;
    }
    progress.update(reader.input_offset() / 1024U);
  }
  progress.finish();

  io::write_log_errors(stderr, reader.errors(), reader.error_count(), kLogErrorsShown);
  // A log with no scan and no odometry left has nothing a log is for: refused, and OUT
  // is not written (the writer's temporary file is abandoned), whatever else it held.
  if (lasers == 0U && odoms == 0U) {
    std::fprintf(stderr,
                 "sdpslam convert: %s: no laser scan and no odometry in %lld lines (%zu skipped): nothing to "
                 "convert\n",
                 a.in.c_str(), static_cast<long long>(reader.lines_read()), reader.error_count());
    return kExitBadInput;
  }
  if (!writer.close(&error)) {
    std::fprintf(stderr, "sdpslam convert: %s\n", error.c_str());
    return kExitIo;
  }
  // A bag's "lines" are its scan messages (LogReader::lines_read()); it names its topics.
  const bool bag = reader.format() == io::LogFormat::kRosBag || reader.format() == io::LogFormat::kRos2Bag;
  std::printf("converted %s (%s%s%s): %llu scans, %llu odometry, %llu params from %lld %s -> %s\n", a.in.c_str(),
              io::to_string(reader.format()), bag ? ": " : "", bag ? reader.source_description().c_str() : "",
              static_cast<unsigned long long>(lasers), static_cast<unsigned long long>(odoms),
              static_cast<unsigned long long>(params), static_cast<long long>(reader.lines_read()),
              bag ? "scan messages" : "lines", a.out.c_str());
  if (reader.error_count() > 0) {
    std::fprintf(stderr, "warning: %zu input lines skipped (%zu of them unknown message types)\n",
                 reader.error_count(), reader.warning_count());
  }
  return kExitOk;
}

std::function<int()> setup_convert(CLI::App& app) {
  auto args = std::make_shared<ConvertArgs>();
  app.add_option("IN", args->in, "input log (.clf, tinySLAM .dat, DP-SLAM .log; .gz accepted; ROS 1 .bag; ROS 2 bag folder or .db3)")->required();
  app.add_option("OUT", args->out, "output CARMEN log (written atomically)")->required();
  app.add_flag("--quiet", args->quiet, "no progress display (errors, warnings and the summary still print)");
  app.add_option("--format", args->format, "input format")
      ->check(CLI::IsMember({"auto", "carmen", "tinyslam", "dpslam", "rosbag", "ros2bag"}))
      ->capture_default_str();
  app.add_option("--to", args->to,
                 "output: carmen (a CARMEN log file) or ros2 (a rosbag2 folder: /scan, /odom, /tf, /tf_static; "
                 "SQLite storage, CDR)")
      ->check(CLI::IsMember({"carmen", "ros2"}))
      ->capture_default_str();
  app.add_option("--ticks-per-rev", args->wheels.ticks_per_rev, "encoder ticks per wheel revolution (tinySLAM)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--wheel-radius", args->wheels.wheel_radius_m, "wheel radius, m (tinySLAM)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--wheel-separation", args->wheels.wheel_separation_m, "distance between the wheels, m (tinySLAM)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  add_bag_options(app, &args->bag);
  return [args] { return run_convert(*args); };
}

}  // namespace

SDPSLAM_REGISTER_COMMAND(convert, "convert", "convert a robot log (CARMEN, tinySLAM, DP-SLAM, ROS 1 or 2 bag) to a CARMEN log or a ROS 2 bag", 20,
                         setup_convert);

}  // namespace sdpslam::cli
