#pragma once
// sdpslamd's configuration: one INI file (libinih), every key documented in
// firmware-host/sdpslamd.ini. Sections:
//   [can]     interface, encoder protocol (canopen | odrive), node ids, SYNC period,
//             position / heartbeat timeouts, re-open interval
//   [laser]   serial device, protocol (scip | sick), line speed, timeouts, mounting pose
//   [robot]   differential-drive geometry (drivers::DiffDriveParams)
//   [sync]    odometry-to-scan alignment: wait bound, largest gap interpolated, queue
//   [slam]    mode (sdp | dpslam | localize), profile (sdp mode's starting options, applied before
//             every other key wherever it stands) and seed; the filter's own sections [filter] [motion]
//             [observation] [proposal] [map] [capacity] [log] are the offline runner's
//             (firmware-host/runtime/slam/default.ini), parsed by the same code (slam::apply_config_key)
//   [sdp]     SDP-SLAM's segmentation and top level (mode = sdp), the offline runner's
//             [sdp] keys, parsed by the same code (slam::apply_sdp_key); read in either
//             mode, used in sdp mode only. The bottom level of sdp mode is [filter] etc.,
//             with [filter] particles as B (the offline runner takes B from --particles)
//   [localize] mode = localize: the saved map, the start pose (none: global localization)
//             and the particle counts of core/localization (Monte Carlo localization)
//   [output]  directory, write period, trajectory capacity, map, input recording
//   [daemon]  event-log rate limit, loop slice
// Unknown sections and keys, malformed and out-of-range values are rejected as
// "file:line: reason"; keys left out keep their defaults.
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "sdpslam/core/localization/monte_carlo_localizer.h"
#include "sdpslam/core/pose2.h"
#include "sdpslam/core/sdp_options.h"
#include "sdpslam/core/sdp_profile.h"
#include "sdpslam/drivers/can_wheel_encoders.h"
#include "sdpslam/drivers/diff_drive_odometry.h"
#include "sdpslam/drivers/sick_lms2xx_laser.h"
#include "sdpslam/drivers/urg_scip2_laser.h"
#include "sdpslam/slam/config_ini.h"

namespace sdpslam::daemon {

enum class LaserProtocol : std::uint8_t { kScip, kSick };
enum class SlamMode : std::uint8_t { kDpSlam, kSdp, kLocalize };
const char* to_string(LaserProtocol p);
const char* to_string(SlamMode m);

struct DaemonConfig {
  // [can]
  std::string can_interface = "can0";
  // The documented defaults (sdpslamd.ini): nodes 1 and 2 for either protocol, and
  // sdpslamd produces the CANopen SYNC every 10 ms.
  drivers::CanWheelEncoderConfig encoders = default_encoders();
  std::int64_t can_reopen_interval_us = 500000;
  // [laser]
  std::string laser_device = "/dev/ttyACM0";
  LaserProtocol laser_protocol = LaserProtocol::kScip;
  std::uint32_t laser_baud = 115200U;
  std::int64_t laser_reopen_interval_us = 500000;
  drivers::UrgOptions urg;
  drivers::SickOptions sick;
  Pose2 laser_in_base;
  // [robot]
  drivers::DiffDriveParams drive;
  // [sync]
  std::int64_t odometry_wait_us = 200000;    // a scan waits this long for newer odometry
  std::int64_t max_interpolation_gap_us = 250000;
  std::uint32_t scan_queue = 4U;             // scans waiting for odometry, 1 .. kMaxScanQueue
  // [slam]
  // SDP-SLAM, the project's algorithm (the offline runner's default too): with the example's
  // options its arena is smaller than dpslam's (sdpslamd.ini [slam] gives the figures).
  SlamMode mode = SlamMode::kSdp;
  // Where sdp mode's options start (core/sdp_profile.h), as `sdpslam run --profile`:
  // load_daemon_config applies it before the file's keys (accurate: scan-matching
  // proposals and loop closure; paper: the paper's algorithm).
  SdpProfile profile = kDefaultSdpProfile;
  std::uint64_t seed = 1U;
  slam::SlamConfig slam;
  // [sdp]
  SdpOptions sdp;
  // [localize]
  std::string localize_map;        // map.yaml (map_server convention); required in mode localize
  bool localize_have_start = false;
  Pose2 localize_start;            // map frame
  LocalizerOptions localize;
  // [output]
  std::string output_directory = "/var/lib/sdpslamd";
  std::int64_t output_period_us = 5000000;
  std::uint32_t max_trajectory_scans = 200000U;
  bool write_map = true;
  bool input_log = false;                    // stream every scan fed to SLAM to <directory>/input.clf
  // Each placed scan's pose to the subscribers of this UNIX datagram socket (empty: off;
  // pose_publisher.h).
  std::string pose_socket;
  // Mode sdp: the whole SLAM state goes to <directory>/snapshot.sdps this often (and at
  // a stop), and a start resumes from it (0 = never; snapshot_file.h, Daemon).
  std::int64_t snapshot_interval_us = 300000000;
  // Set by load_daemon_config: a hash of the mode, the profile and every key that shapes
  // the SLAM state ([slam], [sdp], the filter's sections, [output] max_trajectory_scans),
  // whatever their order in the file. A snapshot resumes only under the same.
  std::uint64_t slam_fingerprint = 0U;
  // [daemon]
  std::int64_t log_interval_us = 1000000;    // one line per event kind at most this often
  std::int64_t loop_slice_us = 5000;         // longest wait on the laser before CAN is read
  // The SLAM arena (the whole SLAM state, sized once at start) may not exceed this; the
  // unit's MemoryMax= (sdpslamd.service) leaves room above it for the rest of the
  // process (drivers, queues, the map rendered for output).
  std::uint32_t memory_budget_mib = 128U;
  // Set by load_daemon_config: "file:line: ..." for keys the chosen mode does not read.
  std::vector<std::string> warnings;

  static constexpr std::uint32_t kMaxScanQueue = 16U;

  static drivers::CanWheelEncoderConfig default_encoders() {
    drivers::CanWheelEncoderConfig e;
    e.canopen.left_node = 1U;
    e.canopen.right_node = 2U;
    e.canopen.sync_period_us = 10000;
    e.odrive.left_node = 1U;
    e.odrive.right_node = 2U;
    return e;
  }
};

// Applies the keys of `path` on top of *config. False iff the file cannot be read, a line
// is malformed (slam::read_ini_line's refusals included), a section or key is unknown, or
// a value is malformed or out of range; `error` is then "file:line: reason" (the first
// problem; *config is then unspecified).
// Checks that involve several keys (SICK variant, drive geometry, filter options, and in
// sdp mode the [sdp] options and the bottom options SDP-SLAM derives from [filter] etc.)
// run once the file is read and name the file and the section.
// One key of sdpslamd's own sections ([can] [laser] [robot] [sync] [slam] [localize]
// [output] [daemon]): a row of the daemon's option table, as DpSlamOptions::table() and
// SdpOptions::table() are for the SLAM sections. sdpslamd.ini documents every row with
// its default (test_config checks it).
struct DaemonKey {
  const char* section;
  const char* key;
  const char* unit;   // "ms", "m", "" ...
  const char* range;  // as documented
  const char* doc;    // one line
  // Reads the value: false, with *why, when it is malformed or outside the key's own
  // range (checks that join keys run once the whole file is read).
  bool (*apply)(DaemonConfig& config, const char* value, std::string* why);
  std::string (*text)(const DaemonConfig& config);  // the value as its INI text
};
// The table, in the order of sdpslamd.ini.
const DaemonKey* daemon_keys(std::size_t* count);
// The configuration in effect as INI (`sdpslamd --check-config`): the daemon's own keys,
// then the SLAM options (the filter's sections; [sdp] in mode sdp) with the profile and
// the file applied. It reads back as the same configuration.
std::string effective_config_ini(const DaemonConfig& config);

bool load_daemon_config(const std::string& path, DaemonConfig* config, std::string* error);
// The same from an open stream, which is read twice (the [slam] profile first) and so must
// be seekable; it is not closed. `name` stands for the file in messages.
bool load_daemon_config(std::FILE* stream, const std::string& name, DaemonConfig* config, std::string* error);

}  // namespace sdpslam::daemon
