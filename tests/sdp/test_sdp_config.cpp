// The [sdp] section of the shipped INI and its parser.
#include <CppUTest/TestHarness.h>

#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "sdpslam/core/sdp_profile.h"
#include "sdpslam/slam/config_ini.h"
#include "sdpslam/slam/ini_document.h"
#include "sdpslam/slam/option_text.h"
#include "sdpslam/slam/run_sdp.h"
#include "shared_data.h"

using namespace sdpslam;

TEST_GROUP(SdpConfig){};

namespace {

// True iff either profile gives the row another value than the struct's own default:
// such a key is the profile's, and default.ini leaves it out (in a comment).
template <class Options>
bool set_by_a_profile(const OptionSpec<Options>& row, const Options& built_in, const Options& accurate,
                      const Options& paper) {
  const std::string d = slam::option_text(row, built_in);
  return slam::option_text(row, accurate) != d || slam::option_text(row, paper) != d;
}

// Every row of `table`: in range at its default, documented, and in the shipped
// default.ini either with its default value or, when a profile sets it, in a comment.
template <class Options>
void check_table_against_default_ini(const OptionTable<Options>& table, const Options& built_in,
                                     const Options& loaded, const Options& accurate, const Options& paper,
                                     const slam::IniDocument& doc, const std::string& text) {
  CHECK(table.count > 0U);
  for (const OptionSpec<Options>& row : table) {
    const std::string name = std::string(row.section) + "." + row.key;
    char why[200];
    CHECK_TRUE_TEXT(option_in_range(row, built_in, why, sizeof why), why);
    CHECK_TRUE_TEXT(row.doc != nullptr && row.doc[0] != '\0', name.c_str());
    CHECK_TRUE_TEXT(table.find(row.section, row.key) == &row, ("given twice: " + name).c_str());
    if (set_by_a_profile(row, built_in, accurate, paper)) {
      CHECK_EQUAL_TEXT(0, doc.line_of(row.section, row.key), ("the profile's key is set in default.ini: " + name).c_str());
      CHECK_TRUE_TEXT(text.find("; " + std::string(row.key) + ":") != std::string::npos,
                      ("default.ini does not say the profile sets " + name).c_str());
    } else {
      CHECK_TRUE_TEXT(doc.line_of(row.section, row.key) > 0, ("missing from default.ini: " + name).c_str());
    }
    STRCMP_EQUAL_TEXT(slam::option_text(row, built_in).c_str(), slam::option_text(row, loaded).c_str(), name.c_str());
  }
}

}  // namespace

// The shipped default.ini documents every key of both tables, and with their defaults:
// a key added to a table and not to the file (or the other way round) fails here.
TEST(SdpConfig, shipped_default_ini_holds_every_table_key_with_its_default) {
  std::string error;
  slam::IniDocument doc;
  CHECK_TRUE_TEXT(doc.load(SDPSLAM_DEFAULT_INI, &error), error.c_str());
  STRCMP_EQUAL("", doc.problem().c_str());
  std::ifstream in(SDPSLAM_DEFAULT_INI);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  DpSlamOptions filter_accurate, filter_paper;
  SdpOptions sdp_accurate, sdp_paper;
  apply_profile(SdpProfile::kAccurate, &filter_accurate, &sdp_accurate);
  apply_profile(SdpProfile::kPaper, &filter_paper, &sdp_paper);
  SdpOptions sdp;
  sdp.top_particles = 7U;  // the file must set it back
  CHECK_TRUE_TEXT(slam::load_sdp_ini(SDPSLAM_DEFAULT_INI, &sdp, &error), error.c_str());
  check_table_against_default_ini(SdpOptions::table(), SdpOptions{}, sdp, sdp_accurate, sdp_paper, doc, text);
  slam::SlamConfig c;
  CHECK_TRUE_TEXT(slam::load_config_ini(SDPSLAM_DEFAULT_INI, &c, &error), error.c_str());
  check_table_against_default_ini(DpSlamOptions::table(), DpSlamOptions{}, c.filter, filter_accurate, filter_paper,
                                  doc, text);
  const io::LogReaderOptions log_defaults;
  check_table_against_default_ini(slam::log_option_table(), log_defaults, c.log, log_defaults, log_defaults, doc, text);
  // Every key of the file is a key of a table.
  for (const slam::IniEntry& e : doc.entries()) {
    const bool known = SdpOptions::table().find(e.section.c_str(), e.key.c_str()) != nullptr ||
                       DpSlamOptions::table().find(e.section.c_str(), e.key.c_str()) != nullptr ||
                       slam::log_option_table().find(e.section.c_str(), e.key.c_str()) != nullptr;
    CHECK_TRUE_TEXT(known, (e.section + "." + e.key).c_str());
  }
}

namespace {

// Every number row: a value just outside its range, set in the options and in a file,
// is refused, naming the row (validate) and the file's line (the INI reader).
template <class Options>
void check_rows_refuse_values_outside_their_range(const OptionTable<Options>& table) {
  for (const OptionSpec<Options>& row : table) {
    if (row.kind != OptionKind::kReal && row.kind != OptionKind::kU32) continue;
    const std::string name = std::string(row.section) + "." + row.key;
    std::vector<double> outside;
    if (row.max < 4294967295.0) outside.push_back(row.kind == OptionKind::kU32 ? row.max + 1.0 : row.max * 1.5 + 1.0);
    if (row.min_open || row.min > 0.0) outside.push_back(row.min_open ? row.min : row.min - (row.kind == OptionKind::kU32 ? 1.0 : 0.5 * row.min + 1e-9));
    if (!row.min_open && row.min <= 0.0 && row.kind == OptionKind::kReal) outside.push_back(row.min - 1.0);
    for (double v : outside) {
      if (row.kind == OptionKind::kU32 && v < 0.0) continue;
      Options o;
      if (row.kind == OptionKind::kReal) option_field<double>(row, o) = v;
      else option_field<std::uint32_t>(row, o) = static_cast<std::uint32_t>(v);
      char why[240];
      CHECK_FALSE_TEXT(o.validate(why, sizeof why), (name + " = " + slam::real_text(v)).c_str());
      CHECK_TRUE_TEXT(std::string(why).rfind(name + ":", 0) == 0, why);
      std::string error;
      Options from_text;
      CHECK_FALSE_TEXT(slam::set_option_text(row, &from_text, slam::real_text(v).c_str(), &error), name.c_str());
      CHECK_TRUE_TEXT(error.rfind(name + ":", 0) == 0, error.c_str());
    }
  }
}

}  // namespace

TEST(SdpConfig, every_row_refuses_values_outside_its_range_by_name) {
  check_rows_refuse_values_outside_their_range(SdpOptions::table());
  check_rows_refuse_values_outside_their_range(DpSlamOptions::table());
}

// firmware-host/runtime/slam/scan_match.ini (mode dpslam with the improved proposal) sets what the
// accurate profile sets on the bottom level, and nothing else.
TEST(SdpConfig, scan_match_ini_is_the_accurate_profile_s_bottom_level) {
  slam::SlamConfig c;
  std::string error;
  CHECK_TRUE_TEXT(slam::load_config_ini(SDPSLAM_SCAN_MATCH_INI, &c, &error), error.c_str());
  DpSlamOptions accurate;
  SdpOptions ignored;
  apply_profile(SdpProfile::kAccurate, &accurate, &ignored);
  accurate.particle_count = DpSlamOptions{}.particle_count;  // the mode's, not the file's
  for (const OptionSpec<DpSlamOptions>& row : DpSlamOptions::table()) {
    STRCMP_EQUAL_TEXT(slam::option_text(row, accurate).c_str(), slam::option_text(row, c.filter).c_str(), row.key);
  }
}

// A file means the same whatever the order of its keys: checks that join keys run once,
// after the last one, and name the line of the first key they join.
TEST(SdpConfig, keys_are_validated_together_after_the_whole_file) {
  const std::string dir = sdpslam::test::make_temp_dir("sdp_config_order");
  const std::string path = dir + "/c.ini";
  SdpOptions o;
  std::string error;
  std::ofstream(path) << "[sdp]\nmax_segment_scans = 5\nmin_segment_scans = 3\n";
  CHECK_TRUE_TEXT(slam::load_sdp_ini(path, &o, &error), error.c_str());
  LONGS_EQUAL(5, o.max_segment_scans);
  LONGS_EQUAL(3, o.min_segment_scans);
  o = SdpOptions{};
  std::ofstream(path) << "[sdp]\nmin_segment_scans = 3\nmax_segment_scans = 5\n";
  CHECK_TRUE_TEXT(slam::load_sdp_ini(path, &o, &error), error.c_str());
  LONGS_EQUAL(5, o.max_segment_scans);
  o = SdpOptions{};
  std::ofstream(path) << "[sdp]\ntop_particles = 30\nworst_fraction = 0.5\nelite_fraction = 0.6\n";
  CHECK_FALSE(slam::load_sdp_ini(path, &o, &error));
  STRCMP_EQUAL((path + ":4: sdp.elite_fraction + worst_fraction: more than 1").c_str(), error.c_str());
  LONGS_EQUAL(SdpOptions{}.top_particles, o.top_particles);  // a refused file changes nothing
  // The bottom level's sections alike: a finer map first, then the window it allows.
  slam::SlamConfig c;
  std::ofstream(path) << "[observation]\nwindow_m = 0.03\n[map]\nresolution_m = 0.01\n";
  CHECK_TRUE_TEXT(slam::load_config_ini(path, &c, &error), error.c_str());
  DOUBLES_EQUAL(0.03, c.filter.beam.window_m, 0.0);
  c = slam::SlamConfig{};
  std::ofstream(path) << "[observation]\nwindow_m = 0.03\n";
  CHECK_FALSE(slam::load_config_ini(path, &c, &error));
  CHECK_TRUE_TEXT(error.find(path + ":2: observation.window_m") == 0U, error.c_str());
}

// One dialect for every reader: booleans take true/false, yes/no, on/off, 1/0.
TEST(SdpConfig, values_share_one_dialect) {
  bool b = false;
  for (const char* t : {"true", "yes", "on", "1"}) {
    b = false;
    CHECK_TRUE_TEXT(slam::parse_bool_text(t, &b) && b, t);
  }
  for (const char* f : {"false", "no", "off", "0"}) {
    b = true;
    CHECK_TRUE_TEXT(slam::parse_bool_text(f, &b) && !b, f);
  }
  CHECK_FALSE(slam::parse_bool_text("True", &b));
  CHECK_FALSE(slam::parse_bool_text("", &b));
  std::uint32_t u = 0U;
  CHECK_FALSE(slam::parse_u32_text("-1", &u));
  CHECK_FALSE(slam::parse_u32_text("+1", &u));
  CHECK_FALSE(slam::parse_u32_text("4294967296", &u));
  CHECK_TRUE(slam::parse_u32_text("4294967295", &u));
  double d = 0.0;
  CHECK_FALSE(slam::parse_real_text("nan", &d));
  CHECK_FALSE(slam::parse_real_text("1e999", &d));
  CHECK_FALSE(slam::parse_real_text("1 m", &d));
  for (double v : {0.1, 0.15, 1505000.0, 1.0e-6, 3.14159265358979323846, -3.5}) {
    CHECK_TRUE(slam::parse_real_text(slam::real_text(v).c_str(), &d));
    DOUBLES_EQUAL(v, d, 0.0);
  }
  STRCMP_EQUAL("0.15", slam::real_text(0.15).c_str());
  const OptionSpec<SdpOptions>* row = SdpOptions::table().find("sdp", "topology");
  CHECK(row != nullptr);
  STRCMP_EQUAL("sdp | segslam", slam::option_range_text(*row).c_str());
  row = SdpOptions::table().find("sdp", "loop_search_min_score");
  CHECK(row != nullptr);
  STRCMP_EQUAL("(0, 1]", slam::option_range_text(*row).c_str());
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
  STRCMP_EQUAL((path + ":2: sdp.top_particles: 'x' is not a non-negative 32-bit integer").c_str(), error.c_str());
  std::ofstream(path) << "[sdp]\nbroken line\nno_such_key = 1\n";
  CHECK_FALSE(slam::load_sdp_ini(path, &o, &error));
  STRCMP_EQUAL((path + ":2: malformed line (expected [section] or key = value)").c_str(), error.c_str());
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
  CHECK(slam::apply_sdp_key(&o, "loop_closure", "off", &why) == slam::SdpKeyResult::kApplied);
  CHECK_FALSE(o.loop_closure);
  CHECK(slam::apply_sdp_key(&o, "loop_closure", "maybe", &why) == slam::SdpKeyResult::kInvalid);
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
  CHECK(slam::apply_sdp_key(&o, "map_owner_cell_index", "2", &why) == slam::SdpKeyResult::kInvalid);
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
