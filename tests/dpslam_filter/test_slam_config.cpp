// INI configuration of the filter and the offline runner's outputs.
#include <CppUTest/TestHarness.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "sdpslam/slam/config_ini.h"
#include "sdpslam/slam/run_offline.h"
#include "shared_data.h"

using namespace sdpslam;

namespace {
std::string write_temp(const std::string& text) {
  const std::string dir = sdpslam::test::make_temp_dir("slam_config");
  const std::string path = dir + "/c.ini";
  std::ofstream(path) << text;
  return path;
}
std::string slurp(const std::string& path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}
}  // namespace

TEST_GROUP(SlamConfig){};

TEST(SlamConfig, shipped_default_config_loads_and_equals_the_built_in_defaults) {
  slam::SlamConfig c;
  c.filter.particle_count = 7;  // the mode sets it (30 dpslam, 10 sdp): the file leaves it
  std::string error;
  CHECK_TRUE_TEXT(slam::load_config_ini(SDPSLAM_DEFAULT_INI, &c, &error), error.c_str());
  const DpSlamOptions d;
  LONGS_EQUAL(7, c.filter.particle_count);
  DOUBLES_EQUAL(d.beam.sigma_hit_m, c.filter.beam.sigma_hit_m, 0.0);
  DOUBLES_EQUAL(d.motion.alpha_rot_from_rot, c.filter.motion.alpha_rot_from_rot, 0.0);
  DOUBLES_EQUAL(d.map_width_m, c.filter.map_width_m, 0.0);
  LONGS_EQUAL(d.path_entries_per_particle, c.filter.path_entries_per_particle);
  LONGS_EQUAL(d.beam.weight_beam_stride, c.filter.beam.weight_beam_stride);
  CHECK(c.filter.proposal == d.proposal);
  CHECK(c.filter.proposal_weight == d.proposal_weight);
  DOUBLES_EQUAL(d.match.linear_step_m, c.filter.match.linear_step_m, 0.0);
  DOUBLES_EQUAL(d.match.angular_step_rad, c.filter.match.angular_step_rad, 0.0);
  LONGS_EQUAL(d.match.refinements, c.filter.match.refinements);
  LONGS_EQUAL(d.match.max_iterations, c.filter.match.max_iterations);
  LONGS_EQUAL(d.match.beam_stride, c.filter.match.beam_stride);
  LONGS_EQUAL(d.match.min_beams, c.filter.match.min_beams);
  DOUBLES_EQUAL(d.match.min_known_fraction, c.filter.match.min_known_fraction, 0.0);
  DOUBLES_EQUAL(d.match.min_mean_log_likelihood, c.filter.match.min_mean_log_likelihood, 0.0);
  DOUBLES_EQUAL(d.proposal_sigma_xy_m, c.filter.proposal_sigma_xy_m, 0.0);
  DOUBLES_EQUAL(d.proposal_sigma_rot_rad, c.filter.proposal_sigma_rot_rad, 0.0);
  CHECK(c.filter.validate(nullptr, 0));
}

TEST(SlamConfig, proposal_section_selects_the_improved_proposal) {
  slam::SlamConfig c;
  std::string error;
  CHECK_TRUE_TEXT(slam::load_config_ini(write_temp("[proposal]\nkind = scan_match\nweight = neighbourhood\n"
                                                   "beam_stride = 3\nsample_sigma_rot_rad = 0.01\n"),
                                        &c, &error),
                  error.c_str());
  CHECK(c.filter.proposal == DpSlamOptions::Proposal::kScanMatch);
  CHECK(c.filter.proposal_weight == DpSlamOptions::ProposalWeight::kNeighbourhood);
  LONGS_EQUAL(3, c.filter.match.beam_stride);
  DOUBLES_EQUAL(0.01, c.filter.proposal_sigma_rot_rad, 0.0);
}

TEST(SlamConfig, unknown_proposal_kind_and_bad_matcher_values_are_rejected) {
  slam::SlamConfig c;
  std::string error;
  CHECK_FALSE(slam::load_config_ini(write_temp("[proposal]\nkind = icp\n"), &c, &error));
  STRCMP_CONTAINS(":2:", error.c_str());
  STRCMP_CONTAINS("odometry or scan_match", error.c_str());
  CHECK_FALSE(slam::load_config_ini(write_temp("[proposal]\nweight = max\n"), &c, &error));
  STRCMP_CONTAINS("match or neighbourhood", error.c_str());
  slam::SlamConfig c2;
  CHECK_FALSE(slam::load_config_ini(write_temp("[proposal]\nrefinements = 11\n"), &c2, &error));
  STRCMP_CONTAINS("proposal.refinements", error.c_str());
}

TEST(SlamConfig, unknown_key_is_rejected_with_file_and_line) {
  const std::string path = write_temp("[filter]\nparticles = 10\n\n[motion]\nalpha_typo = 0.1\n");
  slam::SlamConfig c;
  std::string error;
  CHECK_FALSE(slam::load_config_ini(path, &c, &error));
  STRCMP_CONTAINS((path + ":5:").c_str(), error.c_str());
  STRCMP_CONTAINS("alpha_typo", error.c_str());
}

// Either would make the file mean what its last occurrence says; [sdp] (read by
// load_sdp_ini) is checked here too.
TEST(SlamConfig, a_section_or_a_key_given_twice_is_rejected_with_file_and_line) {
  const char* const cases[][2] = {
      {"[filter]\nparticles = 10\n[motion]\nalpha_rot_from_rot = 0.1\n[filter]\n", ":5: section [filter] given twice"},
      {"[motion]\nalpha_rot_from_rot = 0.1\nalpha_rot_from_rot = 0.2\n",
       ":3: key 'alpha_rot_from_rot' given twice in section [motion]"},
      {"[sdp]\ntop_particles = 30\ntop_particles = 40\n", ":3: key 'top_particles' given twice in section [sdp]"},
  };
  for (const auto& c : cases) {
    const std::string path = write_temp(c[0]);
    slam::SlamConfig config;
    std::string error;
    CHECK_FALSE(slam::load_config_ini(path, &config, &error));
    STRCMP_CONTAINS((path + c[1]).c_str(), error.c_str());
  }
}

TEST(SlamConfig, out_of_range_value_is_rejected_naming_field_and_range) {
  const std::string path = write_temp("[filter]\nparticles = 100000\n");
  slam::SlamConfig c;
  std::string error;
  CHECK_FALSE(slam::load_config_ini(path, &c, &error));
  STRCMP_CONTAINS(":2:", error.c_str());
  STRCMP_CONTAINS("filter.particles", error.c_str());
  STRCMP_CONTAINS("out of range", error.c_str());
}

TEST(SlamConfig, non_numeric_and_negative_integers_are_rejected) {
  slam::SlamConfig c;
  std::string error;
  CHECK_FALSE(slam::load_config_ini(write_temp("[observation]\nsigma_hit_m = 0.05m\n"), &c, &error));
  STRCMP_CONTAINS("not a finite number", error.c_str());
  CHECK_FALSE(slam::load_config_ini(write_temp("[capacity]\npath_entries_per_particle = -3\n"), &c, &error));
  STRCMP_CONTAINS(":2:", error.c_str());
}

// Found by fuzz_slam_config: the unknown key of line 3 was reported, not line 2 before it.
TEST(SlamConfig, a_malformed_line_before_a_bad_key_is_the_problem_reported) {
  const std::string path = write_temp("[map]\ntile_capac\nwidth_x = 1\n");
  slam::SlamConfig c;
  std::string error;
  CHECK_FALSE(slam::load_config_ini(path, &c, &error));
  STRCMP_EQUAL((path + ":2: malformed line (expected [section] or key = value)").c_str(), error.c_str());
}

// inih parses a line in pieces of 199 bytes: the end of this comment line used to be read
// as a line of its own and applied.
TEST(SlamConfig, a_line_longer_than_198_characters_is_refused_at_its_line_not_cut) {
  const std::string path = write_temp("[filter]\n; " + std::string(197U, 'x') + "particles = 7\n");
  slam::SlamConfig c;
  std::string error;
  CHECK_FALSE(slam::load_config_ini(path, &c, &error));
  STRCMP_EQUAL((path + ":2: line longer than 198 characters").c_str(), error.c_str());
  LONGS_EQUAL(DpSlamOptions{}.particle_count, c.filter.particle_count);
  const std::string longest = write_temp("[filter]\nparticles = 7 ;" + std::string(183U, 'x') + "\n");
  CHECK_TRUE_TEXT(slam::load_config_ini(longest, &c, &error), error.c_str());
  LONGS_EQUAL(7, c.filter.particle_count);
}

// The text after a NUL byte was invisible to the parser: "particles = 7" was applied.
TEST(SlamConfig, a_nul_byte_in_a_line_is_refused) {
  const char text[] = "[filter]\nparticles = 7\0 ; 9\n";
  const std::string path = write_temp(std::string(text, sizeof text - 1U));
  slam::SlamConfig c;
  std::string error;
  CHECK_FALSE(slam::load_config_ini(path, &c, &error));
  STRCMP_EQUAL((path + ":2: control byte 0x00 in the line (not a text file?)").c_str(), error.c_str());
}

TEST(SlamConfig, missing_file_is_an_error_naming_it) {
  slam::SlamConfig c;
  std::string error;
  CHECK_FALSE(slam::load_config_ini("/nonexistent/x.ini", &c, &error));
  STRCMP_CONTAINS("/nonexistent/x.ini", error.c_str());
}

TEST_GROUP(RunOffline){};

TEST(RunOffline, same_seed_gives_identical_trajectory_and_map_on_a_real_log) {
  const std::string log = sdpslam::test::shared_path("datasets/dpslam-loop5.log");
  slam::RunOptions ro;
  ro.config.filter.particle_count = 5;
  ro.seed = 3;
  const std::string a = sdpslam::test::make_temp_dir("run_a");
  const std::string b = sdpslam::test::make_temp_dir("run_b");
  std::string error;
  slam::RunSummary s;
  CHECK_TRUE_TEXT(slam::run_offline(log, ro, a, &s, &error) == slam::RunStatus::kOk, error.c_str());
  CHECK_TRUE_TEXT(slam::run_offline(log, ro, b, nullptr, &error) == slam::RunStatus::kOk, error.c_str());
  CHECK(s.scans > 500U);
  CHECK(s.processed > 20U);
  const std::string ta = slurp(a + "/trajectory.txt");
  std::size_t lines = 0;  // pose lines (comment lines start with '#')
  std::istringstream in(ta);
  for (std::string line; std::getline(in, line);) lines += (!line.empty() && line[0] != '#') ? 1U : 0U;
  LONGS_EQUAL(s.scans, lines);
  CHECK(ta == slurp(b + "/trajectory.txt"));
  CHECK(slurp(a + "/map.pgm") == slurp(b + "/map.pgm"));
  CHECK(!slurp(a + "/map.pgm").empty());
  STRCMP_CONTAINS("\"naive_copy_bytes\"", slurp(a + "/stats.json").c_str());
}

TEST(RunOffline, unreadable_log_is_bad_input) {
  slam::RunOptions ro;
  std::string error;
  CHECK(slam::run_offline("/nonexistent.clf", ro, sdpslam::test::make_temp_dir("run_c"), nullptr, &error) ==
        slam::RunStatus::kBadInput);
  CHECK(!error.empty());
}

// fopen accepts a directory on Linux and reading it looks like an empty file: the run
// would go on with the built-in defaults as if the file had been read.
TEST(SlamConfig, a_directory_is_refused_as_a_config_file_and_dev_null_reads_as_empty) {
  const std::string dir = sdpslam::test::make_temp_dir("slam_config_dir");
  slam::SlamConfig c;
  std::string error;
  CHECK_FALSE(slam::load_config_ini(dir, &c, &error));
  STRCMP_EQUAL((dir + ": is a directory, not a configuration file").c_str(), error.c_str());
  error.clear();
  std::FILE* f = slam::open_config_file(dir, &error);
  CHECK(f == nullptr);
  STRCMP_EQUAL((dir + ": is a directory, not a configuration file").c_str(), error.c_str());
  CHECK_TRUE_TEXT(slam::load_config_ini("/dev/null", &c, &error), error.c_str());
}
