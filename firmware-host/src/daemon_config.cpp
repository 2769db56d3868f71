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

R handle_key(DaemonConfig& c, const std::string& sec, const std::string& key, const char* v, std::string* why) {
  double d = 0.0;
  long long i = 0;
  auto ok = [](bool b) { return b ? R::kOk : R::kBad; };
  auto ms = [&](std::int64_t& field, double lo, double hi, bool lo_open) {
    if (!real_in(v, lo, hi, lo_open, &d, why)) return R::kBad;
    field = static_cast<std::int64_t>(std::llround(d * 1000.0));
    return R::kOk;
  };
  auto real = [&](double& field, double lo, double hi, bool lo_open) {
    if (!real_in(v, lo, hi, lo_open, &d, why)) return R::kBad;
    field = d;
    return R::kOk;
  };
  auto path = [&](std::string& field, const char* what) {
    if (*v == '\0') {
      *why = std::string("empty ") + what;
      return R::kBad;
    }
    field = v;
    return R::kOk;
  };
  if (sec == "can") {
    drivers::CanOpenEncoderOptions& co = c.encoders.canopen;
    drivers::ODriveEncoderOptions& od = c.encoders.odrive;
    if (key == "interface") {
      const std::size_t n = std::strlen(v);
      if (n == 0U || n > 15U || std::strchr(v, '/') != nullptr || std::strchr(v, ' ') != nullptr) {
        *why = "interface name must be 1..15 characters without '/' or spaces";
        return R::kBad;
      }
      c.can_interface = v;
      return R::kOk;
    }
    if (key == "protocol") {
      if (!drivers::parse_encoder_protocol(v, c.encoders.protocol)) {
        *why = "'" + std::string(v) + "' is not an encoder protocol (canopen, odrive)";
        return R::kBad;
      }
      return R::kOk;
    }
    if (key == "left_node" || key == "right_node") {
      // CANopen node ids are 1..127 (CiA 301), ODrive axis ids 0..63 (6 bits of the 11-bit
      // id): the range depends on [can] protocol, so it is checked once the file is read.
      if (!int_in(v, 0, 127, &i, why)) return R::kBad;
      const auto n = static_cast<std::uint8_t>(i);
      (key == "left_node" ? co.left_node : co.right_node) = n;
      (key == "left_node" ? od.left_node : od.right_node) = n;
      return R::kOk;
    }
    if (key == "position_bytes") {
      if (!int_in(v, 2, 4, &i, why) || i == 3) {
        *why = std::string(v) + ": position_bytes must be 2 or 4";
        return R::kBad;
      }
      co.position_bytes = static_cast<std::uint8_t>(i);
      return R::kOk;
    }
    if (key == "send_nmt_start") return ok(boolean(v, &co.send_nmt_start, why));
    if (key == "sync_period_ms") return ms(co.sync_period_us, 0.0, 1000.0, false);
    if (key == "position_timeout_ms") {
      const R r = ms(co.position_timeout_us, 1.0, 10000.0, false);
      od.position_timeout_us = co.position_timeout_us;
      return r;
    }
    if (key == "heartbeat_timeout_ms") {
      const R r = ms(co.heartbeat_timeout_us, 0.0, 60000.0, false);
      od.heartbeat_timeout_us = co.heartbeat_timeout_us;
      return r;
    }
    if (key == "odrive_counts_per_turn") return real(od.counts_per_turn, 1.0, 1e7, false);
    if (key == "odrive_request_period_ms") return ms(od.request_period_us, 0.0, 1000.0, false);
    if (key == "reopen_interval_ms") return ms(c.can_reopen_interval_us, 10.0, 60000.0, false);
  } else if (sec == "laser") {
    if (key == "device") {
      if (*v == '\0' || std::strlen(v) > drivers::SerialOptions::kMaxPathChars) {
        *why = "device path must be 1..127 characters";
        return R::kBad;
      }
      c.laser_device = v;
      return R::kOk;
    }
    if (key == "protocol") {
      const std::string p(v);
      if (p == "scip") c.laser_protocol = LaserProtocol::kScip;
      else if (p == "sick") c.laser_protocol = LaserProtocol::kSick;
      else {
        *why = "'" + p + "' is not a laser protocol (scip, sick)";
        return R::kBad;
      }
      return R::kOk;
    }
    if (key == "baud") {
      static constexpr long long kRates[] = {9600, 19200, 38400, 57600, 115200, 230400, 250000, 460800, 500000, 750000, 921600};
      if (!int_in(v, 1, 4000000, &i, why)) return R::kBad;
      for (long long r : kRates) {
        if (r == i) {
          c.laser_baud = static_cast<std::uint32_t>(i);
          return R::kOk;
        }
      }
      *why = std::string(v) + " is not a supported line speed (9600 ... 921600)";
      return R::kBad;
    }
    if (key == "scip_cluster") {
      if (!int_in(v, 1, 99, &i, why)) return R::kBad;
      c.urg.cluster = static_cast<std::uint32_t>(i);
      return R::kOk;
    }
    if (key == "sick_baud") {
      if (!int_in(v, 9600, 500000, &i, why)) return R::kBad;
      c.sick.target_baud = static_cast<std::uint32_t>(i);
      if (!drivers::validate(c.sick)) {
        *why = std::string(v) + ": the LMS2xx offers 9600, 19200, 38400 or 500000";
        return R::kBad;
      }
      return R::kOk;
    }
    if (key == "sick_angle_deg" || key == "sick_resolution_cdeg") {
      if (!int_in(v, 1, 180, &i, why)) return R::kBad;
      (key == "sick_angle_deg" ? c.sick.angle_deg : c.sick.resolution_cdeg) = static_cast<std::uint16_t>(i);
      return R::kOk;  // the combination is checked once the file is read
    }
    if (key == "reply_timeout_ms") {
      const R r = ms(c.urg.reply_timeout_us, 10.0, 60000.0, false);
      c.sick.reply_timeout_us = c.urg.reply_timeout_us;
      return r;
    }
    if (key == "stall_timeout_ms") {
      const R r = ms(c.urg.stall_timeout_us, 10.0, 60000.0, false);
      c.sick.stall_timeout_us = c.urg.stall_timeout_us;
      return r;
    }
    if (key == "reopen_interval_ms") return ms(c.laser_reopen_interval_us, 10.0, 60000.0, false);
    if (key == "x_m") return real(c.laser_in_base.x_m, -10.0, 10.0, false);
    if (key == "y_m") return real(c.laser_in_base.y_m, -10.0, 10.0, false);
    if (key == "heading_rad") return real(c.laser_in_base.heading_rad, -det::kPi, det::kPi, false);
  } else if (sec == "robot") {
    drivers::DiffDriveParams& p = c.drive;
    if (key == "ticks_per_rev") return real(p.ticks_per_rev, 0.0, 1e9, true);
    if (key == "gear_ratio") return real(p.gear_ratio, 0.0, 1e6, true);
    if (key == "left_radius_m") return real(p.left_radius_m, 0.0, 5.0, true);
    if (key == "right_radius_m") return real(p.right_radius_m, 0.0, 5.0, true);
    if (key == "wheel_separation_m") return real(p.wheel_separation_m, 0.0, 20.0, true);
    if (key == "left_sign" || key == "right_sign") {
      if (!int_in(v, -1, 1, &i, why) || i == 0) {
        *why = std::string(v) + ": a direction sign is 1 or -1";
        return R::kBad;
      }
      (key == "left_sign" ? p.left_sign : p.right_sign) = static_cast<int>(i);
      return R::kOk;
    }
    if (key == "counter_bits") {
      if (!int_in(v, 16, 32, &i, why) || (i != 16 && i != 32)) {
        *why = std::string(v) + ": counter_bits must be 16 or 32";
        return R::kBad;
      }
      p.counter_bits = static_cast<std::uint8_t>(i);
      return R::kOk;
    }
  } else if (sec == "sync") {
    if (key == "odometry_wait_ms") return ms(c.odometry_wait_us, 0.0, 5000.0, false);
    if (key == "max_interpolation_gap_ms") return ms(c.max_interpolation_gap_us, 1.0, 10000.0, false);
    if (key == "scan_queue") {
      if (!int_in(v, 1, DaemonConfig::kMaxScanQueue, &i, why)) return R::kBad;
      c.scan_queue = static_cast<std::uint32_t>(i);
      return R::kOk;
    }
  } else if (sec == "slam") {
    if (key == "mode") {
      if (!parse_mode(v, &c.mode)) {
        *why = "'" + std::string(v) + "' is not a SLAM mode (sdp, dpslam, localize)";
        return R::kBad;
      }
      return R::kOk;
    }
    if (key == "profile") {
      if (!parse_sdp_profile(v, &c.profile)) {
        *why = "'" + std::string(v) + "' is not a profile (accurate, paper)";
        return R::kBad;
      }
      return R::kOk;
    }
    if (key == "seed") {
      if (*v == '-' || !int_in(v, 0, 0x7FFFFFFFFFFFFFFFLL, &i, why)) {
        if (why->empty()) *why = std::string(v) + " is not a non-negative integer";
        return R::kBad;
      }
      c.seed = static_cast<std::uint64_t>(i);
      return R::kOk;
    }
  } else if (sec == "sdp") {
    // The offline runner's own [sdp] parser: same keys, values and ranges; its reasons
    // already name "[sdp] key" or the option.
    switch (slam::apply_sdp_key(&c.sdp, key, v, why)) {
      case slam::SdpKeyResult::kApplied: return R::kOk;
      case slam::SdpKeyResult::kInvalid: return R::kBad;
      case slam::SdpKeyResult::kUnknown: return R::kUnknown;
    }
  } else if (sec == "localize") {
    if (key == "map") return path(c.localize_map, "map path");
    if (key == "start") {
      if (*v == '\0') {  // empty: global localization
        c.localize_have_start = false;
        return R::kOk;
      }
      if (!slam::parse_start_pose(v, &c.localize_start)) {
        *why = "'" + std::string(v) + "' is not a pose x, y, theta (m, m, rad) in the map's frame";
        return R::kBad;
      }
      c.localize_have_start = true;
      return R::kOk;
    }
    if (key == "min_particles" || key == "max_particles") {
      if (!int_in(v, 10, 1000000, &i, why)) return R::kBad;
      (key == "min_particles" ? c.localize.min_particles : c.localize.max_particles) = static_cast<std::uint32_t>(i);
      return R::kOk;
    }
  } else if (sec == "output") {
    if (key == "directory") return path(c.output_directory, "output directory");
    if (key == "period_s") {
      if (!real_in(v, 0.1, 3600.0, false, &d, why)) return R::kBad;
      c.output_period_us = static_cast<std::int64_t>(std::llround(d * 1e6));
      return R::kOk;
    }
    if (key == "max_trajectory_scans") {
      if (!int_in(v, 1, 10000000, &i, why)) return R::kBad;
      c.max_trajectory_scans = static_cast<std::uint32_t>(i);
      return R::kOk;
    }
    if (key == "write_map") return ok(boolean(v, &c.write_map, why));
    if (key == "input_log") return ok(boolean(v, &c.input_log, why));
    if (key == "pose_socket") {
      if (std::strlen(v) >= sizeof(sockaddr_un{}.sun_path)) {
        *why = "a socket path has at most " + std::to_string(sizeof(sockaddr_un{}.sun_path) - 1U) + " bytes";
        return R::kBad;
      }
      c.pose_socket = v;
      return R::kOk;
    }
    if (key == "snapshot_interval_s") {
      if (!real_in(v, 0.0, 86400.0, false, &d, why)) return R::kBad;
      c.snapshot_interval_us = static_cast<std::int64_t>(std::llround(d * 1e6));
      return R::kOk;
    }
  } else if (sec == "daemon") {
    if (key == "log_interval_s") {
      if (!real_in(v, 0.0, 3600.0, false, &d, why)) return R::kBad;
      c.log_interval_us = static_cast<std::int64_t>(std::llround(d * 1e6));
      return R::kOk;
    }
    if (key == "loop_slice_ms") return ms(c.loop_slice_us, 0.1, 100.0, false);
    if (key == "memory_budget_mib") {
      if (!int_in(v, 8, 65536, &i, why)) return R::kBad;
      c.memory_budget_mib = static_cast<std::uint32_t>(i);
      return R::kOk;
    }
  } else {
    std::string slam_why;
    switch (slam::apply_config_key(&c.slam, sec, key, v, &slam_why)) {
      case slam::ConfigKeyResult::kApplied: return R::kOk;
      case slam::ConfigKeyResult::kInvalid: *why = slam_why; return R::kBad;
      case slam::ConfigKeyResult::kUnknown:
        if (!slam::is_slam_config_section(sec)) {
          *why = "unknown section [" + sec + "]";
          return R::kBad;
        }
        break;
    }
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
