// `sdpslam run` end to end on small logs with bad lines: every skipped line is named
// with file:line and its reason (the first kLogErrorsShown of each kind), the rest are
// counted, and the good scans still make a trajectory. Option values out of range are
// usage errors, not silently wrapped or saturated.
#include <CppUTest/TestHarness.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sdpslam/io/atomic_file.h"
#include "sdpslam/io/trajectory_io.h"
#include "run_program.h"
#include "shared_data.h"

namespace {

using Run = sdpslam::test::ProgramRun;

Run run_cli(const std::string& args) { return sdpslam::test::run_program(std::string(SDPSLAM_CLI_PATH) + " " + args); }

// The whole file (empty when it cannot be read).
std::string text_of(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::size_t lines_in(const std::string& path) {
  std::ifstream in(path);
  std::size_t n = 0;
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line[0] != '#') ++n;
  }
  return n;
}

// One FLASER line of 180 beams 2 m long, the robot at x (m), stamped t (s).
std::string scan(double x, double t, const char* bad_range = nullptr) {
  std::string s = "FLASER 180";
  for (int i = 0; i < 180; ++i) s += (i == 7 && bad_range != nullptr) ? std::string(" ") + bad_range : " 2.0";
  char tail[160];
  std::snprintf(tail, sizeof tail, " %.3f 0 0 %.3f 0 0 %.6f host %.6f\n", x, x, t, t);
  return s + tail;
}

}  // namespace

TEST_GROUP(CliRun) {
  std::string dir;
  void setup() override { dir = sdpslam::test::make_temp_dir("cli-run"); }
  void teardown() override {
    const std::string cmd = "rm -rf '" + dir + "'";
    CHECK_EQUAL(0, std::system(cmd.c_str()));
  }
  std::string put(const char* name, const std::string& text) {
    std::string error;
    const std::string p = dir + "/" + name;
    CHECK_TRUE(sdpslam::io::write_file_atomic(p, text, &error));
    return p;
  }
  // Ten good scans, then `bad` scans with a NaN range, then an unknown message type.
  std::string log_with_bad_lines(int bad) {
    std::string text;
    for (int i = 0; i < 10; ++i) text += scan(0.05 * i, 100.0 + 0.1 * i);
    for (int i = 0; i < bad; ++i) text += scan(0.5, 101.0 + 0.1 * i, "nan");
    text += "NOSUCHSENSOR 1 2 3\n";
    return put("log.clf", text);
  }
};

TEST(CliRun, every_skipped_line_is_named_in_both_modes) {
  const std::string log = log_with_bad_lines(2);
  for (const char* mode : {"sdp", "dpslam"}) {
    const Run r = run_cli("run " + log + " --mode " + mode + " --out " + dir + "/out");
    LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
    STRCMP_CONTAINS((log + ":11: range 7 (field 10) is not a finite number").c_str(), r.out.c_str());
    STRCMP_CONTAINS((log + ":12: range 7").c_str(), r.out.c_str());
    STRCMP_CONTAINS((log + ":13: unknown message type").c_str(), r.out.c_str());
    CHECK_TEXT(r.out.find("more skipped lines") == std::string::npos, r.out.c_str());
    STRCMP_CONTAINS("3 log errors", r.out.c_str());
    // The good scans are all in the trajectory.
    LONGS_EQUAL_TEXT(10, lines_in(dir + "/out/trajectory.txt"), mode);
  }
}

TEST(CliRun, past_the_first_lines_of_a_kind_the_rest_are_counted) {
  const std::string log = log_with_bad_lines(25);
  const Run r = run_cli("run " + log + " --mode dpslam --out " + dir + "/out");
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  STRCMP_CONTAINS((log + ":30: range 7").c_str(), r.out.c_str());  // the 20th malformed line
  CHECK_TEXT(r.out.find(log + ":31: ") == std::string::npos, r.out.c_str());
  STRCMP_CONTAINS((log + ":36: unknown message type").c_str(), r.out.c_str());  // its own kind
  STRCMP_CONTAINS("... and 5 more skipped lines", r.out.c_str());
  STRCMP_CONTAINS("26 log errors", r.out.c_str());
}

// ROS bag support lives in a plugin (sdpslam/io/bags.h): a run on a CARMEN log loads
// neither it nor the ROS, SQLite and Fast-CDR libraries, which would hold several MiB of
// the robot computer's memory for nothing. glibc's loader names every object it loads.
TEST(CliRun, a_run_on_a_carmen_log_loads_no_bag_library) {
  const std::string log = log_with_bad_lines(0);
  const Run r = sdpslam::test::run_program("LD_DEBUG=files " + std::string(SDPSLAM_CLI_PATH) + " run " + log +
                                           " --out " + dir + "/out");
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  STRCMP_CONTAINS("libc.so", r.out.c_str());  // the loader did report what it loaded
  for (const char* lib : {"sdpslam_bags", "rosbag", "sqlite3", "fastcdr", "boost"}) {
    CHECK_TEXT(r.out.find(lib) == std::string::npos, lib);
  }
}

// The hostile case: a 1 km odometry jump. The line is named, the jump is not
// applied (the trajectory moves centimetres, not a kilometre), stats.json counts it; a
// scan stamped before the one it follows is reported with its line.
TEST(CliRun, an_odometry_jump_and_time_going_backwards_are_reported_and_handled) {
  std::string text;
  for (int i = 0; i < 10; ++i) text += scan(0.05 * i, 100.0 + 0.1 * i);
  text += scan(1000.5, 101.0);                 // line 11: 1 km in 0.1 s
  for (int i = 1; i < 5; ++i) text += scan(1000.5 + 0.05 * i, 101.0 + 0.1 * i);
  text += scan(1000.75, 101.35);               // line 16: before 101.4
  const std::string log = put("log.clf", text);
  for (const char* mode : {"sdp", "dpslam"}) {
    const Run r = run_cli("run " + log + " --mode " + mode + " --out " + dir + "/out");
    LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
    STRCMP_CONTAINS((log + ":11: odometry jumps 1000.050 m").c_str(), r.out.c_str());
    STRCMP_CONTAINS("1 odometry increments beyond the plausible speed", r.out.c_str());
    STRCMP_CONTAINS(("1 scans are stamped before the scan they follow (the first at " + log + ":16)").c_str(),
                    r.out.c_str());
    std::ifstream in(dir + "/out/trajectory.txt");
    std::string line;
    double max_x = 0.0;
    while (std::getline(in, line)) {
      double t = 0.0, x = 0.0, y = 0.0, th = 0.0;
      if (!line.empty() && line[0] != '#' && std::sscanf(line.c_str(), "%lf %lf %lf %lf", &t, &x, &y, &th) == 4) {
        if (x > max_x) max_x = x;
      }
    }
    CHECK_TEXT(max_x < 2.0, mode);
    const std::string stats = text_of(dir + "/out/stats.json");
    STRCMP_CONTAINS("\"odometry_jumps_removed\": 1", stats.c_str());
    STRCMP_CONTAINS("\"scans_stamped_backwards\": 1", stats.c_str());
  }
}

// An output folder that cannot be written fails at once, naming it, with the I/O exit
// status - not after the whole log has been processed.
TEST(CliRun, an_unwritable_output_folder_fails_before_any_work) {
  const std::string log = log_with_bad_lines(0);
  std::string out = dir + "/locked";
  if (::geteuid() == 0) {
    out = "/proc";  // root writes wherever a mode allows; /proc takes no new entries
  } else {
    CHECK_EQUAL(0, ::mkdir(out.c_str(), 0555));
  }
  for (const char* mode : {"sdp", "dpslam"}) {
    const Run r = run_cli("run " + log + " --mode " + mode + " --out " + out);
    LONGS_EQUAL_TEXT(4, r.status, r.out.c_str());
    STRCMP_CONTAINS(("cannot write in output directory '" + out + "'").c_str(), r.out.c_str());
    CHECK_TEXT(r.out.find("scans (") == std::string::npos, r.out.c_str());
  }
}

// The outputs arrive as one set listed in manifest.txt; a dpslam run after an sdp run
// removes the sdp run's ICP files, and a killed run's temporaries are cleaned up.
TEST(CliRun, outputs_are_one_run_s_set) {
  const std::string log = log_with_bad_lines(0);
  const std::string out = dir + "/out";
  Run r = run_cli("run " + log + " --mode sdp --out " + out);
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  const std::string m1 = text_of(out + "/manifest.txt");
  STRCMP_CONTAINS(" icp_error.csv\n", m1.c_str());
  STRCMP_CONTAINS(" trajectory.txt\n", m1.c_str());
  // What a run killed between write and rename leaves (pid 2^22 + 1 is above Linux's
  // largest pid, so no process owns it).
  {
    std::ofstream torn(out + "/.map.pgm.tmp.4194305.0");
    torn << "torn";
  }
  r = run_cli("run " + log + " --mode dpslam --out " + out);
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  std::ifstream probe(out + "/icp_error.csv");
  CHECK_FALSE(probe.good());
  std::ifstream torn(out + "/.map.pgm.tmp.4194305.0");
  CHECK_FALSE(torn.good());
  const std::string m2 = text_of(out + "/manifest.txt");
  CHECK_TEXT(m2.find("icp_error") == std::string::npos, m2.c_str());
  STRCMP_CONTAINS(" stats.json\n", m2.c_str());
}

// On a terminal the progress line is drawn (\r-redrawn, the end once); --quiet draws
// nothing. A terminal comes from script(1) (util-linux, in every Debian system).
TEST(CliRun, progress_on_a_terminal_and_quiet) {
  if (std::system("command -v script > /dev/null 2>&1") != 0) {
    std::fprintf(stderr, "skipped: no script(1) to give the program a terminal\n");
    return;
  }
  const std::string log = log_with_bad_lines(0);
  auto on_tty = [&](const std::string& args) {
    return sdpslam::test::run_program("script -qec \"" + std::string(SDPSLAM_CLI_PATH) + " " + args + "\" /dev/null");
  };
  Run r = on_tty("run " + log + " --mode dpslam --out " + dir + "/o1");
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  STRCMP_CONTAINS("\rKiB ", r.out.c_str());
  std::size_t ends = 0;
  for (std::size_t p = r.out.find("100.0%"); p != std::string::npos; p = r.out.find("100.0%", p + 1)) ++ends;
  LONGS_EQUAL_TEXT(1, ends, r.out.c_str());
  r = on_tty("run " + log + " --mode dpslam --quiet --out " + dir + "/o2");
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  CHECK_TEXT(r.out.find("KiB") == std::string::npos, r.out.c_str());
  STRCMP_CONTAINS("sdpslam run: ", r.out.c_str());
  // The summary is a result: on stdout (with stderr thrown away), as simulate's and
  // convert's are.
  r = sdpslam::test::run_program("(" + std::string(SDPSLAM_CLI_PATH) + " run " + log + " --mode dpslam --quiet --out " +
                                 dir + "/o3 2>/dev/null)");
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  STRCMP_CONTAINS("sdpslam run: ", r.out.c_str());
}

// trajectory.tum holds the poses of trajectory.txt (TUM, as evo reads it), in both modes,
// and is part of the run's set.
TEST(CliRun, the_trajectory_is_also_written_in_tum_format) {
  const std::string log = log_with_bad_lines(0);
  for (const char* mode : {"sdp", "dpslam"}) {
    const std::string out = dir + "/out-" + mode;
    Run r = run_cli("run " + log + " --mode " + mode + " --out " + out);
    LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
    std::vector<sdpslam::io::StampedPose> txt;
    std::vector<sdpslam::io::StampedPose> tum;
    std::string error;
    CHECK_TRUE_TEXT(sdpslam::io::read_trajectory(out + "/trajectory.txt", &txt, &error), error.c_str());
    CHECK_TRUE_TEXT(sdpslam::io::read_trajectory(out + "/trajectory.tum", &tum, &error), error.c_str());
    LONGS_EQUAL_TEXT(10, txt.size(), mode);
    LONGS_EQUAL_TEXT(txt.size(), tum.size(), mode);
    for (std::size_t i = 0; i < txt.size(); ++i) {
      LONGS_EQUAL(txt[i].stamp_us, tum[i].stamp_us);
      DOUBLES_EQUAL(txt[i].pose.x_m, tum[i].pose.x_m, 1e-6);
      DOUBLES_EQUAL(txt[i].pose.y_m, tum[i].pose.y_m, 1e-6);
      DOUBLES_EQUAL(txt[i].pose.heading_rad, tum[i].pose.heading_rad, 1e-6);
    }
    STRCMP_CONTAINS(" trajectory.tum\n", text_of(out + "/manifest.txt").c_str());
  }
}

namespace {

std::string slurp_without_timing(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string out;
  std::string line;
  while (std::getline(in, line)) {
    if (line.find("\"timing\"") == std::string::npos && line.find(" stats.json") == std::string::npos) {
      out += line + "\n";
    }
  }
  return out;
}

}  // namespace

// firmware-host/runtime/slam/default.ini documents the defaults: given as --config it changes nothing, in
// either mode (sdp mode's profile keys and the mode's particle count are left out of it).
TEST(CliRun, the_shipped_default_ini_changes_nothing) {
  Run r = run_cli("simulate --max-duration 15 --out " + dir + "/sim");
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  for (const char* mode : {"sdp", "dpslam"}) {
    const std::string base = "run " + dir + "/sim/sim.clf --mode " + mode + " --seed 3 --out " + dir;
    r = run_cli(base + "/plain");
    LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
    r = run_cli(base + "/documented --config " + SDPSLAM_DEFAULT_INI);
    LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
    for (const char* file : {"trajectory.txt", "map.pgm", "stats.json", "manifest.txt"}) {
      const std::string a = slurp_without_timing(dir + "/plain/" + file);
      const std::string b = slurp_without_timing(dir + "/documented/" + file);
      CHECK_TEXT(!a.empty(), file);
      CHECK_TEXT(a == b, (std::string(mode) + ": " + file + " differs with the documented defaults").c_str());
    }
  }
}

// [filter] particles is the bottom level's B in sdp mode too (it used to be ignored
// there without a word); --particles still overrides it.
TEST(CliRun, filter_particles_is_honoured_in_sdp_mode) {
  const std::string log = log_with_bad_lines(0);
  const std::string ini = put("b.ini", "[filter]\nparticles = 12\n");
  Run r = run_cli("run " + log + " --config " + ini + " --out " + dir + "/a");
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  STRCMP_CONTAINS("\"bottom_particles\": 12,", slurp_without_timing(dir + "/a/stats.json").c_str());
  r = run_cli("run " + log + " --config " + ini + " --particles 7 --out " + dir + "/b");
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  STRCMP_CONTAINS("\"bottom_particles\": 7,", slurp_without_timing(dir + "/b/stats.json").c_str());
  r = run_cli("run " + log + " --out " + dir + "/c");
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  STRCMP_CONTAINS("\"bottom_particles\": 10,", slurp_without_timing(dir + "/c/stats.json").c_str());
}

// How the bottom level drew its particles is counted in sdp mode as in dpslam mode: with
// the improved proposal (the accurate profile) every particle of every step is drawn
// around a match or by the odometry fallback, and counted once as one or the other; with
// the paper's odometry proposal nothing is.
TEST(CliRun, the_bottom_levels_proposals_are_counted_in_sdp_mode) {
  std::string text;
  for (int i = 0; i < 40; ++i) text += scan(0.05 * i, 100.0 + 0.1 * i);
  const std::string log = put("walk.clf", text);
  auto proposals = [&](const std::string& args, nlohmann::json* stats) {
    Run r = run_cli("run " + log + " " + args + " --quiet --out " + dir + "/out");
    LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
    const std::string stats_text = text_of(dir + "/out/stats.json");
    *stats = nlohmann::json::parse(stats_text, nullptr, false);
    CHECK_FALSE_TEXT(stats->is_discarded(), stats_text.c_str());
    const nlohmann::json& p = (*stats)["proposal"];
    return p["matched"].get<std::uint64_t>() + p["fallback_few_beams"].get<std::uint64_t>() +
           p["fallback_empty_map"].get<std::uint64_t>() + p["fallback_low_score"].get<std::uint64_t>();
  };
  nlohmann::json stats;
  const std::uint64_t drawn = proposals("", &stats);
  const auto particles = stats["bottom_particles"].get<std::uint64_t>();
  const auto processed = stats["processed_scans"].get<std::uint64_t>();
  CHECK_TRUE(processed >= 5U);
  // Every processed scan after the first draws each particle once.
  LONGS_EQUAL(particles * (processed - 1U), drawn);
  CHECK_TRUE(stats["proposal"]["evaluations"].get<std::uint64_t>() >= stats["proposal"]["matched"].get<std::uint64_t>());
  LONGS_EQUAL(0, proposals("--profile paper", &stats));
  LONGS_EQUAL(0, stats["proposal"]["evaluations"].get<std::uint64_t>());
}

// --print-config shows what the profile, the file and the flags made of the options,
// nothing hidden: flags and profile appear in it, and it reads back as the same run's
// configuration.
TEST(CliRun, print_config_is_the_effective_configuration_and_reads_back) {
  const std::string log = log_with_bad_lines(0);
  const std::string ini = put("p.ini", "[sdp]\nmax_segment_scans = 40\nmin_segment_scans = 5\n");
  Run r = run_cli("run " + log + " --config " + ini + " --particles 7 --topology segslam --print-config --out " + dir +
                  "/never");
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  CHECK_TEXT(access((dir + "/never").c_str(), F_OK) != 0, "--print-config ran the log");
  STRCMP_CONTAINS("--profile accurate", r.out.c_str());
  STRCMP_CONTAINS("\nparticles = 7 ", r.out.c_str());
  STRCMP_CONTAINS("\ntopology = segslam ", r.out.c_str());
  STRCMP_CONTAINS("\nmax_segment_scans = 40 ", r.out.c_str());
  STRCMP_CONTAINS("\nkind = scan_match ", r.out.c_str());  // the profile's
  STRCMP_CONTAINS("\nloop_search_window_m = 6 ", r.out.c_str());
  const std::string effective = put("effective.ini", r.out);
  Run again = run_cli("run " + log + " --config " + effective + " --print-config --out " + dir + "/never");
  LONGS_EQUAL_TEXT(0, again.status, again.out.c_str());
  STRCMP_EQUAL(r.out.c_str(), again.out.c_str());
  r = run_cli("run " + log + " --mode dpslam --print-config --out " + dir + "/never");
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  STRCMP_CONTAINS("\nparticles = 30 ", r.out.c_str());
  STRCMP_CONTAINS("\nkind = odometry ", r.out.c_str());
  CHECK_TEXT(r.out.find("[sdp]") == std::string::npos, r.out.c_str());
}

// Top-level options given to DP-SLAM alone are refused (flags) or warned about (a
// config's [sdp] section), never silently ignored.
TEST(CliRun, top_level_options_in_dpslam_mode_are_not_ignored_silently) {
  const std::string log = log_with_bad_lines(0);
  Run r = run_cli("run " + log + " --mode dpslam --top-particles 20 --out " + dir + "/a");
  LONGS_EQUAL_TEXT(2, r.status, r.out.c_str());
  STRCMP_CONTAINS("--top-particles and --topology apply to --mode sdp", r.out.c_str());
  const std::string ini = put("s.ini", "[filter]\nparticles = 12\n\n[sdp]\ntop_particles = 20\n");
  r = run_cli("run " + log + " --mode dpslam --config " + ini + " --out " + dir + "/b");
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  STRCMP_CONTAINS((ini + ": [sdp] keys have no effect in --mode dpslam").c_str(), r.out.c_str());
}

TEST(CliRun, numbers_out_of_range_and_an_empty_output_folder_are_usage_errors) {
  const std::string log = log_with_bad_lines(0);
  const struct {
    const char* args;
    const char* why;
  } refused[] = {
      {"--seed -1", "--seed: must be a whole number from 0 to 18446744073709551615, not '-1'"},
      {"--seed 18446744073709551616", "not '18446744073709551616'"},
      {"--seed 99999999999999999999999", "not '99999999999999999999999'"},
      {"--seed 7x", "not '7x'"},
      {"--particles -3", "--particles: must be a whole number from 0 to 4294967295, not '-3'"},
      {"--top-particles 4294967296", "--top-particles: must be a whole number from 0 to 4294967295"},
  };
  for (const auto& c : refused) {
    const Run r = run_cli("run " + log + " " + c.args + " --out " + dir + "/a");
    LONGS_EQUAL_TEXT(2, r.status, c.args);
    STRCMP_CONTAINS(c.why, r.out.c_str());
  }
  struct stat st {};
  CHECK_EQUAL(-1, ::stat((dir + "/a").c_str(), &st));  // nothing ran
  Run r = run_cli("run " + log + " --out ''");
  LONGS_EQUAL_TEXT(2, r.status, r.out.c_str());
  STRCMP_CONTAINS("--out: must not be empty", r.out.c_str());
  // The largest seed is a seed like any other.
  r = run_cli("run " + log + " --seed 18446744073709551615 --out " + dir + "/b");
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  r = run_cli("simulate --world paper --seed -1 --out " + dir + "/c");
  LONGS_EQUAL_TEXT(2, r.status, r.out.c_str());
  STRCMP_CONTAINS("--seed: must be a whole number", r.out.c_str());
  r = run_cli("simulate --world paper --odom-rate -5 --out " + dir + "/c");
  LONGS_EQUAL_TEXT(2, r.status, r.out.c_str());
  STRCMP_CONTAINS("--odom-rate: must be a whole number", r.out.c_str());
  r = run_cli("simulate --world paper --out ''");
  LONGS_EQUAL_TEXT(2, r.status, r.out.c_str());
  STRCMP_CONTAINS("--out: must not be empty", r.out.c_str());
}

// loops.tsv names each loop constraint's levels with where they started, so that a
// simulated run's constraints can be checked against its ground truth: on the paper
// world every constraint the run used is right (within 0.5 m), which it can only be if
// the origins are the levels' true ones.
// The state is sized from the options and checked against --memory-budget-mib before
// the log is read: a capacity with digits too many is refused with the size it asks
// for, and nothing is written.
TEST(CliRun, a_state_above_the_memory_budget_is_refused_before_any_work) {
  const std::string log = log_with_bad_lines(0);
  const std::string ini = put("huge.ini", "[sdp]\nmap_observation_capacity = 1000000000\n");
  Run r = run_cli("run " + log + " --config " + ini + " --out " + dir + "/a");
  LONGS_EQUAL_TEXT(2, r.status, r.out.c_str());
  STRCMP_CONTAINS("the SLAM state needs ", r.out.c_str());
  STRCMP_CONTAINS(" MiB, above --memory-budget-mib 128", r.out.c_str());
  struct stat st {};
  CHECK_EQUAL(-1, ::stat((dir + "/a").c_str(), &st));  // nothing ran
  // The default options fit 64 MiB in sdp mode; the DP-SLAM baseline's larger map does not.
  r = run_cli("run " + log + " --memory-budget-mib 64 --quiet --out " + dir + "/b");
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  r = run_cli("run " + log + " --mode dpslam --memory-budget-mib 64 --out " + dir + "/c");
  LONGS_EQUAL_TEXT(2, r.status, r.out.c_str());
  STRCMP_CONTAINS("above --memory-budget-mib 64", r.out.c_str());
  r = run_cli("run " + log + " --memory-budget-mib 7 --out " + dir + "/c");
  LONGS_EQUAL_TEXT(2, r.status, r.out.c_str());
  STRCMP_CONTAINS("--memory-budget-mib", r.out.c_str());
  CHECK_EQUAL(-1, ::stat((dir + "/c").c_str(), &st));
}

// fopen() opens a directory, and reading one looks like an empty file: the built-in
// defaults would run unannounced.
TEST(CliRun, a_directory_given_as_the_config_is_refused_before_any_work) {
  const std::string log = log_with_bad_lines(0);
  const Run r = run_cli("run " + log + " --config " + dir + " --out " + dir + "/a");
  LONGS_EQUAL_TEXT(3, r.status, r.out.c_str());
  STRCMP_CONTAINS(("sdpslam run: " + dir + ": is a directory, not a configuration file").c_str(), r.out.c_str());
  struct stat st {};
  CHECK_EQUAL(-1, ::stat((dir + "/a").c_str(), &st));
}

// `convert` keeps every good record of a log with bad lines, names the bad ones, and
// refuses a log with no scan and no odometry left (its lines all malformed) instead of
// writing an empty log with exit 0.
TEST(CliRun, convert_refuses_a_log_with_nothing_left_and_writes_nothing) {
  std::string text;
  for (int i = 0; i < 3; ++i) text += scan(0.5, 101.0 + 0.1 * i, "nan");
  text += "NOSUCHSENSOR 1 2 3\n";
  const std::string bad = put("bad.clf", text);
  Run r = run_cli("convert --quiet " + bad + " " + dir + "/bad_out.clf");
  LONGS_EQUAL_TEXT(3, r.status, r.out.c_str());
  STRCMP_CONTAINS((bad + ":1: range 7 (field 10) is not a finite number").c_str(), r.out.c_str());
  STRCMP_CONTAINS((bad + ": no laser scan and no odometry in 4 lines (4 skipped): nothing to convert").c_str(),
                  r.out.c_str());
  struct stat st {};
  CHECK_EQUAL(-1, ::stat((dir + "/bad_out.clf").c_str(), &st));
  // The same bad lines after good scans: the good ones are converted, exit 0.
  const std::string mixed = log_with_bad_lines(3);
  r = run_cli("convert --quiet " + mixed + " " + dir + "/mixed_out.clf");
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  STRCMP_CONTAINS("10 scans", r.out.c_str());
  STRCMP_CONTAINS("warning: 4 input lines skipped", r.out.c_str());
  LONGS_EQUAL(10, lines_in(dir + "/mixed_out.clf"));
}

// What the core would refuse at init is refused before any work, with the config line
// that set the key (SdpSlam::check_options: limits that join several options).
TEST(CliRun, options_the_core_cannot_start_with_are_refused_at_their_line_before_any_work) {
  const std::string log = log_with_bad_lines(0);
  std::string ini = put("wide.ini", "[filter]\nparticles = 10\n\n[map]\nwidth_m = 3000\n");
  Run r = run_cli("run " + log + " --config " + ini + " --out " + dir + "/a");
  LONGS_EQUAL_TEXT(2, r.status, r.out.c_str());
  STRCMP_CONTAINS((ini + ":5: map.width_m: a map grid 60000 cells wide").c_str(), r.out.c_str());
  struct stat st {};
  CHECK_EQUAL(-1, ::stat((dir + "/a").c_str(), &st));  // nothing ran, no folder made
  ini = put("patch.ini", "[sdp]\nskeleton_max_side_m = 400\n");
  r = run_cli("run " + log + " --config " + ini + " --out " + dir + "/a");
  LONGS_EQUAL_TEXT(2, r.status, r.out.c_str());
  STRCMP_CONTAINS((ini + ":2: sdp.skeleton_max_side_m: a skeleton patch of").c_str(), r.out.c_str());
  CHECK_EQUAL(-1, ::stat((dir + "/a").c_str(), &st));
  // A key the command line set has no line: the reason alone.
  r = run_cli("run " + log + " --particles 100000 --out " + dir + "/a");
  LONGS_EQUAL_TEXT(2, r.status, r.out.c_str());
  STRCMP_CONTAINS("sdpslam run: filter.particles: 100000 out of range", r.out.c_str());
}

TEST(CliRun, the_loop_constraints_are_written_with_their_levels_origins) {
  Run r = run_cli("simulate --world paper --seed 4 --quiet --out " + dir + "/sim");
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  r = run_cli("run " + dir + "/sim/sim.clf --seed 4 --quiet --out " + dir + "/run");
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  STRCMP_CONTAINS(" loops.tsv\n", text_of(dir + "/run/manifest.txt").c_str());
  CHECK_TRUE(lines_in(dir + "/run/loops.tsv") >= 2U);
  // segments.tsv: one line per level and one for the segment being mapped at the end,
  // each level starting where loops.tsv says it did.
  STRCMP_CONTAINS(" segments.tsv\n", text_of(dir + "/run/manifest.txt").c_str());
  std::map<std::string, std::string> starts;
  {
    std::istringstream in(text_of(dir + "/run/segments.tsv"));
    for (std::string line; std::getline(in, line);) {
      if (line.empty() || line[0] == '#') continue;
      std::istringstream f(line);
      std::string level, stamp, extra;
      CHECK_TEXT(static_cast<bool>(f >> level >> stamp) && !(f >> extra), line.c_str());
      starts[level] = stamp;
    }
  }
  {
    std::istringstream in(text_of(dir + "/run/loops.tsv"));
    for (std::string line; std::getline(in, line);) {
      if (line.empty() || line[0] == '#') continue;
      std::istringstream f(line);
      std::vector<std::string> c;
      for (std::string t; f >> t;) c.push_back(t);
      LONGS_EQUAL_TEXT(16U, c.size(), line.c_str());
      STRCMP_EQUAL_TEXT(starts[c[0]].c_str(), c[8].c_str(), line.c_str());
      STRCMP_EQUAL_TEXT(starts[c[1]].c_str(), c[12].c_str(), line.c_str());
    }
  }
  r = run_cli("evaluate --loops " + dir + "/run/loops.tsv --ground-truth " + dir + "/sim/ground_truth.txt --json " +
              dir + "/loops.json");
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  STRCMP_CONTAINS(" 0 without a ground-truth origin", r.out.c_str());
  const std::string json = text_of(dir + "/loops.json");
  const std::string used = json.substr(json.find("\"used\""));
  STRCMP_CONTAINS("\"between\": 0, \"wrong\": 0", used.c_str());
  CHECK_TEXT(used.find("\"count\": 0,") == std::string::npos, used.c_str());
  // stats.json counts the pose-graph solves those loops made, and those of them that ended
  // before converging.
  const std::string stats_text = text_of(dir + "/run/stats.json");
  const nlohmann::json stats = nlohmann::json::parse(stats_text, nullptr, false);
  CHECK_FALSE_TEXT(stats.is_discarded(), stats_text.c_str());
  const nlohmann::json& lc = stats["loop_closure"];
  CHECK_TRUE(lc["adjustments"].is_number_unsigned());
  CHECK_TRUE(lc["adjustments_capped"].is_number_unsigned());
  CHECK(lc["adjustments"].get<std::uint64_t>() > 0U);
  CHECK(lc["adjustments_capped"].get<std::uint64_t>() <= lc["adjustments"].get<std::uint64_t>());
  LONGS_EQUAL(stats["segments"].get<std::size_t>() + 1U, starts.size());
}

// `sdpslam localize` on a simulated world's own map, from the ground truth's first pose:
// the path is the true one within centimetres, and the output set is complete.
TEST(CliRun, localize_on_the_world_map_follows_the_true_path) {
  Run r = run_cli("simulate --world paper --seed 1 --quiet --out " + dir + "/sim");
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  std::ifstream gt(dir + "/sim/ground_truth.txt");
  std::string line;
  while (std::getline(gt, line) && line[0] == '#') {
  }
  std::istringstream first(line);
  double t = 0.0, x = 0.0, y = 0.0, th = 0.0;
  CHECK_TRUE(static_cast<bool>(first >> t >> x >> y >> th));
  char start[96];
  std::snprintf(start, sizeof start, "%.6f,%.6f,%.6f", x, y, th);
  r = run_cli("localize " + dir + "/sim/sim.clf --map " + dir + "/sim/world.yaml --start " + start + " --quiet --out " +
              dir + "/loc");
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  STRCMP_CONTAINS("converged at scan 0", r.out.c_str());
  const std::string manifest = text_of(dir + "/loc/manifest.txt");
  for (const char* name : {" trajectory.txt\n", " trajectory.tum\n", " map.png\n", " particles.tsv\n", " stats.json\n"}) {
    STRCMP_CONTAINS(name, manifest.c_str());
  }
  LONGS_EQUAL(lines_in(dir + "/sim/ground_truth.txt"), lines_in(dir + "/loc/trajectory.txt"));
  r = run_cli("evaluate --ground-truth " + dir + "/sim/ground_truth.txt --trajectory " + dir + "/loc/trajectory.txt");
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  const std::size_t at = r.out.find("rmse ");
  CHECK(at != std::string::npos);
  CHECK_TEXT(std::stod(r.out.substr(at + 5)) < 0.05, r.out.c_str());
}

// Width and height from a PNG's IHDR (0 x 0 when it is not a PNG).
std::pair<unsigned, unsigned> png_size(const std::string& path) {
  const std::string b = text_of(path);
  if (b.size() < 24U || b.compare(1, 3, "PNG") != 0) return {0U, 0U};
  auto be32 = [&b](std::size_t at) {
    unsigned v = 0U;
    for (std::size_t k = 0; k < 4U; ++k) v = (v << 8U) | static_cast<unsigned char>(b[at + k]);
    return v;
  };
  return {be32(16U), be32(20U)};
}

// The figures of a run are drawn with text (tools/plot): the ICP error chart at its
// chart size, the map with its title band and legend under it; `evaluate --plot` draws
// the per-relation error (relations made here from the simulation's ground truth).
TEST(CliRun, the_run_and_evaluate_draw_figures_with_text) {
  Run r = run_cli("simulate --world paper --seed 1 --quiet --out " + dir + "/sim");
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  r = run_cli("run " + dir + "/sim/sim.clf --quiet --out " + dir + "/run");
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  const std::pair<unsigned, unsigned> chart = png_size(dir + "/run/icp_error.png");
  LONGS_EQUAL(900U, chart.first);
  LONGS_EQUAL(500U, chart.second);
  const std::pair<unsigned, unsigned> map = png_size(dir + "/run/map.png");
  CHECK(map.first >= 560U);  // room for the scale bar and the legend under the map
  CHECK(map.second > 100U);
  // Relations: each ground-truth pose with the one 20 poses later, in its frame.
  std::vector<sdpslam::io::StampedPose> truth;
  std::string error;
  CHECK_TRUE_TEXT(sdpslam::io::read_trajectory(dir + "/sim/ground_truth.txt", &truth, &error), error.c_str());
  std::string relations;
  for (std::size_t k = 0; k + 20U < truth.size(); k += 50U) {
    const sdpslam::Pose2 d = sdpslam::between(truth[k].pose, truth[k + 20U].pose);
    char line[200];
    std::snprintf(line, sizeof line, "%s %s %.6f %.6f 0 0 0 %.6f\n", sdpslam::io::format_stamp_us(truth[k].stamp_us).c_str(),
                  sdpslam::io::format_stamp_us(truth[k + 20U].stamp_us).c_str(), d.x_m, d.y_m, d.heading_rad);
    relations += line;
  }
  put("sim.relations", relations);
  r = run_cli("evaluate --log " + dir + "/sim/sim.clf --relations " + dir + "/sim.relations --trajectory " + dir +
              "/run/trajectory.txt --plot " + dir + "/relations.png");
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  const std::pair<unsigned, unsigned> rel = png_size(dir + "/relations.png");
  LONGS_EQUAL(900U, rel.first);
  LONGS_EQUAL(500U, rel.second);
  r = run_cli("evaluate --ground-truth " + dir + "/sim/ground_truth.txt --trajectory " + dir +
              "/run/trajectory.txt --plot " + dir + "/ate.png");
  LONGS_EQUAL_TEXT(2, r.status, r.out.c_str());
  STRCMP_CONTAINS("--plot needs --relations", r.out.c_str());
}

TEST(CliRun, localize_names_a_bad_start_and_a_missing_map) {
  const std::string log = log_with_bad_lines(0);
  Run r = run_cli("localize " + log + " --map " + dir + "/none.yaml --start 1,2 --out " + dir + "/loc");
  LONGS_EQUAL(2, r.status);
  STRCMP_CONTAINS("--start: expected x,y,theta", r.out.c_str());
  r = run_cli("localize " + log + " --map " + dir + "/none.yaml --out " + dir + "/loc");
  LONGS_EQUAL(3, r.status);
  STRCMP_CONTAINS("none.yaml", r.out.c_str());
}

// stats.json stays JSON whatever the log's name: read back by a JSON parser, its "log" is
// the path as given, quotes, backslashes and UTF-8 included, and its counts and timings
// are numbers.
TEST(CliRun, a_log_path_with_quotes_and_backslashes_reads_back_from_stats_json) {
  std::string text;
  for (int i = 0; i < 10; ++i) text += scan(0.05 * i, 100.0 + 0.1 * i);
  const std::string log = put("we\"ird\\na\xc3\xafve.clf", text);
  for (const char* mode : {"sdp", "dpslam"}) {
    Run r = run_cli("run '" + log + "' --mode " + mode + " --quiet --out " + dir + "/out");
    LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
    const std::string stats_text = text_of(dir + "/out/stats.json");
    const nlohmann::json stats = nlohmann::json::parse(stats_text, nullptr, false);
    CHECK_FALSE_TEXT(stats.is_discarded(), stats_text.c_str());
    STRCMP_EQUAL(log.c_str(), stats["log"].get<std::string>().c_str());
    STRCMP_EQUAL(mode, stats["mode"].get<std::string>().c_str());
    LONGS_EQUAL(10, stats["scans"].get<int>());
    CHECK_TRUE(stats["pools"]["ancestry_nodes"]["peak"].is_number_unsigned());
    CHECK_TRUE(stats["timing"]["cpu_time_s"].is_number());
  }
}
