#include "sdpslam/daemon/daemon_config.h"

#include "sdpslam/core/sdp_slam.h"
#include "sdpslam/daemon/slam_engine.h"
#include "sdpslam/drivers/serial_port.h"
#include "sdpslam/io/snapshot_file.h"
#include "sdpslam/slam/config_ini.h"
#include "sdpslam/slam/ini_document.h"
#include "sdpslam/slam/option_text.h"
#include "sdpslam/slam/run_localize.h"
#include "sdpslam/slam/run_sdp.h"

#include <sys/un.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace sdpslam::daemon {

const char* to_string(LaserProtocol p) { return p == LaserProtocol::kScip ? "scip" : "sick"; }
const char* to_string(SlamMode m) {
  return m == SlamMode::kDpSlam ? "dpslam" : m == SlamMode::kSdp ? "sdp" : "localize";
}

namespace {

bool parse_mode(const char* text, SlamMode* mode) {
  if (std::strcmp(text, "sdp") == 0) *mode = SlamMode::kSdp;
  else if (std::strcmp(text, "dpslam") == 0) *mode = SlamMode::kDpSlam;
  else if (std::strcmp(text, "localize") == 0) *mode = SlamMode::kLocalize;
  else return false;
  return true;
}

bool known_section(const std::string& sec) {
  static const char* const kOwn[] = {"can", "laser", "robot", "sync", "slam", "sdp", "localize", "output", "daemon"};
  for (const char* k : kOwn) {
    if (sec == k) return true;
  }
  return slam::is_slam_config_section(sec);
}

// Value parsers: each returns false with *why set.
bool real_in(const char* text, double lo, double hi, bool lo_open, double* out, std::string* why) {
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(text, &end);
  if (end == text || *end != '\0' || errno == ERANGE || !std::isfinite(v)) {
    *why = "'" + std::string(text) + "' is not a finite number";
    return false;
  }
  if ((lo_open ? v <= lo : v < lo) || v > hi) {
    char b[160];
    std::snprintf(b, sizeof b, "%s out of range %s%g, %g]", text, lo_open ? "(" : "[", lo, hi);
    *why = b;
    return false;
  }
  *out = v;
  return true;
}

bool int_in(const char* text, long long lo, long long hi, long long* out, std::string* why) {
  errno = 0;
  char* end = nullptr;
  const long long v = std::strtoll(text, &end, 0);
  if (end == text || *end != '\0' || errno == ERANGE) {
    *why = "'" + std::string(text) + "' is not an integer";
    return false;
  }
  if (v < lo || v > hi) {
    *why = std::string(text) + " out of range [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
    return false;
  }
  *out = v;
  return true;
}

// The one boolean dialect of every INI reader (option_text.h).
bool boolean(const char* text, bool* out, std::string* why) {
  if (slam::parse_bool_text(text, out)) return true;
  *why = "'" + std::string(text) + "' is not a boolean (true/false, yes/no, on/off, 1/0)";
  return false;
}

enum class R { kOk, kUnknown, kBad };

// ---- the daemon's own keys ------------------------------------------------------------
// Setters for the rows below: each returns false with *why set (without "section.key: ").

bool set_real(double* field, const char* v, double lo, double hi, bool lo_open, std::string* why) {
  double d = 0.0;
  if (!real_in(v, lo, hi, lo_open, &d, why)) return false;
  *field = d;
  return true;
}
// A duration given in ms (or s: `scale_us`), kept in µs.
bool set_us(std::int64_t* field, const char* v, double lo, double hi, double scale_us, std::string* why) {
  double d = 0.0;
  if (!real_in(v, lo, hi, false, &d, why)) return false;
  *field = static_cast<std::int64_t>(std::llround(d * scale_us));
  return true;
}
template <class T>
bool set_int(T* field, const char* v, long long lo, long long hi, std::string* why) {
  long long i = 0;
  if (!int_in(v, lo, hi, &i, why)) return false;
  *field = static_cast<T>(i);
  return true;
}
bool set_path(std::string* field, const char* v, const char* what, std::string* why) {
  if (*v == '\0') {
    *why = std::string("empty ") + what;
    return false;
  }
  *field = v;
  return true;
}
bool set_sign(int* field, const char* v, std::string* why) {
  long long i = 0;
  if (!int_in(v, -1, 1, &i, why) || i == 0) {
    *why = std::string(v) + ": a direction sign is 1 or -1";
    return false;
  }
  *field = static_cast<int>(i);
  return true;
}
std::string ms_text(std::int64_t us) { return slam::real_text(static_cast<double>(us) / 1000.0); }
std::string s_text(std::int64_t us) { return slam::real_text(static_cast<double>(us) / 1.0e6); }
std::string num(double v) { return slam::real_text(v); }
std::string bool_text(bool b) { return b ? "true" : "false"; }

using C = DaemonConfig;
using W = std::string*;

// Every key of the daemon's own sections, in the order of sdpslamd.ini (which documents
// each: test_config checks that it holds every row with its default). A row's range is
// its setter's; the checks that join keys run once the file is read (load_daemon_config).
const DaemonKey kKeys[] = {
    {"can", "interface", "", "1..15 characters", "SocketCAN interface",
     [](C& c, const char* v, W why) {
       const std::size_t n = std::strlen(v);
       if (n == 0U || n > 15U || std::strchr(v, '/') != nullptr || std::strchr(v, ' ') != nullptr) {
         *why = "interface name must be 1..15 characters without '/' or spaces";
         return false;
       }
       c.can_interface = v;
       return true;
     },
     [](const C& c) { return c.can_interface; }},
    {"can", "protocol", "", "canopen | odrive", "wheel encoders: CANopen (CiA 406 TPDO1) or ODrive (CAN Simple)",
     [](C& c, const char* v, W why) {
       if (drivers::parse_encoder_protocol(v, c.encoders.protocol)) return true;
       *why = "'" + std::string(v) + "' is not an encoder protocol (canopen, odrive)";
       return false;
     },
     [](const C& c) { return std::string(drivers::to_string(c.encoders.protocol)); }},
    // CANopen node ids are 1..127 (CiA 301), ODrive axis ids 0..63 (6 bits of the 11-bit
    // id): the range depends on [can] protocol, so it is checked once the file is read.
    {"can", "left_node", "", "CANopen 1..127, ODrive 0..63", "node id of the left wheel",
     [](C& c, const char* v, W why) {
       if (!set_int(&c.encoders.canopen.left_node, v, 0, 127, why)) return false;
       c.encoders.odrive.left_node = c.encoders.canopen.left_node;
       return true;
     },
     [](const C& c) { return std::to_string(c.encoders.canopen.left_node); }},
    {"can", "right_node", "", "CANopen 1..127, ODrive 0..63", "node id of the right wheel, not left_node",
     [](C& c, const char* v, W why) {
       if (!set_int(&c.encoders.canopen.right_node, v, 0, 127, why)) return false;
       c.encoders.odrive.right_node = c.encoders.canopen.right_node;
       return true;
     },
     [](const C& c) { return std::to_string(c.encoders.canopen.right_node); }},
    {"can", "position_bytes", "", "4 | 2", "CANopen TPDO1 position size",
     [](C& c, const char* v, W why) {
       long long i = 0;
       if (!int_in(v, 2, 4, &i, why) || i == 3) {
         *why = std::string(v) + ": position_bytes must be 2 or 4";
         return false;
       }
       c.encoders.canopen.position_bytes = static_cast<std::uint8_t>(i);
       return true;
     },
     [](const C& c) { return std::to_string(c.encoders.canopen.position_bytes); }},
    {"can", "send_nmt_start", "", "true | false", "CANopen: NMT start both nodes at start",
     [](C& c, const char* v, W why) { return boolean(v, &c.encoders.canopen.send_nmt_start, why); },
     [](const C& c) { return bool_text(c.encoders.canopen.send_nmt_start); }},
    {"can", "sync_period_ms", "ms", "[0, 1000]", "CANopen: produce SYNC this often (0 = another node does)",
     [](C& c, const char* v, W why) { return set_us(&c.encoders.canopen.sync_period_us, v, 0.0, 1000.0, 1e3, why); },
     [](const C& c) { return ms_text(c.encoders.canopen.sync_period_us); }},
    {"can", "position_timeout_ms", "ms", "[1, 10000]", "a wheel without a position for this long is stale",
     [](C& c, const char* v, W why) {
       if (!set_us(&c.encoders.canopen.position_timeout_us, v, 1.0, 10000.0, 1e3, why)) return false;
       c.encoders.odrive.position_timeout_us = c.encoders.canopen.position_timeout_us;
       return true;
     },
     [](const C& c) { return ms_text(c.encoders.canopen.position_timeout_us); }},
    {"can", "heartbeat_timeout_ms", "ms", "[0, 60000]", "heartbeat supervision (0 = off)",
     [](C& c, const char* v, W why) {
       if (!set_us(&c.encoders.canopen.heartbeat_timeout_us, v, 0.0, 60000.0, 1e3, why)) return false;
       c.encoders.odrive.heartbeat_timeout_us = c.encoders.canopen.heartbeat_timeout_us;
       return true;
     },
     [](const C& c) { return ms_text(c.encoders.canopen.heartbeat_timeout_us); }},
    {"can", "odrive_counts_per_turn", "", "[1, 1e7]", "ODrive: counter counts per encoder turn",
     [](C& c, const char* v, W why) { return set_real(&c.encoders.odrive.counts_per_turn, v, 1.0, 1e7, false, why); },
     [](const C& c) { return num(c.encoders.odrive.counts_per_turn); }},
    {"can", "odrive_request_period_ms", "ms", "[0, 1000]", "ODrive: RTR request period (0 = axes stream)",
     [](C& c, const char* v, W why) { return set_us(&c.encoders.odrive.request_period_us, v, 0.0, 1000.0, 1e3, why); },
     [](const C& c) { return ms_text(c.encoders.odrive.request_period_us); }},
    {"can", "reopen_interval_ms", "ms", "[10, 60000]", "interface down or bus-off: re-open attempt period",
     [](C& c, const char* v, W why) { return set_us(&c.can_reopen_interval_us, v, 10.0, 60000.0, 1e3, why); },
     [](const C& c) { return ms_text(c.can_reopen_interval_us); }},
    {"laser", "device", "", "1..127 characters", "serial device of the laser",
     [](C& c, const char* v, W why) {
       if (*v == '\0' || std::strlen(v) > drivers::SerialOptions::kMaxPathChars) {
         *why = "device path must be 1..127 characters";
         return false;
       }
       c.laser_device = v;
       return true;
     },
     [](const C& c) { return c.laser_device; }},
    {"laser", "protocol", "", "scip | sick", "Hokuyo URG (SCIP 2.0) or SICK LMS200/291",
     [](C& c, const char* v, W why) {
       const std::string p(v);
       if (p == "scip") {
         c.laser_protocol = LaserProtocol::kScip;
       } else if (p == "sick") {
         c.laser_protocol = LaserProtocol::kSick;
       } else {
         *why = "'" + p + "' is not a laser protocol (scip, sick)";
         return false;
       }
       return true;
     },
     [](const C& c) { return std::string(to_string(c.laser_protocol)); }},
    {"laser", "baud", "", "9600 .. 921600 standard rates", "SCIP line speed (ignored over USB-ACM)",
     [](C& c, const char* v, W why) {
       static constexpr long long kRates[] = {9600,   19200,  38400,  57600,  115200, 230400,
                                              250000, 460800, 500000, 750000, 921600};
       long long i = 0;
       if (!int_in(v, 1, 4000000, &i, why)) return false;
       for (long long r : kRates) {
         if (r == i) {
           c.laser_baud = static_cast<std::uint32_t>(i);
           return true;
         }
       }
       *why = std::string(v) + " is not a supported line speed (9600 ... 921600)";
       return false;
     },
     [](const C& c) { return std::to_string(c.laser_baud); }},
    {"laser", "scip_cluster", "", "1..99", "SCIP: steps merged per beam",
     [](C& c, const char* v, W why) { return set_int(&c.urg.cluster, v, 1, 99, why); },
     [](const C& c) { return std::to_string(c.urg.cluster); }},
    {"laser", "sick_baud", "", "9600 | 19200 | 38400 | 500000", "SICK: line speed switched to after start",
     [](C& c, const char* v, W why) {
       if (!set_int(&c.sick.target_baud, v, 9600, 500000, why)) return false;
       if (drivers::validate(c.sick)) return true;
       *why = std::string(v) + ": the LMS2xx offers 9600, 19200, 38400 or 500000";
       return false;
     },
     [](const C& c) { return std::to_string(c.sick.target_baud); }},
    // The variant (angle and resolution together) is checked once the file is read.
    {"laser", "sick_angle_deg", "deg", "100 | 180", "SICK scan variant",
     [](C& c, const char* v, W why) { return set_int(&c.sick.angle_deg, v, 1, 180, why); },
     [](const C& c) { return std::to_string(c.sick.angle_deg); }},
    {"laser", "sick_resolution_cdeg", "1/100 deg", "25 | 50 | 100", "SICK angular step",
     [](C& c, const char* v, W why) { return set_int(&c.sick.resolution_cdeg, v, 1, 180, why); },
     [](const C& c) { return std::to_string(c.sick.resolution_cdeg); }},
    {"laser", "reply_timeout_ms", "ms", "[10, 60000]", "a command without reply is re-sent after this",
     [](C& c, const char* v, W why) {
       if (!set_us(&c.urg.reply_timeout_us, v, 10.0, 60000.0, 1e3, why)) return false;
       c.sick.reply_timeout_us = c.urg.reply_timeout_us;
       return true;
     },
     [](const C& c) { return ms_text(c.urg.reply_timeout_us); }},
    {"laser", "stall_timeout_ms", "ms", "[10, 60000]", "streaming without a scan this long restarts the sensor",
     [](C& c, const char* v, W why) {
       if (!set_us(&c.urg.stall_timeout_us, v, 10.0, 60000.0, 1e3, why)) return false;
       c.sick.stall_timeout_us = c.urg.stall_timeout_us;
       return true;
     },
     [](const C& c) { return ms_text(c.urg.stall_timeout_us); }},
    {"laser", "reopen_interval_ms", "ms", "[10, 60000]", "unplugged device: re-open attempt period",
     [](C& c, const char* v, W why) { return set_us(&c.laser_reopen_interval_us, v, 10.0, 60000.0, 1e3, why); },
     [](const C& c) { return ms_text(c.laser_reopen_interval_us); }},
    {"laser", "x_m", "m", "[-10, 10]", "laser mounting pose in the base frame: x forward",
     [](C& c, const char* v, W why) { return set_real(&c.laser_in_base.x_m, v, -10.0, 10.0, false, why); },
     [](const C& c) { return num(c.laser_in_base.x_m); }},
    {"laser", "y_m", "m", "[-10, 10]", "y left",
     [](C& c, const char* v, W why) { return set_real(&c.laser_in_base.y_m, v, -10.0, 10.0, false, why); },
     [](const C& c) { return num(c.laser_in_base.y_m); }},
    {"laser", "heading_rad", "rad", "[-pi, pi]", "rotation",
     [](C& c, const char* v, W why) {
       return set_real(&c.laser_in_base.heading_rad, v, -det::kPi, det::kPi, false, why);
     },
     [](const C& c) { return num(c.laser_in_base.heading_rad); }},
    {"robot", "ticks_per_rev", "", "> 0", "encoder counts per encoder revolution",
     [](C& c, const char* v, W why) { return set_real(&c.drive.ticks_per_rev, v, 0.0, 1e9, true, why); },
     [](const C& c) { return num(c.drive.ticks_per_rev); }},
    {"robot", "gear_ratio", "", "> 0", "wheel revolutions per encoder revolution",
     [](C& c, const char* v, W why) { return set_real(&c.drive.gear_ratio, v, 0.0, 1e6, true, why); },
     [](const C& c) { return num(c.drive.gear_ratio); }},
    {"robot", "left_radius_m", "m", "(0, 5]", "left wheel radius",
     [](C& c, const char* v, W why) { return set_real(&c.drive.left_radius_m, v, 0.0, 5.0, true, why); },
     [](const C& c) { return num(c.drive.left_radius_m); }},
    {"robot", "right_radius_m", "m", "(0, 5]", "right wheel radius",
     [](C& c, const char* v, W why) { return set_real(&c.drive.right_radius_m, v, 0.0, 5.0, true, why); },
     [](const C& c) { return num(c.drive.right_radius_m); }},
    {"robot", "wheel_separation_m", "m", "(0, 20]", "distance between the wheel contact points",
     [](C& c, const char* v, W why) { return set_real(&c.drive.wheel_separation_m, v, 0.0, 20.0, true, why); },
     [](const C& c) { return num(c.drive.wheel_separation_m); }},
    {"robot", "left_sign", "", "1 | -1", "counts increase when the wheel drives forward",
     [](C& c, const char* v, W why) { return set_sign(&c.drive.left_sign, v, why); },
     [](const C& c) { return std::to_string(c.drive.left_sign); }},
    {"robot", "right_sign", "", "1 | -1", "the same for the right wheel",
     [](C& c, const char* v, W why) { return set_sign(&c.drive.right_sign, v, why); },
     [](const C& c) { return std::to_string(c.drive.right_sign); }},
    {"robot", "counter_bits", "", "16 | 32", "encoder counter width",
     [](C& c, const char* v, W why) {
       long long i = 0;
       if (!int_in(v, 16, 32, &i, why) || (i != 16 && i != 32)) {
         *why = std::string(v) + ": counter_bits must be 16 or 32";
         return false;
       }
       c.drive.counter_bits = static_cast<std::uint8_t>(i);
       return true;
     },
     [](const C& c) { return std::to_string(c.drive.counter_bits); }},
    {"sync", "odometry_wait_ms", "ms", "[0, 5000]", "a scan newer than the newest odometry waits this long",
     [](C& c, const char* v, W why) { return set_us(&c.odometry_wait_us, v, 0.0, 5000.0, 1e3, why); },
     [](const C& c) { return ms_text(c.odometry_wait_us); }},
    {"sync", "max_interpolation_gap_ms", "ms", "[1, 10000]", "odometry samples farther apart are not interpolated",
     [](C& c, const char* v, W why) { return set_us(&c.max_interpolation_gap_us, v, 1.0, 10000.0, 1e3, why); },
     [](const C& c) { return ms_text(c.max_interpolation_gap_us); }},
    {"sync", "scan_queue", "", "1..16", "scans waiting for odometry",
     [](C& c, const char* v, W why) { return set_int(&c.scan_queue, v, 1, DaemonConfig::kMaxScanQueue, why); },
     [](const C& c) { return std::to_string(c.scan_queue); }},
    {"slam", "mode", "", "sdp | dpslam | localize", "SDP-SLAM, the bottom filter alone, or localization on a map",
     [](C& c, const char* v, W why) {
       if (parse_mode(v, &c.mode)) return true;
       *why = "'" + std::string(v) + "' is not a SLAM mode (sdp, dpslam, localize)";
       return false;
     },
     [](const C& c) { return std::string(to_string(c.mode)); }},
    {"slam", "profile", "", "accurate | paper", "where sdp mode's options start",
     [](C& c, const char* v, W why) {
       if (parse_sdp_profile(v, &c.profile)) return true;
       *why = "'" + std::string(v) + "' is not a profile (accurate, paper)";
       return false;
     },
     [](const C& c) { return std::string(to_string(c.profile)); }},
    {"slam", "seed", "", ">= 0", "random seed (same input and seed, same output)",
     [](C& c, const char* v, W why) {
       long long i = 0;
       if (*v == '-' || !int_in(v, 0, 0x7FFFFFFFFFFFFFFFLL, &i, why)) {
         if (why->empty()) *why = std::string(v) + " is not a non-negative integer";
         return false;
       }
       c.seed = static_cast<std::uint64_t>(i);
       return true;
     },
     [](const C& c) { return std::to_string(c.seed); }},
    {"localize", "map", "", "a path or empty", "the saved map (its map.yaml); required in mode localize",
     [](C& c, const char* v, W) {
       c.localize_map = v;  // empty: none (mode localize refuses that once the file is read)
       return true;
     },
     [](const C& c) { return c.localize_map; }},
    {"localize", "start", "m, m, rad", "x, y, theta or empty", "the start pose in the map (empty: global localization)",
     [](C& c, const char* v, W why) {
       if (*v == '\0') {
         c.localize_have_start = false;
         return true;
       }
       if (!slam::parse_start_pose(v, &c.localize_start)) {
         *why = "'" + std::string(v) + "' is not a pose x, y, theta (m, m, rad) in the map's frame";
         return false;
       }
       c.localize_have_start = true;
       return true;
     },
     [](const C& c) {
       return c.localize_have_start
                  ? num(c.localize_start.x_m) + ", " + num(c.localize_start.y_m) + ", " + num(c.localize_start.heading_rad)
                  : std::string();
     }},
    {"localize", "min_particles", "", "[10, 1000000]", "KLD sampling floor",
     [](C& c, const char* v, W why) { return set_int(&c.localize.min_particles, v, 10, 1000000, why); },
     [](const C& c) { return std::to_string(c.localize.min_particles); }},
    {"localize", "max_particles", "", "[10, 1000000]", "KLD sampling ceiling (and memory)",
     [](C& c, const char* v, W why) { return set_int(&c.localize.max_particles, v, 10, 1000000, why); },
     [](const C& c) { return std::to_string(c.localize.max_particles); }},
    {"output", "directory", "", "a path", "where maps, trajectories and status go",
     [](C& c, const char* v, W why) { return set_path(&c.output_directory, v, "output directory", why); },
     [](const C& c) { return c.output_directory; }},
    {"output", "period_s", "s", "[0.1, 3600]", "outputs written this often",
     [](C& c, const char* v, W why) { return set_us(&c.output_period_us, v, 0.1, 3600.0, 1e6, why); },
     [](const C& c) { return s_text(c.output_period_us); }},
    {"output", "max_trajectory_scans", "", "[1, 10000000]", "trajectory poses kept",
     [](C& c, const char* v, W why) { return set_int(&c.max_trajectory_scans, v, 1, 10000000, why); },
     [](const C& c) { return std::to_string(c.max_trajectory_scans); }},
    {"output", "write_map", "", "true | false", "write the map with the outputs",
     [](C& c, const char* v, W why) { return boolean(v, &c.write_map, why); },
     [](const C& c) { return bool_text(c.write_map); }},
    {"output", "input_log", "", "true | false", "record every scan fed to SLAM to <directory>/input.clf",
     [](C& c, const char* v, W why) { return boolean(v, &c.input_log, why); },
     [](const C& c) { return bool_text(c.input_log); }},
    {"output", "pose_socket", "", "a path or empty", "each placed scan's pose to this UNIX datagram socket (empty: off)",
     [](C& c, const char* v, W why) {
       if (std::strlen(v) >= sizeof(sockaddr_un{}.sun_path)) {
         *why = "a socket path has at most " + std::to_string(sizeof(sockaddr_un{}.sun_path) - 1U) + " bytes";
         return false;
       }
       c.pose_socket = v;
       return true;
     },
     [](const C& c) { return c.pose_socket; }},
    {"output", "snapshot_interval_s", "s", "[0, 86400]", "mode sdp: the whole state saved this often (0 = never)",
     [](C& c, const char* v, W why) { return set_us(&c.snapshot_interval_us, v, 0.0, 86400.0, 1e6, why); },
     [](const C& c) { return s_text(c.snapshot_interval_us); }},
    {"daemon", "log_interval_s", "s", "[0, 3600]", "one log line per event kind at most this often",
     [](C& c, const char* v, W why) { return set_us(&c.log_interval_us, v, 0.0, 3600.0, 1e6, why); },
     [](const C& c) { return s_text(c.log_interval_us); }},
    {"daemon", "loop_slice_ms", "ms", "[0.1, 100]", "longest wait on the laser before CAN is read",
     [](C& c, const char* v, W why) { return set_us(&c.loop_slice_us, v, 0.1, 100.0, 1e3, why); },
     [](const C& c) { return ms_text(c.loop_slice_us); }},
    {"daemon", "memory_budget_mib", "MiB", "[8, 65536]", "the SLAM state may not exceed this",
     [](C& c, const char* v, W why) { return set_int(&c.memory_budget_mib, v, 8, 65536, why); },
     [](const C& c) { return std::to_string(c.memory_budget_mib); }},
};

R handle_key(DaemonConfig& c, const std::string& sec, const std::string& key, const char* v, std::string* why) {
  if (sec == "sdp") {
    // The offline runner's own [sdp] reading: same keys, values and ranges; its reasons
    // already name "sdp.key".
    switch (slam::apply_sdp_key(&c.sdp, key, v, why)) {
      case slam::SdpKeyResult::kApplied: return R::kOk;
      case slam::SdpKeyResult::kInvalid: return R::kBad;
      case slam::SdpKeyResult::kUnknown: return R::kUnknown;
    }
  }
  if (slam::is_slam_config_section(sec)) {
    switch (slam::apply_config_key(&c.slam, sec, key, v, why)) {
      case slam::ConfigKeyResult::kApplied: return R::kOk;
      case slam::ConfigKeyResult::kInvalid: return R::kBad;
      case slam::ConfigKeyResult::kUnknown: return R::kUnknown;
    }
  }
  for (const DaemonKey& k : kKeys) {
    if (sec == k.section && key == k.key) return k.apply(c, v, why) ? R::kOk : R::kBad;
  }
  return R::kUnknown;
}

// Keys whose value the SLAM state depends on: a snapshot resumes only under the same
// (the drivers, the outputs' timing and the daemon's own keys may change in between).
bool shapes_slam_state(const std::string& sec, const char* name) {
  if (sec == "slam" || sec == "sdp") return true;
  if (sec == "output") return std::strcmp(name, "max_trajectory_scans") == 0;
  return slam::is_slam_config_section(sec);
}

}  // namespace

const DaemonKey* daemon_keys(std::size_t* count) {
  *count = sizeof kKeys / sizeof kKeys[0];
  return kKeys;
}

std::string effective_config_ini(const DaemonConfig& config) {
  std::string out;
  const char* section = nullptr;
  for (const DaemonKey& k : kKeys) {
    if (section == nullptr || std::strcmp(section, k.section) != 0) {
      section = k.section;
      out += (out.empty() ? "[" : "\n[") + std::string(section) + "]\n";
    }
    out += slam::ini_option_line(k.key, k.text(config), k.unit, k.range, k.doc);
  }
  out += "\n" + slam::options_ini_text(DpSlamOptions::table(), config.slam.filter);
  out += "\n" + slam::options_ini_text(slam::log_option_table(), config.slam.log);
  if (config.mode == SlamMode::kSdp) out += "\n" + slam::options_ini_text(SdpOptions::table(), config.sdp);
  return out;
}

bool load_daemon_config(const std::string& path, DaemonConfig* config, std::string* error) {
  std::FILE* f = slam::open_config_file(path, error);
  if (f == nullptr) return false;
  const bool ok = load_daemon_config(f, path, config, error);
  std::fclose(f);
  return ok;
}

bool load_daemon_config(std::FILE* f, const std::string& path, DaemonConfig* config, std::string* error) {
  // One INI reader for every program (slam/ini_document.h): the whole file first.
  slam::IniDocument doc;
  if (!doc.read(f, path, error)) return false;
  // The [slam] profile (sdp mode) is where the options start: the file's keys go on top of
  // it wherever they appear in the file (malformed values are refused below).
  for (const slam::IniEntry& e : doc.entries()) {
    if (e.section != "slam") continue;
    if (e.key == "mode") (void)parse_mode(e.value.c_str(), &config->mode);
    if (e.key == "profile") (void)parse_sdp_profile(e.value.c_str(), &config->profile);
  }
  if (config->mode == SlamMode::kSdp) apply_profile(config->profile, &config->slam.filter, &config->sdp);
  // The file's first problem, in line order: an unknown section (even one without keys),
  // a refused key, or a line refused as read.
  int problem_line = doc.problem_line();
  std::string problem = doc.problem();
  for (const auto& sec : doc.sections()) {
    if (known_section(sec.first) || (problem_line != 0 && sec.second > problem_line)) continue;
    problem_line = sec.second;
    problem = doc.at(sec.second, "unknown section [" + sec.first + "]");
    break;
  }
  int first_sdp_line = 0;  // the first [sdp] key and the [slam] profile key, for mode dpslam's warning
  int profile_line = 0;
  // "section.key=value" of every key that shapes the SLAM state (DaemonConfig::slam_fingerprint).
  std::vector<std::string> slam_keys;
  for (const slam::IniEntry& e : doc.entries()) {
    if (problem_line != 0 && e.line > problem_line) break;
    std::string why;
    const R r = handle_key(*config, e.section, e.key, e.value.c_str(), &why);
    if (r != R::kOk) {
      if (r == R::kUnknown) why = "unknown key '" + e.key + "' in section [" + e.section + "]";
      else if (!slam::is_slam_config_section(e.section) && e.section != "sdp") why = e.section + "." + e.key + ": " + why;
      problem_line = e.line;
      problem = doc.at(e.line, why);
      break;
    }
    if (e.section == "sdp" && first_sdp_line == 0) first_sdp_line = e.line;
    if (e.section == "slam" && e.key == "profile") profile_line = e.line;
    if (shapes_slam_state(e.section, e.key.c_str())) slam_keys.push_back(e.section + "." + e.key + "=" + e.value);
  }
  {
    // Order-free: the same keys with the same values give the same fingerprint.
    std::sort(slam_keys.begin(), slam_keys.end());
    std::string text = std::string("mode=") + to_string(config->mode) + "\nprofile=" + to_string(config->profile) + "\n";
    for (const std::string& k : slam_keys) text += k + "\n";
    config->slam_fingerprint = io::fingerprint(text);
  }
  if (problem_line != 0) {
    *error = problem;
    return false;
  }
  // Keys that only sdp mode reads are not refused in mode dpslam (a file switches mode by
  // one key), but said to have no effect.
  config->warnings.clear();
  if (config->mode == SlamMode::kDpSlam) {
    if (first_sdp_line > 0) {
      config->warnings.push_back(path + ":" + std::to_string(first_sdp_line) +
                                 ": [sdp] keys have no effect in mode dpslam");
    }
    if (profile_line > 0) {
      config->warnings.push_back(path + ":" + std::to_string(profile_line) +
                                 ": slam.profile has no effect in mode dpslam");
    }
  }
  // Checks that involve several keys, once everything is read. A refusal is named with
  // the line of the file that set the key it names.
  const std::string at = path + ": ";
  auto refuse = [&](const std::string& reason) {
    const std::string located = doc.locate(reason);
    *error = located != reason ? located : at + reason;
    return false;
  };
  {
    const bool canopen = config->encoders.protocol == drivers::EncoderProtocol::kCanOpen;
    const drivers::CanOpenEncoderOptions& co = config->encoders.canopen;
    for (const char* side : {"left_node", "right_node"}) {
      const unsigned n = std::strcmp(side, "left_node") == 0 ? co.left_node : co.right_node;
      if (canopen ? (n < 1U || n > 127U) : n > 63U) {
        return refuse(std::string("can.") + side + ": " + std::to_string(n) +
                      (canopen ? " out of range [1, 127] (CANopen node id)" : " out of range [0, 63] (ODrive axis id)"));
      }
    }
    if (co.left_node == co.right_node) return refuse("can.right_node: left_node and right_node are the same node");
  }
  if (config->laser_protocol == LaserProtocol::kSick && !drivers::validate(config->sick)) {
    *error = at + "laser: the LMS2xx has no variant sick_angle_deg = " + std::to_string(config->sick.angle_deg) +
             ", sick_resolution_cdeg = " + std::to_string(config->sick.resolution_cdeg);
    return false;
  }
  if (drivers::validate(config->drive) != drivers::DiffDriveParamsError::kOk) {
    *error = at + "robot: " + drivers::to_string(drivers::validate(config->drive));
    return false;
  }
  char why[240];
  if (!config->slam.filter.validate(why, sizeof why)) return refuse(why);
  // Every check SDP-SLAM's init makes (SdpSlam::check_options): what is approved here starts.
  if (config->mode == SlamMode::kSdp && !SdpSlam::check_options(config->slam.filter, config->sdp, why, sizeof why)) {
    return refuse(why);
  }
  if (config->mode == SlamMode::kLocalize) {
    if (config->localize_map.empty()) {
      *error = at + "localize.map: mode localize needs the saved map (its map.yaml)";
      return false;
    }
    if (!config->localize.check(why, sizeof why)) return refuse(std::string("localize.") + why);
    // The map is read here, as at start: an unreadable map is refused before any work.
    slam::LocalizationMap map;
    std::string map_error;
    if (!slam::load_localization_map(config->localize_map, &map, &map_error)) return refuse("localize.map: " + map_error);
  }
  // The whole state is sized here, before any work: what is approved here can start.
  const std::size_t arena_bytes = engine_arena_bytes(*config);
  if (arena_bytes == 0U) {
    *error = at + "the SLAM options size no valid state (a map or pool capacity beyond what the core can address)";
    return false;
  }
  const double arena_mb = static_cast<double>(arena_bytes) / (1024.0 * 1024.0);
  if (arena_mb > static_cast<double>(config->memory_budget_mib)) {
    char b[300];
    std::snprintf(b, sizeof b,
                  "the SLAM state needs %.1f MiB, above [daemon] memory_budget_mib = %u (lower the [map]/[sdp] capacities "
                  "or raise the budget, and the unit's MemoryMax= with it)",
                  arena_mb, config->memory_budget_mib);
    *error = at + b;
    return false;
  }
  return true;
}

}  // namespace sdpslam::daemon
