// The [sdp] section of the shipped INI and its parser.
#include <CppUTest/TestHarness.h>

#include <fstream>
#include <string>

#include "sdpslam/core/sdp_profile.h"
#include "sdpslam/slam/config_ini.h"
#include "sdpslam/slam/run_sdp.h"
#include "shared_data.h"

using namespace sdpslam;

TEST_GROUP(SdpConfig){};

TEST(SdpConfig, shipped_default_sdp_section_loads_and_equals_the_built_in_defaults) {
  SdpOptions o;
  o.top_particles = 7U;  // the file must set it back
  std::string error;
  CHECK_TRUE_TEXT(slam::load_sdp_ini(SDPSLAM_DEFAULT_INI, &o, &error), error.c_str());
  const SdpOptions d;
  LONGS_EQUAL(d.top_particles, o.top_particles);
  LONGS_EQUAL(d.max_levels, o.max_levels);
  DOUBLES_EQUAL(d.period_travel_m, o.period_travel_m, 0.0);
  DOUBLES_EQUAL(d.elite_fraction, o.elite_fraction, 0.0);
  DOUBLES_EQUAL(d.icp.max_correspondence_m, o.icp.max_correspondence_m, 0.0);
  LONGS_EQUAL(d.icp.max_iterations, o.icp.max_iterations);
  LONGS_EQUAL(d.skeleton_points, o.skeleton_points);
  LONGS_EQUAL(static_cast<int>(d.accumulation), static_cast<int>(o.accumulation));
  LONGS_EQUAL(static_cast<int>(d.segmentation), static_cast<int>(o.segmentation));
  CHECK_EQUAL(d.loop_closure, o.loop_closure);
  LONGS_EQUAL(d.loop_points, o.loop_points);
  DOUBLES_EQUAL(d.loop_icp_max_correspondence_m, o.loop_icp_max_correspondence_m, 0.0);
  DOUBLES_EQUAL(d.loop_max_error_m, o.loop_max_error_m, 0.0);
  LONGS_EQUAL(d.loop_min_pairs, o.loop_min_pairs);
  DOUBLES_EQUAL(d.loop_max_correction_m, o.loop_max_correction_m, 0.0);
  DOUBLES_EQUAL(d.segment_sigma_xy_m, o.segment_sigma_xy_m, 0.0);
  DOUBLES_EQUAL(d.segment_sigma_theta_rad, o.segment_sigma_theta_rad, 0.0);
  DOUBLES_EQUAL(d.loop_sigma_xy_m, o.loop_sigma_xy_m, 0.0);
  DOUBLES_EQUAL(d.loop_sigma_theta_rad, o.loop_sigma_theta_rad, 0.0);
  DOUBLES_EQUAL(d.loop_normal_radius_m, o.loop_normal_radius_m, 0.0);
  DOUBLES_EQUAL(d.loop_weak_direction_floor, o.loop_weak_direction_floor, 0.0);
  DOUBLES_EQUAL(d.loop_robust_chi, o.loop_robust_chi, 0.0);
  LONGS_EQUAL(d.max_loop_constraints, o.max_loop_constraints);
  LONGS_EQUAL(d.graph_iterations, o.graph_iterations);
  DOUBLES_EQUAL(d.loop_search_window_m, o.loop_search_window_m, 0.0);
  DOUBLES_EQUAL(d.loop_search_max_window_m, o.loop_search_max_window_m, 0.0);
  DOUBLES_EQUAL(d.loop_search_window_rad, o.loop_search_window_rad, 0.0);
  DOUBLES_EQUAL(d.loop_search_min_score, o.loop_search_min_score, 0.0);
  DOUBLES_EQUAL(d.loop_search_max_ambiguity, o.loop_search_max_ambiguity, 0.0);
  DOUBLES_EQUAL(d.loop_search_drift_m, o.loop_search_drift_m, 0.0);
  LONGS_EQUAL(d.permanent_map_tiles, o.permanent_map_tiles);
  LONGS_EQUAL(d.loop_search_candidates, o.loop_search_candidates);
  LONGS_EQUAL(d.loop_search_reads_per_scan, o.loop_search_reads_per_scan);
  CHECK_EQUAL(d.defer_top_work, o.defer_top_work);
  // ... and the bottom-level loader skips the [sdp] section.
  slam::SlamConfig c;
  CHECK_TRUE_TEXT(slam::load_config_ini(SDPSLAM_DEFAULT_INI, &c, &error), error.c_str());
}

TEST(SdpConfig, shipped_default_file_leaves_the_profile_keys_to_the_profile) {
  // default.ini can be used as it is on top of either profile.
  slam::SlamConfig c;
  SdpOptions o;
  apply_profile(SdpProfile::kAccurate, &c.filter, &o);
  std::string error;
  CHECK_TRUE_TEXT(slam::load_config_ini(SDPSLAM_DEFAULT_INI, &c, &error), error.c_str());
  CHECK_TRUE_TEXT(slam::load_sdp_ini(SDPSLAM_DEFAULT_INI, &o, &error), error.c_str());
  CHECK(c.filter.proposal == DpSlamOptions::Proposal::kScanMatch);
  LONGS_EQUAL(8, c.filter.match.beam_stride);
  LONGS_EQUAL(8, o.max_levels);
  CHECK_TRUE(o.loop_closure);
  DOUBLES_EQUAL(6.0, o.loop_search_window_m, 0.0);
  DOUBLES_EQUAL(16.0, o.loop_search_max_window_m, 0.0);
}

TEST(SdpConfig, unknown_or_out_of_range_sdp_keys_are_rejected_with_file_and_line) {
  const std::string dir = sdpslam::test::make_temp_dir("sdp_config");
  const std::string path = dir + "/c.ini";
  std::ofstream(path) << "[filter]\nparticles = 5\n[sdp]\ntop_particles = 20\nmax_levels = 1\n";
  SdpOptions o;
  std::string error;
  CHECK_FALSE(slam::load_sdp_ini(path, &o, &error));
  CHECK_TRUE_TEXT(error.find(path + ":5:") != std::string::npos, error.c_str());
  CHECK_TRUE_TEXT(error.find("max_levels") != std::string::npos, error.c_str());
  std::ofstream(path) << "[sdp]\nno_such_key = 1\n";
  CHECK_FALSE(slam::load_sdp_ini(path, &o, &error));
  CHECK_TRUE_TEXT(error.find(":2:") != std::string::npos && error.find("no_such_key") != std::string::npos,
                  error.c_str());
  std::ofstream(path) << "[sdp]\ntopology = global\n";
  CHECK_FALSE(slam::load_sdp_ini(path, &o, &error));
  CHECK_TRUE_TEXT(error.find("topology") != std::string::npos, error.c_str());
}

// Found with fuzz_slam_config's check that a refusal is the file's first problem: the
// reason of a later bad line was reported under the line number of the first one.
TEST(SdpConfig, a_refusal_names_the_first_bad_line_with_its_own_reason) {
  const std::string dir = sdpslam::test::make_temp_dir("sdp_config_first");
  const std::string path = dir + "/c.ini";
  std::ofstream(path) << "[sdp]\ntop_particles = x\nmax_levels = 1\n";
  SdpOptions o;
  std::string error;
  CHECK_FALSE(slam::load_sdp_ini(path, &o, &error));
  STRCMP_EQUAL((path + ":2: [sdp] top_particles: malformed value 'x'").c_str(), error.c_str());
  std::ofstream(path) << "[sdp]\nbroken line\nno_such_key = 1\n";
  CHECK_FALSE(slam::load_sdp_ini(path, &o, &error));
  STRCMP_EQUAL((path + ":2: malformed line").c_str(), error.c_str());
  std::ofstream(path) << "[sdp]\n; " + std::string(197U, 'x') + "max_levels = 1\n";
  CHECK_FALSE(slam::load_sdp_ini(path, &o, &error));
  STRCMP_EQUAL((path + ":2: line longer than 198 characters").c_str(), error.c_str());
}

TEST(SdpConfig, accurate_profile_turns_on_scan_matching_loop_closure_and_search) {
  DpSlamOptions b;
  SdpOptions o;
  apply_profile(SdpProfile::kAccurate, &b, &o);
  CHECK_TRUE(o.loop_closure);
  CHECK(o.loop_search_window_m > 0.0);
  LONGS_EQUAL(8, o.max_levels);
  CHECK(b.proposal == DpSlamOptions::Proposal::kScanMatch);
  LONGS_EQUAL(8, b.match.beam_stride);
  char why[200];
  CHECK_TRUE_TEXT(b.validate(why, sizeof why), why);
  CHECK_TRUE_TEXT(o.validate(why, sizeof why), why);
  CHECK(kDefaultSdpProfile == SdpProfile::kAccurate);
}

TEST(SdpConfig, paper_profile_is_the_declared_defaults_and_changes_nothing) {
  DpSlamOptions b;
  SdpOptions o;
  b.match.beam_stride = 5U;  // a value set before the profile stays
  apply_profile(SdpProfile::kPaper, &b, &o);
  CHECK(b.proposal == DpSlamOptions::Proposal::kOdometry);
  LONGS_EQUAL(5, b.match.beam_stride);
  CHECK_FALSE(o.loop_closure);
  DOUBLES_EQUAL(0.0, o.loop_search_window_m, 0.0);
  DOUBLES_EQUAL(0.0, o.loop_search_max_window_m, 0.0);
  LONGS_EQUAL(12, o.max_levels);
}

TEST(SdpConfig, profile_names_parse_and_print_both_ways) {
  SdpProfile p = SdpProfile::kPaper;
  CHECK_TRUE(parse_sdp_profile("accurate", &p));
  CHECK(p == SdpProfile::kAccurate);
  STRCMP_EQUAL("accurate", to_string(p));
  CHECK_TRUE(parse_sdp_profile("paper", &p));
  STRCMP_EQUAL("paper", to_string(p));
  CHECK_FALSE(parse_sdp_profile("best", &p));
  CHECK_FALSE(parse_sdp_profile("", &p));
  CHECK_FALSE(parse_sdp_profile(nullptr, &p));
  CHECK(p == SdpProfile::kPaper);
}

TEST(SdpConfig, loop_closure_keys_are_parsed_and_range_checked) {
  SdpOptions o;
  std::string why;
  CHECK(slam::apply_sdp_key(&o, "loop_closure", "true", &why) == slam::SdpKeyResult::kApplied);
  CHECK_TRUE(o.loop_closure);
  CHECK(slam::apply_sdp_key(&o, "loop_closure", "yes", &why) == slam::SdpKeyResult::kInvalid);
  CHECK(slam::apply_sdp_key(&o, "loop_max_correction_m", "2.5", &why) == slam::SdpKeyResult::kApplied);
  DOUBLES_EQUAL(2.5, o.loop_max_correction_m, 0.0);
  CHECK(slam::apply_sdp_key(&o, "loop_points", "8", &why) == slam::SdpKeyResult::kInvalid);
  CHECK_TRUE_TEXT(why.find("loop_points") != std::string::npos, why.c_str());
  CHECK(slam::apply_sdp_key(&o, "loop_sigma_xy_m", "0", &why) == slam::SdpKeyResult::kInvalid);
  CHECK(slam::apply_sdp_key(&o, "graph_iterations", "0", &why) == slam::SdpKeyResult::kInvalid);
  CHECK(slam::apply_sdp_key(&o, "loop_normal_radius_m", "0", &why) == slam::SdpKeyResult::kApplied);
  DOUBLES_EQUAL(0.0, o.loop_normal_radius_m, 0.0);
  CHECK(slam::apply_sdp_key(&o, "loop_normal_radius_m", "2.5", &why) == slam::SdpKeyResult::kInvalid);
  CHECK_TRUE_TEXT(why.find("loop_normal_radius_m") != std::string::npos, why.c_str());
  CHECK(slam::apply_sdp_key(&o, "loop_weak_direction_floor", "0", &why) == slam::SdpKeyResult::kInvalid);
  CHECK(slam::apply_sdp_key(&o, "loop_weak_direction_floor", "1", &why) == slam::SdpKeyResult::kApplied);
  CHECK(slam::apply_sdp_key(&o, "max_loop_constraints", "2000000", &why) == slam::SdpKeyResult::kInvalid);
  CHECK(slam::apply_sdp_key(&o, "loop_search_window_m", "6", &why) == slam::SdpKeyResult::kApplied);
  DOUBLES_EQUAL(6.0, o.loop_search_window_m, 0.0);
  CHECK(slam::apply_sdp_key(&o, "loop_search_window_m", "25", &why) == slam::SdpKeyResult::kInvalid);
  CHECK_TRUE_TEXT(why.find("loop_search_window_m") != std::string::npos, why.c_str());
  CHECK(slam::apply_sdp_key(&o, "loop_search_max_window_m", "51", &why) == slam::SdpKeyResult::kInvalid);
  CHECK_TRUE_TEXT(why.find("loop_search_max_window_m") != std::string::npos, why.c_str());
  CHECK(slam::apply_sdp_key(&o, "loop_search_max_window_m", "12", &why) == slam::SdpKeyResult::kApplied);
  DOUBLES_EQUAL(12.0, o.loop_search_max_window_m, 0.0);
  CHECK(slam::apply_sdp_key(&o, "loop_search_min_score", "0", &why) == slam::SdpKeyResult::kInvalid);
  CHECK(slam::apply_sdp_key(&o, "loop_search_candidates", "33", &why) == slam::SdpKeyResult::kInvalid);
  CHECK(slam::apply_sdp_key(&o, "loop_search_drift_m", "-1", &why) == slam::SdpKeyResult::kInvalid);
  CHECK_TRUE_TEXT(why.find("loop_search_drift_m") != std::string::npos, why.c_str());
  CHECK(slam::apply_sdp_key(&o, "loop_search_drift_m", "0", &why) == slam::SdpKeyResult::kApplied);
  DOUBLES_EQUAL(0.0, o.loop_search_drift_m, 0.0);
  CHECK(slam::apply_sdp_key(&o, "permanent_map_tiles", "0", &why) == slam::SdpKeyResult::kInvalid);
  CHECK_TRUE_TEXT(why.find("permanent_map_tiles") != std::string::npos, why.c_str());
  CHECK(slam::apply_sdp_key(&o, "permanent_map_tiles", "1234", &why) == slam::SdpKeyResult::kApplied);
  LONGS_EQUAL(1234, o.permanent_map_tiles);
  CHECK(slam::apply_sdp_key(&o, "loop_search_reads_per_scan", "100", &why) == slam::SdpKeyResult::kInvalid);
  // Removed: the search's constraints are verified and enter the pose graph without a kernel.
  CHECK(slam::apply_sdp_key(&o, "loop_search_robust_chi", "12.5", &why) == slam::SdpKeyResult::kUnknown);
}

TEST(SdpConfig, enumerated_keys_take_their_names) {
  SdpOptions o;
  std::string why;
  CHECK(slam::apply_sdp_key(&o, "topology", "segslam", &why) == slam::SdpKeyResult::kApplied);
  CHECK(o.topology == TopologyMode::kSegSlam);
  CHECK(slam::apply_sdp_key(&o, "segmentation", "dispersion", &why) == slam::SdpKeyResult::kApplied);
  CHECK(o.segmentation == SegmentationMode::kDispersion);
  CHECK(slam::apply_sdp_key(&o, "accumulation", "mean", &why) == slam::SdpKeyResult::kApplied);
  CHECK(o.accumulation == PgsAccumulation::kMean);
  CHECK_FALSE(o.map_owner_cell_index);
  CHECK(slam::apply_sdp_key(&o, "map_owner_cell_index", "true", &why) == slam::SdpKeyResult::kApplied);
  CHECK_TRUE(o.map_owner_cell_index);
  CHECK(slam::apply_sdp_key(&o, "map_owner_cell_index", "1", &why) == slam::SdpKeyResult::kInvalid);
  CHECK(slam::apply_sdp_key(&o, "elite_fraction", "abc", &why) == slam::SdpKeyResult::kInvalid);
  CHECK(slam::apply_sdp_key(&o, "nothing", "1", &why) == slam::SdpKeyResult::kUnknown);
}

TEST(SdpConfig, a_directory_is_refused_as_a_config_file) {
  const std::string dir = sdpslam::test::make_temp_dir("sdp_config_dir");
  SdpOptions o;
  std::string error;
  CHECK_FALSE(slam::load_sdp_ini(dir, &o, &error));
  STRCMP_EQUAL((dir + ": is a directory, not a configuration file").c_str(), error.c_str());
}
