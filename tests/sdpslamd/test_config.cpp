// sdpslamd configuration: the shipped example loads; every rejection names file:line.
#include <CppUTest/TestHarness.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "sdpslam/daemon/daemon_config.h"
#include "sdpslam/slam/option_text.h"
#include "sdpslam/slam/ini_document.h"
#include "sdpslam/daemon/slam_engine.h"
#include "sdpslam/io/map_image.h"
#include "sdpslam/slam/run_sdp.h"
#include "shared_data.h"
#include "yaml_statics.h"  // localize mode reads a map YAML

using sdpslam::daemon::DaemonConfig;
using sdpslam::daemon::load_daemon_config;

namespace {

std::string write_ini(const std::string& text) {
  static int n = 0;
  const std::string dir = sdpslam::test::make_temp_dir("sdpslamd_config");
  const std::string path = dir + "/c" + std::to_string(n++) + ".ini";
  std::FILE* f = std::fopen(path.c_str(), "w");
  std::fputs(text.c_str(), f);
  std::fclose(f);
  return path;
}

// Loads `text`; expects failure with an error that starts "<path>:<line>:" and contains `what`.
void expect_rejected(const std::string& text, int line, const std::string& what) {
  DaemonConfig c;
  std::string error;
  const std::string path = write_ini(text);
  CHECK_FALSE(load_daemon_config(path, &c, &error));
  const std::string prefix = path + ":" + std::to_string(line) + ":";
  if (error.rfind(prefix, 0) != 0 || error.find(what) == std::string::npos) {
    FAIL(("expected '" + prefix + " ..." + what + "', got '" + error + "'").c_str());
  }
}

}  // namespace

TEST_GROUP(SdpslamdConfig){};

TEST(SdpslamdConfig, shipped_example_config_loads_with_documented_defaults) {
  DaemonConfig c;
  std::string error;
  CHECK_TRUE_TEXT(load_daemon_config(SDPSLAMD_EXAMPLE_INI, &c, &error), error.c_str());
  STRCMP_EQUAL("can0", c.can_interface.c_str());
  LONGS_EQUAL(10, c.slam.filter.particle_count);
  LONGS_EQUAL(10000, c.encoders.canopen.sync_period_us);
  DOUBLES_EQUAL(0.33, c.drive.wheel_separation_m, 1e-12);
  LONGS_EQUAL(5000000, c.output_period_us);
}

// Every key the shipped sdpslamd.ini sets has its built-in value: the file documents the
// defaults, it does not change them. Derived from the option tables (the daemon's keys,
// DpSlamOptions::table, SdpOptions::table): every daemon key is in the file (set, or
// commented where it has no default), and every key the file sets is a row of a table.
TEST(SdpslamdConfig, the_shipped_file_sets_every_key_to_its_built_in_default) {
  DaemonConfig shipped;
  DaemonConfig empty;
  std::string error;
  CHECK_TRUE_TEXT(load_daemon_config(SDPSLAMD_EXAMPLE_INI, &shipped, &error), error.c_str());
  CHECK_TRUE_TEXT(load_daemon_config(write_ini(""), &empty, &error), error.c_str());
  sdpslam::slam::IniDocument doc;
  CHECK_TRUE_TEXT(doc.load(SDPSLAMD_EXAMPLE_INI, &error), error.c_str());
  std::ifstream in(SDPSLAMD_EXAMPLE_INI);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::size_t n = 0;
  const sdpslam::daemon::DaemonKey* keys = sdpslam::daemon::daemon_keys(&n);
  CHECK(n > 40U);
  for (std::size_t i = 0; i < n; ++i) {
    const std::string name = std::string(keys[i].section) + "." + keys[i].key;
    const bool set = doc.line_of(keys[i].section, keys[i].key) > 0;
    CHECK_TEXT(set || text.find("; " + std::string(keys[i].key) + " =") != std::string::npos,
               ("sdpslamd.ini does not document " + name).c_str());
    CHECK_TEXT(keys[i].doc[0] != '\0' && keys[i].range[0] != '\0', name.c_str());
    STRCMP_EQUAL_TEXT(keys[i].text(empty).c_str(), keys[i].text(shipped).c_str(), name.c_str());
  }
  for (const auto& row : sdpslam::DpSlamOptions::table()) {
    STRCMP_EQUAL_TEXT(sdpslam::slam::option_text(row, empty.slam.filter).c_str(),
                      sdpslam::slam::option_text(row, shipped.slam.filter).c_str(), row.key);
  }
  for (const auto& row : sdpslam::SdpOptions::table()) {
    STRCMP_EQUAL_TEXT(sdpslam::slam::option_text(row, empty.sdp).c_str(),
                      sdpslam::slam::option_text(row, shipped.sdp).c_str(), row.key);
  }
  for (const sdpslam::slam::IniEntry& e : doc.entries()) {
    bool known = sdpslam::DpSlamOptions::table().find(e.section.c_str(), e.key.c_str()) != nullptr ||
                 sdpslam::SdpOptions::table().find(e.section.c_str(), e.key.c_str()) != nullptr ||
                 sdpslam::slam::log_option_table().find(e.section.c_str(), e.key.c_str()) != nullptr;
    for (std::size_t i = 0; i < n && !known; ++i) known = e.section == keys[i].section && e.key == keys[i].key;
    CHECK_TEXT(known, (e.section + "." + e.key + " is in no option table").c_str());
  }
}

// --check-config prints the configuration in effect; read back, it is the same.
TEST(SdpslamdConfig, the_effective_configuration_reads_back_as_itself) {
  DaemonConfig c;
  std::string error;
  CHECK_TRUE_TEXT(load_daemon_config(write_ini("[can]\nprotocol = odrive\nleft_node = 0\n[laser]\nx_m = 0.12\n"
                                               "[localize]\nstart = 1, 2, 0.5\n[slam]\nprofile = paper\n[sdp]\n"
                                               "top_particles = 40\n[output]\npose_socket = /run/p.sock\n"),
                                     &c, &error),
                  error.c_str());
  const std::string text = sdpslam::daemon::effective_config_ini(c);
  STRCMP_CONTAINS("\nleft_node = 0 ", text.c_str());
  STRCMP_CONTAINS("\nstart = 1, 2, 0.5 ", text.c_str());
  STRCMP_CONTAINS("\ntop_particles = 40 ", text.c_str());
  STRCMP_CONTAINS("\nkind = odometry ", text.c_str());  // the paper profile's
  DaemonConfig again;
  CHECK_TRUE_TEXT(load_daemon_config(write_ini(text), &again, &error), error.c_str());
  STRCMP_EQUAL(text.c_str(), sdpslam::daemon::effective_config_ini(again).c_str());
}

TEST(SdpslamdConfig, shipped_example_starts_sdp_from_the_accurate_profile) {
  DaemonConfig c;
  std::string error;
  CHECK_TRUE_TEXT(load_daemon_config(SDPSLAMD_EXAMPLE_INI, &c, &error), error.c_str());
  CHECK(c.profile == sdpslam::SdpProfile::kAccurate);
  CHECK(c.slam.filter.proposal == sdpslam::DpSlamOptions::Proposal::kScanMatch);
  LONGS_EQUAL(8, c.slam.filter.match.beam_stride);
  CHECK_TRUE(c.sdp.loop_closure);
  DOUBLES_EQUAL(6.0, c.sdp.loop_search_window_m, 0.0);
  LONGS_EQUAL(8, c.sdp.max_levels);
}

TEST(SdpslamdConfig, profile_applies_before_every_key_wherever_it_stands) {
  // The profile comes last in the file, yet the keys before it win over it.
  DaemonConfig c;
  std::string error;
  CHECK_TRUE_TEXT(load_daemon_config(write_ini("[sdp]\nmax_levels = 5\n[proposal]\nbeam_stride = 3\n"
                                               "[slam]\nmode = sdp\nprofile = accurate\n"),
                                     &c, &error),
                  error.c_str());
  LONGS_EQUAL(5, c.sdp.max_levels);
  LONGS_EQUAL(3, c.slam.filter.match.beam_stride);
  CHECK_TRUE(c.sdp.loop_closure);  // from the profile
  CHECK(c.slam.filter.proposal == sdpslam::DpSlamOptions::Proposal::kScanMatch);
}

TEST(SdpslamdConfig, paper_profile_keeps_the_papers_algorithm) {
  DaemonConfig c;
  std::string error;
  CHECK_TRUE_TEXT(load_daemon_config(write_ini("[slam]\nprofile = paper\n"), &c, &error), error.c_str());
  CHECK(c.slam.filter.proposal == sdpslam::DpSlamOptions::Proposal::kOdometry);
  CHECK_FALSE(c.sdp.loop_closure);
  LONGS_EQUAL(12, c.sdp.max_levels);
}

TEST(SdpslamdConfig, dpslam_mode_does_not_take_the_profile) {
  DaemonConfig c;
  std::string error;
  CHECK_TRUE_TEXT(load_daemon_config(write_ini("[slam]\nprofile = accurate\nmode = dpslam\n"), &c, &error),
                  error.c_str());
  CHECK(c.slam.filter.proposal == sdpslam::DpSlamOptions::Proposal::kOdometry);
}

TEST(SdpslamdConfig, unknown_profile_is_rejected_with_its_line) {
  expect_rejected("[slam]\nmode = sdp\nprofile = best\n", 3, "slam.profile: 'best' is not a profile (accurate, paper)");
}

TEST(SdpslamdConfig, values_are_applied_to_every_part) {
  DaemonConfig c;
  std::string error;
  const std::string path = write_ini(
      "[can]\nprotocol = odrive\nleft_node = 0\nright_node = 3\n[laser]\ndevice = /dev/ttyUSB1\nprotocol = sick\n"
      "[robot]\nleft_sign = -1\ncounter_bits = 16\n[slam]\nseed = 42\n[filter]\nparticles = 7\n[sync]\n"
      "odometry_wait_ms = 50\n");
  CHECK_TRUE_TEXT(load_daemon_config(path, &c, &error), error.c_str());
  CHECK(c.encoders.protocol == sdpslam::drivers::EncoderProtocol::kODrive);
  LONGS_EQUAL(3, c.encoders.odrive.right_node);
  STRCMP_EQUAL("/dev/ttyUSB1", c.laser_device.c_str());
  LONGS_EQUAL(-1, c.drive.left_sign);
  LONGS_EQUAL(16, c.drive.counter_bits);
  LONGS_EQUAL(42, c.seed);
  LONGS_EQUAL(7, c.slam.filter.particle_count);
  LONGS_EQUAL(50000, c.odometry_wait_us);
}

TEST(SdpslamdConfig, unknown_section_is_rejected_at_its_line_even_when_empty) {
  expect_rejected("[can]\ninterface = can1\n\n[lidar]\n", 4, "unknown section [lidar]");
}

// The state is sized when the file is read: a capacity beyond what the core addresses, or
// a state above the declared budget, is refused before any work (not at start, not by an
// out-of-memory abort that systemd would restart in a loop).
TEST(SdpslamdConfig, a_state_the_core_cannot_address_or_above_the_budget_is_refused) {
  expect_rejected("[sdp]\nmap_observation_capacity = 3758096384\n", 2, "out of range [0, 1073741824]");
  DaemonConfig c;
  std::string error;
  const std::string big = write_ini("[sdp]\nmap_observation_capacity = 1000000000\n");
  CHECK_FALSE(load_daemon_config(big, &c, &error));
  STRCMP_CONTAINS("above [daemon] memory_budget_mib = 128", error.c_str());
  DaemonConfig d;
  const std::string small = write_ini("[daemon]\nmemory_budget_mib = 32\n");
  CHECK_FALSE(load_daemon_config(small, &d, &error));
  STRCMP_CONTAINS("memory_budget_mib = 32", error.c_str());
  DaemonConfig e;
  CHECK_TEXT(load_daemon_config(write_ini("[daemon]\nmemory_budget_mib = 4096\n[sdp]\nmap_observation_capacity = 20000000\n"),
                                &e, &error),
             error.c_str());
  expect_rejected("[daemon]\nmemory_budget_mib = 12.5\n", 2, "not an integer");
}

// A binary file given as the config: the first line with a control byte is refused as
// such, and the message carries none of the file's bytes (a terminal escape sequence
// would otherwise reach the user's terminal).
TEST(SdpslamdConfig, a_binary_file_is_refused_without_echoing_its_bytes) {
  const std::string text = "[can]\ninterface = can0\x1b]0;owned\x07\n\x7f" "ELF\x02\x01\n";
  expect_rejected(text, 2, "control byte 0x1B in the line (not a text file?)");
  DaemonConfig c;
  std::string error;
  CHECK_FALSE(load_daemon_config(write_ini(text), &c, &error));
  for (const char ch : error) CHECK_TEXT(static_cast<unsigned char>(ch) >= 0x20 && ch != 0x7F, error.c_str());
}

// The lines of the shipped systemd unit (firmware-host/systemd/sdpslamd.service).
std::vector<std::string> unit_lines() {
  std::string unit = SDPSLAMD_EXAMPLE_INI;
  unit = unit.substr(0, unit.rfind('/')) + "/systemd/sdpslamd.service";
  std::ifstream in(unit);
  CHECK_TEXT(in.good(), unit.c_str());
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// The unit's MemoryMax= sits above the default budget of the state, with room for the
// rest of the process.
TEST(SdpslamdConfig, the_units_memory_ceiling_is_above_the_default_state_budget) {
  long max_mib = 0;
  for (const std::string& line : unit_lines()) {
    if (std::sscanf(line.c_str(), "MemoryMax=%ldM", &max_mib) == 1) break;
  }
  const DaemonConfig defaults;
  CHECK_TEXT(max_mib >= 2L * defaults.memory_budget_mib, "MemoryMax= missing or below twice the state budget");
}

// The unit names no device (the config does, and sdpslamd waits for each), so a robot
// with can1 or a late USB adapter needs no drop-in; its device policy lets every serial
// UART a robot computer has through: USB adapters, PC UARTs, the Raspberry Pi's (ttyAMA)
// and the Jetson's (ttyTHS).
TEST(SdpslamdConfig, the_unit_names_no_device_and_allows_the_uarts_of_robot_computers) {
  std::string allowed;
  for (const std::string& l : unit_lines()) {
    if (l.empty() || l[0] == '#') continue;
    for (const char* dep : {"After=", "Wants=", "Requires=", "BindsTo=", "PartOf="}) {
      if (l.compare(0, std::strlen(dep), dep) == 0) {
        CHECK_TEXT(l.find("can") == std::string::npos && l.find("dev-") == std::string::npos &&
                       l.find("sys-subsystem") == std::string::npos,
                   l.c_str());
      }
    }
    if (l.compare(0, 12, "DeviceAllow=") == 0) allowed += l;
  }
  for (const char* uart : {"char-ttyACM rw", "char-ttyUSB rw", "char-ttyS rw", "char-ttyAMA rw", "char-ttyTHS rw"}) {
    CHECK_TEXT(allowed.find(uart) != std::string::npos, uart);
  }
}

// Either would make the file mean what its last occurrence says.
TEST(SdpslamdConfig, a_section_or_a_key_given_twice_is_rejected_at_its_line) {
  expect_rejected("[can]\ninterface = can1\n[laser]\ndevice = /dev/ttyACM0\n[can]\n", 5,
                  "section [can] given twice");
  expect_rejected("[laser]\ndevice = /dev/ttyACM0\ndevice = /dev/ttyUSB0\n", 3,
                  "key 'device' given twice in section [laser]");
  expect_rejected("[sdp]\ntop_particles = 30\n[filter]\nparticles = 10\n[sdp]\nloop_closure = true\n", 5,
                  "section [sdp] given twice");
}

TEST(SdpslamdConfig, unknown_key_is_rejected_with_its_line) {
  expect_rejected("[laser]\ndevice = /dev/ttyACM0\nspeed = 3\n", 3, "unknown key 'speed' in section [laser]");
}

TEST(SdpslamdConfig, out_of_range_node_id_is_rejected) {
  expect_rejected("[can]\nprotocol = canopen\nleft_node = 128\n", 3, "out of range [0, 127]");
  expect_rejected("[can]\nprotocol = canopen\nleft_node = 0\n", 3, "can.left_node: 0 out of range [1, 127]");
  expect_rejected("[can]\nright_node = 64\nprotocol = odrive\n", 2, "can.right_node: 64 out of range [0, 63]");
}

// The node ids' range depends on the protocol: the file's order does not matter.
TEST(SdpslamdConfig, node_ids_may_come_before_the_protocol) {
  sdpslam::daemon::DaemonConfig c;
  std::string error;
  CHECK_TRUE_TEXT(load_daemon_config(write_ini("[can]\nleft_node = 0\nright_node = 1\nprotocol = odrive\n"), &c, &error),
                  error.c_str());
  LONGS_EQUAL(0, c.encoders.odrive.left_node);
}

TEST(SdpslamdConfig, same_node_for_both_wheels_is_rejected) {
  expect_rejected("[can]\nleft_node = 4\nright_node = 4\n", 3, "same node");
}

TEST(SdpslamdConfig, zero_direction_sign_is_rejected) {
  expect_rejected("[robot]\nticks_per_rev = 4096\nleft_sign = 0\n", 3, "1 or -1");
}

TEST(SdpslamdConfig, malformed_number_is_rejected) {
  expect_rejected("[robot]\nwheel_separation_m = 0.3x\n", 2, "not a finite number");
}

TEST(SdpslamdConfig, negative_wheel_radius_is_rejected) {
  expect_rejected("[robot]\nleft_radius_m = -0.1\n", 2, "out of range (0");
}

TEST(SdpslamdConfig, unknown_protocols_and_modes_are_rejected) {
  expect_rejected("[laser]\nprotocol = lms500\n", 2, "not a laser protocol");
  expect_rejected("[can]\nprotocol = j1939\n", 2, "not an encoder protocol");
  expect_rejected("[slam]\nmode = gmapping\n", 2, "not a SLAM mode");
}

TEST(SdpslamdConfig, slam_option_goes_through_the_offline_parser_with_its_line) {
  expect_rejected("[slam]\nmode = dpslam\n[filter]\nparticles = 0\n", 4, "particles");
  expect_rejected("[observation]\nno_such_key = 1\n", 2, "unknown key 'no_such_key' in section [observation]");
}

TEST(SdpslamdConfig, unsupported_baud_rate_is_rejected) {
  expect_rejected("[laser]\nbaud = 12345\n", 2, "not a supported line speed");
}

TEST(SdpslamdConfig, scan_queue_beyond_capacity_is_rejected) {
  expect_rejected("[sync]\nscan_queue = 17\n", 2, "out of range [1, 16]");
}

TEST(SdpslamdConfig, malformed_line_is_rejected_with_its_line) {
  expect_rejected("[output]\nperiod_s = 2\nthis line has no equals sign\n", 3, "malformed line");
}

// As in the offline reader (fuzz_slam_config found the first): a malformed line was
// reported as a later line's problem, and a line over inih's 199-byte buffer was cut, its
// end read as the next line.
TEST(SdpslamdConfig, the_first_problem_is_reported_at_its_own_line) {
  expect_rejected("[can]\nbroken\nbogus = 1\n", 2, "malformed line");
  expect_rejected("[output]\ndirectory = /" + std::string(250U, 'd') + "\n", 2, "line longer than 198 characters");
}

TEST(SdpslamdConfig, missing_file_is_reported) {
  DaemonConfig c;
  std::string error;
  CHECK_FALSE(load_daemon_config("/nonexistent/sdpslamd.ini", &c, &error));
  CHECK(error.find("/nonexistent/sdpslamd.ini: cannot open") == 0);
}

// `sdpslamd --config /etc --check-config` used to answer "ok" and run the built-in defaults.
TEST(SdpslamdConfig, a_directory_is_refused_as_a_config_file) {
  const std::string dir = sdpslam::test::make_temp_dir("sdpslamd_config_dir");
  DaemonConfig c;
  std::string error;
  CHECK_FALSE(load_daemon_config(dir, &c, &error));
  STRCMP_EQUAL((dir + ": is a directory, not a configuration file").c_str(), error.c_str());
}

TEST(SdpslamdConfig, shipped_example_and_the_built_in_default_select_sdp) {
  DaemonConfig c;
  CHECK(c.mode == sdpslam::daemon::SlamMode::kSdp);
  c.mode = sdpslam::daemon::SlamMode::kDpSlam;
  std::string error;
  CHECK_TRUE_TEXT(load_daemon_config(SDPSLAMD_EXAMPLE_INI, &c, &error), error.c_str());
  CHECK(c.mode == sdpslam::daemon::SlamMode::kSdp);
  LONGS_EQUAL(60, c.sdp.top_particles);
}

TEST(SdpslamdConfig, sdp_mode_and_sdp_options_are_accepted) {
  DaemonConfig c;
  std::string error;
  const std::string path = write_ini(
      "[slam]\nmode = sdp\n[filter]\nparticles = 5\n[sdp]\ntop_particles = 10\nsegmentation = periodic\n"
      "period_scans = 6\nmin_segment_scans = 3\nmax_segment_scans = 12\ntopology = segslam\n"
      "map_observation_capacity = 300000\n");
  CHECK_TRUE_TEXT(load_daemon_config(path, &c, &error), error.c_str());
  CHECK(c.mode == sdpslam::daemon::SlamMode::kSdp);
  LONGS_EQUAL(5, c.slam.filter.particle_count);
  LONGS_EQUAL(10, c.sdp.top_particles);
  LONGS_EQUAL(6, c.sdp.period_scans);
  LONGS_EQUAL(3, c.sdp.min_segment_scans);
  LONGS_EQUAL(12, c.sdp.max_segment_scans);
  CHECK(c.sdp.topology == sdpslam::TopologyMode::kSegSlam);
  LONGS_EQUAL(300000, c.sdp.map_observation_capacity);
}

TEST(SdpslamdConfig, offline_default_ini_loads_as_daemon_config_with_the_offline_sdp_values) {
  // Every section of firmware-host/runtime/slam/default.ini, [sdp] included, is a section of sdpslamd.
  DaemonConfig c;
  std::string error;
  CHECK_TRUE_TEXT(load_daemon_config(SDPSLAM_DEFAULT_INI, &c, &error), error.c_str());
  sdpslam::SdpOptions offline;
  sdpslam::apply_profile(sdpslam::kDefaultSdpProfile, nullptr, &offline);  // as `sdpslam run` does
  offline.top_particles = 1U;  // differs from the file, so the comparison sees the file was read
  CHECK_TRUE_TEXT(sdpslam::slam::load_sdp_ini(SDPSLAM_DEFAULT_INI, &offline, &error), error.c_str());
  LONGS_EQUAL(offline.top_particles, c.sdp.top_particles);
  LONGS_EQUAL(offline.max_levels, c.sdp.max_levels);
  LONGS_EQUAL(offline.map_observation_capacity, c.sdp.map_observation_capacity);
  DOUBLES_EQUAL(offline.period_travel_m, c.sdp.period_travel_m, 0.0);
  DOUBLES_EQUAL(offline.icp.max_correspondence_m, c.sdp.icp.max_correspondence_m, 0.0);
}

TEST(SdpslamdConfig, malformed_sdp_value_is_rejected_with_its_line) {
  expect_rejected("[slam]\nmode = sdp\n[sdp]\ntop_particles = ten\n", 4, "sdp.top_particles: 'ten' is not a non-negative 32-bit integer");
}

TEST(SdpslamdConfig, out_of_range_sdp_value_is_rejected_with_its_line) {
  expect_rejected("[sdp]\nmax_levels = 3\nmax_levels = 1\n", 3, "max_levels");
}

TEST(SdpslamdConfig, unknown_sdp_key_is_rejected_with_its_line) {
  expect_rejected("[sdp]\ntop_particles = 10\nbottom_particles = 5\n", 3, "unknown key 'bottom_particles' in section [sdp]");
}

TEST(SdpslamdConfig, sdp_periodic_segmentation_without_a_period_is_rejected_at_the_line_that_removes_it) {
  expect_rejected("[sdp]\nsegmentation = periodic\nperiod_travel_m = 0\n", 3, "periodic segmentation needs");
}

TEST(SdpslamdConfig, empty_and_misspelt_modes_are_rejected_with_their_line) {
  expect_rejected("[can]\ninterface = can0\n[slam]\nmode =\n", 4, "slam.mode: '' is not a SLAM mode (sdp, dpslam, localize)");
  expect_rejected("[slam]\nseed = 3\nmode = SDP\n", 3, "'SDP' is not a SLAM mode");
}

TEST(SdpslamdConfig, sdp_mode_of_the_shipped_example_needs_less_memory_than_dpslam) {
  // Why the example (and the built-in default) is sdp: it fits the memory dpslam takes
  // with the same file (firmware-host/sdpslamd.ini [slam] gives the figures).
  DaemonConfig c;
  std::string error;
  CHECK_TRUE_TEXT(load_daemon_config(SDPSLAMD_EXAMPLE_INI, &c, &error), error.c_str());
  const std::size_t sdp_bytes = sdpslam::daemon::engine_arena_bytes(c);
  c.mode = sdpslam::daemon::SlamMode::kDpSlam;
  const std::size_t dpslam_bytes = sdpslam::daemon::engine_arena_bytes(c);
  CHECK(sdp_bytes > 0U);
  CHECK(sdp_bytes < dpslam_bytes);
  std::printf("\nexample arena: dpslam %zu B, sdp (60T/%uB) %zu B\n", dpslam_bytes, c.slam.filter.particle_count, sdp_bytes);
}

// Keys sdp mode alone reads are said to have no effect in mode dpslam, with their line;
// in sdp mode there is nothing to say.
TEST(SdpslamdConfig, sdp_keys_in_mode_dpslam_are_warned_about) {
  DaemonConfig c;
  std::string error;
  const std::string path = write_ini("[slam]\nmode = dpslam\nprofile = paper\n\n[sdp]\ntop_particles = 20\n");
  CHECK_TRUE_TEXT(load_daemon_config(path, &c, &error), error.c_str());
  LONGS_EQUAL(2, c.warnings.size());
  STRCMP_EQUAL((path + ":6: [sdp] keys have no effect in mode dpslam").c_str(), c.warnings[0].c_str());
  STRCMP_EQUAL((path + ":3: slam.profile has no effect in mode dpslam").c_str(), c.warnings[1].c_str());
  DaemonConfig d;
  CHECK_TRUE_TEXT(load_daemon_config(write_ini("[slam]\nmode = sdp\n\n[sdp]\ntop_particles = 20\n"), &d, &error),
                  error.c_str());
  CHECK_TRUE(d.warnings.empty());
}

// [slam] mode = localize: the saved map is required, read and sized before any work, and
// a start pose that is not x, y, theta is refused at its line.
TEST(SdpslamdConfig, localize_mode_needs_a_readable_map_and_a_well_formed_start) {
  const std::string dir = sdpslam::test::make_temp_dir("sdpslamd_localize");
  // A 4 m x 3 m room at 0.1 m, written in the map_server convention.
  sdpslam::io::OccupancyImage room;
  room.width = 40U;
  room.height = 30U;
  room.resolution_m = 0.1;
  room.occupancy.assign(40U * 30U, 0.0F);
  for (std::uint32_t r = 0; r < 30U; ++r) {
    for (std::uint32_t c = 0; c < 40U; ++c) {
      if (r == 0U || c == 0U || r == 29U || c == 39U) room.occupancy[r * 40U + c] = 1.0F;
    }
  }
  std::string error;
  CHECK_TRUE_TEXT(sdpslam::io::write_map_pgm_yaml(dir + "/room", room, sdpslam::io::MapWriteOptions{}, &error),
                  error.c_str());
  DaemonConfig c;
  const std::string good =
      write_ini("[slam]\nmode = localize\n[localize]\nmap = " + dir + "/room.yaml\nstart = 1.5, 2, -0.5\n");
  CHECK_TRUE_TEXT(load_daemon_config(good, &c, &error), error.c_str());
  CHECK(c.mode == sdpslam::daemon::SlamMode::kLocalize);
  CHECK_TRUE(c.localize_have_start);
  DOUBLES_EQUAL(-0.5, c.localize_start.heading_rad, 0.0);
  CHECK(sdpslam::daemon::engine_arena_bytes(c) > 1200U);  // a byte per cell and the particles

  DaemonConfig d;
  CHECK_FALSE(load_daemon_config(write_ini("[slam]\nmode = localize\n"), &d, &error));
  STRCMP_CONTAINS("localize.map: mode localize needs the saved map", error.c_str());
  expect_rejected("[slam]\nmode = localize\n[localize]\nmap = " + dir + "/room.yaml\nstart = 1, 2\n", 5,
                  "'1, 2' is not a pose x, y, theta");
  expect_rejected("[slam]\nmode = localize\n[localize]\nmap = " + dir + "/none.yaml\n", 4, "none.yaml");
}

// Snapshots resume only under the configuration that wrote them: its fingerprint covers
// the keys that shape the SLAM state, whatever their order, and nothing else.
TEST(SdpslamdConfig, the_slam_fingerprint_covers_the_keys_that_shape_the_state_and_only_those) {
  auto fp = [](const std::string& text) {
    DaemonConfig c;
    std::string error;
    CHECK_TRUE_TEXT(load_daemon_config(write_ini(text), &c, &error), error.c_str());
    return c.slam_fingerprint;
  };
  const std::string sections = "[filter]\nparticles = 8\n[sdp]\ntop_particles = 20\n";
  const std::uint64_t a = fp(sections + "[output]\nperiod_s = 5\n");
  CHECK(a != 0U);
  CHECK(a == fp("[sdp]\ntop_particles = 20\n; a comment\n[output]\nperiod_s = 5\n[filter]\nparticles = 8\n"));
  CHECK(a == fp(sections + "[laser]\ndevice = /dev/ttyUSB0\n[output]\nsnapshot_interval_s = 10\n"));
  CHECK(a != fp("[filter]\nparticles = 9\n[sdp]\ntop_particles = 20\n"));
  CHECK(a != fp(sections + "[output]\nmax_trajectory_scans = 1000\n"));
  CHECK(a != fp(sections + "[slam]\nprofile = paper\n"));
  DaemonConfig c;
  std::string error;
  CHECK_TRUE(load_daemon_config(write_ini("[output]\nsnapshot_interval_s = 2.5\n"), &c, &error));
  LONGS_EQUAL(2500000, c.snapshot_interval_us);
  expect_rejected("[output]\nsnapshot_interval_s = -1\n", 2, "snapshot_interval_s");
}
