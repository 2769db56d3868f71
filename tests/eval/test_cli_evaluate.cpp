// `sdpslam evaluate` end to end: figures on a tiny synthetic log, loop constraints
// against a ground truth, JSON output, and exit codes with file:line for bad input.
#include <CppUTest/TestHarness.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "sdpslam/io/atomic_file.h"
#include "sdpslam/io/map_image.h"
#include "run_program.h"
#include "shared_data.h"

namespace {

using Run = sdpslam::test::ProgramRun;

Run run_evaluate(const std::string& args) {
  return sdpslam::test::run_program(std::string(SDPSLAM_CLI_PATH) + " evaluate " + args);
}

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The --json file as nlohmann reads it; a discarded value (is_discarded()) when it is not
// JSON.
nlohmann::json json_of(const std::string& path) { return nlohmann::json::parse(slurp(path), nullptr, false); }

}  // namespace

TEST_GROUP(CliEvaluate) {
  std::string dir;
  void setup() override { dir = sdpslam::test::make_temp_dir("cli-eval"); }
  void teardown() override {
    for (const char* f : {"/log.clf", "/r.relations", "/t.txt", "/gt.txt", "/bad.txt", "/out.json", "/m.pgm", "/m.yaml",
                          "/l.tsv"}) {
      ::unlink((dir + f).c_str());
    }
    ::rmdir(dir.c_str());
  }
  std::string put(const char* name, const std::string& text) {
    std::string error;
    const std::string p = dir + "/" + name;
    CHECK_TRUE(sdpslam::io::write_file_atomic(p, text, &error));
    return p;
  }
  // Three scans driving 1 m straight ahead each; odometry says 1.1 m per step.
  std::string log() {
    return put("log.clf",
               "FLASER 3 1.0 2.0 3.0 0 0 0 0 0 0 10.000000 host 0.1\n"
               "FLASER 3 1.0 2.0 3.0 1.1 0 0 1.1 0 0 11.000000 host 1.1\n"
               "FLASER 3 1.0 2.0 3.0 2.2 0 0 2.2 0 0 12.000000 host 2.1\n");
  }
  std::string relations() {
    return put("r.relations",
               "10.000000 11.000000 1.0 0 0 0 0 0\n"
               "11.000000 12.000000 1.0 0 0 0 0 0\n");
  }
};

TEST(CliEvaluate, odometry_relations_figures_and_json) {
  const std::string json = dir + "/out.json";
  const Run r = run_evaluate("--log " + log() + " --relations " + relations() + " --odometry --json " + json);
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  STRCMP_CONTAINS("used 2 (2 exact stamp matches), unmatched 0", r.out.c_str());
  STRCMP_CONTAINS("translation [m]            0.100000     0.000000     0.100000", r.out.c_str());
  const nlohmann::json j = json_of(json);
  CHECK_FALSE(j.is_discarded());
  CHECK_TRUE(j["relations"]["used_count"].is_number_unsigned());
  LONGS_EQUAL(2, j["relations"]["used_count"].get<int>());
  DOUBLES_EQUAL(0.1, j["relations"]["translation_m"]["mean"].get<double>(), 1e-12);
  STRCMP_EQUAL("odometry", j["relations"]["trajectory"].get<std::string>().c_str());
  // The benchmark scripts (tools/bench) read a statistic from one line.
  STRCMP_CONTAINS("\"translation_m\": {\"mean\": 0.1", slurp(json).c_str());
}

// Paths are JSON strings whatever they hold: quotes, backslashes and UTF-8 read back as
// they were given.
TEST(CliEvaluate, paths_with_quotes_and_backslashes_read_back_from_the_json) {
  const std::string gt = put("g\"t\\1\xc3\xa9.txt", "1 0 0 0\n2 1 0 0\n3 1 1 1.5\n");
  const std::string t = put("t.txt", "1 5 5 0\n2 6 5 0\n3 6 6 1.5\n");
  const std::string json = dir + "/out.json";
  const Run r = run_evaluate("--trajectory " + t + " --ground-truth '" + gt + "' --json " + json);
  ::unlink(gt.c_str());
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  const nlohmann::json j = json_of(json);
  CHECK_FALSE_TEXT(j.is_discarded(), slurp(json).c_str());
  STRCMP_EQUAL(gt.c_str(), j["ate"]["ground_truth"].get<std::string>().c_str());
  STRCMP_EQUAL(t.c_str(), j["ate"]["trajectory"].get<std::string>().c_str());
  CHECK_TRUE(j["ate"]["matched_count"].is_number_unsigned());
  CHECK_TRUE(j["ate"]["rmse_m"].is_number_float());
}

// The worst relation is named with its stamps, in the text and in the JSON.
TEST(CliEvaluate, the_worst_relation_is_named_with_its_stamps) {
  const std::string json = dir + "/out.json";
  const std::string t = put("t.txt", "10.000000 0 0 0\n11.000000 1 0 0\n12.000000 2.5 0 0\n");
  const Run r = run_evaluate("--log " + log() + " --relations " + relations() + " --trajectory " + t + " --json " + json);
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  // Both relations lie within a minute of each other: one event, the 0.5 m one.
  STRCMP_CONTAINS("worst       stamps 11.0 s and 12.0 s (1.00 m apart): 0.500 m, 0.00 deg off", r.out.c_str());
  CHECK(r.out.find("stamps 10.0 s") == std::string::npos);
  const nlohmann::json w = json_of(json)["relations"]["worst"];
  LONGS_EQUAL(1, w.size());
  LONGS_EQUAL(11000000, w[0]["t1_us"].get<long>());
  DOUBLES_EQUAL(0.5, w[0]["translation_m"].get<double>(), 1e-9);
  // Both relations span 1 s: the local class holds them and all the error.
  STRCMP_CONTAINS("span        under 2 s: 2 relations, mean 0.250 m, max 0.500 m (100 % of the error)", r.out.c_str());
  STRCMP_CONTAINS("span        60 s and over: 0 relations", r.out.c_str());
  const nlohmann::json s = json_of(json)["relations"]["by_span"];
  LONGS_EQUAL(3, s.size());
  LONGS_EQUAL(2, s[0]["count"].get<long>());
  DOUBLES_EQUAL(2.0, s[0]["to_s"].get<double>(), 0.0);
  DOUBLES_EQUAL(1.0, s[0]["share"].get<double>(), 1e-9);
  CHECK_TRUE(s[2]["to_s"].is_null());
}

// With the run's segments, each segment's frame is fitted to the relations: the scan of
// the second segment sits 0.5 m too far, which its frame takes back whole.
TEST(CliEvaluate, segment_frames_fitted_to_the_relations_say_what_their_placement_costs) {
  const std::string json = dir + "/out.json";
  const std::string t = put("t.txt", "10.000000 0 0 0\n11.000000 1 0 0\n12.000000 2.5 0 0\n");
  const std::string seg = put("l.tsv", "# level start\n0 9.999999\n1 11.000000\n");
  const Run r = run_evaluate("--log " + log() + " --relations " + relations() + " --trajectory " + t + " --segments " +
                             seg + " --json " + json);
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  STRCMP_CONTAINS(": 2; each segment's frame fitted rigidly to the relations (1 moved)", r.out.c_str());
  STRCMP_CONTAINS("within a segment     1 relations, mean 0.000 m as estimated, 0.000 m with the fitted frames",
                  r.out.c_str());
  STRCMP_CONTAINS("across segments      1 relations, mean 0.500 m as estimated, 0.000 m with the fitted frames",
                  r.out.c_str());
  STRCMP_CONTAINS("the frames' placement accounts for 0.250 m of the mean (", r.out.c_str());
  const nlohmann::json f = json_of(json)["relations"]["frame_fit"];
  LONGS_EQUAL(1, f["across"]["count"].get<int>());
  DOUBLES_EQUAL(0.5, f["across"]["mean_m"].get<double>(), 1e-9);
  DOUBLES_EQUAL(0.0, f["across"]["fitted_mean_m"].get<double>(), 1e-6);
  CHECK_TRUE(f["converged"].get<bool>());
  // Without --segments the JSON says there was no fit.
  const Run plain = run_evaluate("--log " + log() + " --relations " + relations() + " --trajectory " + t + " --json " +
                                 json);
  LONGS_EQUAL_TEXT(0, plain.status, plain.out.c_str());
  CHECK_TRUE(json_of(json)["relations"]["frame_fit"].is_null());
}

TEST(CliEvaluate, segments_need_a_trajectory_and_a_well_formed_file) {
  const std::string seg = put("l.tsv", "0 9.999999\n1 oops\n");
  Run r = run_evaluate("--log " + log() + " --relations " + relations() + " --odometry --segments " + seg);
  LONGS_EQUAL_TEXT(2, r.status, r.out.c_str());
  STRCMP_CONTAINS("--segments needs --trajectory and --relations or --ground-truth", r.out.c_str());
  const std::string t = put("t.txt", "10.000000 0 0 0\n");
  r = run_evaluate("--log " + log() + " --relations " + relations() + " --trajectory " + t + " --segments " + seg);
  LONGS_EQUAL_TEXT(3, r.status, r.out.c_str());
  STRCMP_CONTAINS((seg + ":2: bad start stamp 'oops'").c_str(), r.out.c_str());
}

TEST(CliEvaluate, segments_against_a_ground_truth_split_placement_from_drift) {
  // 20 m straight at 0.5 m per pose, in two segments. The first is exact but placed 1 m
  // off; the second covers 90 % of each step from its first pose on.
  std::string g;
  std::string e;
  for (int i = 0; i <= 40; ++i) {
    g += std::to_string(i + 1) + " " + std::to_string(0.5 * i) + " 0 0\n";
    const double x = i <= 20 ? 0.5 * i + 1.0 : 10.5 + 0.45 * (i - 21);
    e += std::to_string(i + 1) + " " + std::to_string(x) + " 0 0\n";
  }
  const std::string gt = put("gt.txt", g);
  const std::string t = put("t.txt", e);
  const std::string seg = put("l.tsv", "0 0.999999\n1 21.000000\n");
  const std::string json = dir + "/out.json";
  const Run r = run_evaluate("--trajectory " + t + " --ground-truth " + gt + " --rpe-m 0 --segments " + seg +
                             " --json " + json);
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  STRCMP_CONTAINS(": 2, 2 measured over 19.5 m of path; each segment aligned on its own", r.out.c_str());
  // Segment 1 ends 0.95 m short over a 9.5 m chord; segment 0 has no drift.
  STRCMP_CONTAINS("drift       first to last scan of a segment: mean 0.475000 m, max 0.950000 m, 0.487179 m per 10 m",
                  r.out.c_str());
  STRCMP_CONTAINS("along-track scale -4.872 % (2 chords of 1 m or more)", r.out.c_str());
  const nlohmann::json d = json_of(json)["segment_drift"];
  LONGS_EQUAL(2, d["segments_measured"].get<int>());
  DOUBLES_EQUAL(-0.95 / 19.5, d["along_track_scale"].get<double>(), 1e-12);
  // Aligned on its own, the short segment keeps only its own error: well under the
  // whole run's, which also carries the first segment's 1 m.
  const double within = d["aligned_rmse_m"].get<double>();
  CHECK_TRUE(within > 0.05);
  CHECK_TRUE(within < json_of(json)["ate"]["rmse_m"].get<double>());
  // --segments with the ground truth but no trajectory is a usage error.
  const Run bad = run_evaluate("--loops " + seg + " --ground-truth " + gt + " --segments " + seg);
  LONGS_EQUAL_TEXT(2, bad.status, bad.out.c_str());
  STRCMP_CONTAINS("--segments needs --trajectory", bad.out.c_str());
}

TEST(CliEvaluate, sparse_trajectory_is_filled_with_odometry) {
  // Only the first scan estimated: the rest comes from odometry, so figures equal the
  // odometry's.
  const std::string t = put("t.txt", "10.000000 0 0 0\n");
  const Run r = run_evaluate("--log " + log() + " --relations " + relations() + " --trajectory " + t);
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  STRCMP_CONTAINS("3 scans, 1 estimated, 2 filled from odometry", r.out.c_str());
  STRCMP_CONTAINS("translation [m]            0.100000", r.out.c_str());
}

TEST(CliEvaluate, ate_of_shifted_copy_is_zero) {
  const std::string gt = put("gt.txt", "1 0 0 0\n2 1 0 0\n3 1 1 1.5\n");
  const std::string t = put("t.txt", "1 5 5 0\n2 6 5 0\n3 6 6 1.5\n");
  const Run r = run_evaluate("--trajectory " + t + " --ground-truth " + gt);
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  STRCMP_CONTAINS("rmse 0.000000 m", r.out.c_str());
  STRCMP_CONTAINS("3 matched", r.out.c_str());
}

TEST(CliEvaluate, relative_error_of_a_short_copy_names_its_scale) {
  // 20 m straight at 0.5 m per pose; the estimate covers 90 % of each step.
  std::string g;
  std::string e;
  for (int i = 0; i <= 40; ++i) {
    g += std::to_string(i + 1) + " " + std::to_string(0.5 * i) + " 0 0\n";
    e += std::to_string(i + 1) + " " + std::to_string(0.45 * i) + " 0 0\n";
  }
  const std::string gt = put("gt.txt", g);
  const std::string t = put("t.txt", e);
  const std::string json = dir + "/out.json";
  const Run r = run_evaluate("--trajectory " + t + " --ground-truth " + gt + " --rpe-m 5 --json " + json);
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  STRCMP_CONTAINS("relative    over 31 stretches of 5.000 m: mean 0.500000 m", r.out.c_str());
  STRCMP_CONTAINS("along-track scale -10.000 %", r.out.c_str());
  // Beside "ate", not inside it: tools/bench/accuracy.sh reads it there.
  CHECK_FALSE(json_of(json)["ate"].contains("rpe"));
  const nlohmann::json rpe = json_of(json)["rpe"];
  DOUBLES_EQUAL(5.0, rpe["distance_m"].get<double>(), 0.0);
  LONGS_EQUAL(31, rpe["stretch_count"].get<int>());
  DOUBLES_EQUAL(0.5, rpe["mean_m"].get<double>(), 1e-9);
  // A path shorter than the stretch is said so; --rpe-m 0 leaves it out; a negative
  // distance is a usage error.
  const Run longer = run_evaluate("--trajectory " + t + " --ground-truth " + gt + " --rpe-m 50");
  LONGS_EQUAL_TEXT(0, longer.status, longer.out.c_str());
  STRCMP_CONTAINS("relative    not measured: the ground-truth path is shorter than 50.000 m", longer.out.c_str());
  const Run off = run_evaluate("--trajectory " + t + " --ground-truth " + gt + " --rpe-m 0");
  LONGS_EQUAL_TEXT(0, off.status, off.out.c_str());
  CHECK(off.out.find("relative") == std::string::npos);
  const Run bad = run_evaluate("--trajectory " + t + " --ground-truth " + gt + " --rpe-m -1");
  LONGS_EQUAL_TEXT(2, bad.status, bad.out.c_str());
  STRCMP_CONTAINS("--rpe-m", bad.out.c_str());
}

TEST(CliEvaluate, malformed_trajectory_is_bad_input_with_file_and_line) {
  const std::string bad = put("bad.txt", "1 0 0 0\n2 0 oops 0\n");
  const std::string gt = put("gt.txt", "1 0 0 0\n");
  const Run r = run_evaluate("--trajectory " + bad + " --ground-truth " + gt);
  LONGS_EQUAL(3, r.status);
  STRCMP_CONTAINS((bad + ":2:").c_str(), r.out.c_str());
}

TEST(CliEvaluate, malformed_relations_file_is_bad_input_with_file_and_line) {
  const std::string rel = put("r.relations", "10 11 1 0 0 0 0 0\n10 11 1 0\n");
  const Run r = run_evaluate("--log " + log() + " --relations " + rel + " --odometry");
  LONGS_EQUAL(3, r.status);
  STRCMP_CONTAINS((rel + ":2:").c_str(), r.out.c_str());
}

TEST(CliEvaluate, missing_input_file_is_bad_input) {
  const Run r = run_evaluate("--trajectory " + dir + "/none.txt --ground-truth " + dir + "/none.txt");
  LONGS_EQUAL(3, r.status);
  STRCMP_CONTAINS("none.txt", r.out.c_str());
}

TEST(CliEvaluate, relations_without_a_trajectory_source_is_a_usage_error) {
  const Run r = run_evaluate("--log " + log() + " --relations " + relations());
  LONGS_EQUAL(2, r.status);
  STRCMP_CONTAINS("--odometry", r.out.c_str());
}

TEST(CliEvaluate, unmatched_relations_are_reported) {
  const std::string rel = put("r.relations", "10 11 1 0 0 0 0 0\n11 13 1 0 0 0 0 0\n");
  const Run r = run_evaluate("--log " + log() + " --relations " + rel + " --odometry");
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  STRCMP_CONTAINS((rel + ":2: relation 11.000000 -> 13.000000").c_str(), r.out.c_str());
  STRCMP_CONTAINS("used 1 (1 exact stamp matches), unmatched 1", r.out.c_str());
}

TEST(CliEvaluate, unwritable_json_is_an_output_error) {
  const std::string gt = put("gt.txt", "1 0 0 0\n");
  const Run r = run_evaluate("--trajectory " + gt + " --ground-truth " + gt + " --json " + dir + "/no/dir/out.json");
  LONGS_EQUAL(4, r.status);
  STRCMP_CONTAINS("no/dir/out.json", r.out.c_str());
}

namespace {
// A 20 m square map around the origin, every cell `p`.
std::string uniform_map(const std::string& dir, float p) {
  sdpslam::io::OccupancyImage m;
  m.width = 400U;
  m.height = 400U;
  m.resolution_m = 0.05;
  m.origin_x_m = -10.0;
  m.origin_y_m = -10.0;
  m.occupancy.assign(160000U, p);
  std::string error;
  CHECK_TRUE_TEXT(sdpslam::io::write_map_pgm_yaml(dir + "/m", m, sdpslam::io::MapWriteOptions{}, &error), error.c_str());
  return dir + "/m.yaml";
}
}  // namespace

TEST(CliEvaluate, map_agreement_counts_the_returns_that_end_on_walls) {
  const std::string t = put("t.txt", "10.000000 0 0 0\n11.000000 1 0 0\n12.000000 2 0 0\n");
  const std::string json = dir + "/out.json";
  Run r = run_evaluate("--log " + log() + " --trajectory " + t + " --map " + uniform_map(dir, 1.0F) + " --json " + json);
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  STRCMP_CONTAINS("3 of 3 cast", r.out.c_str());
  STRCMP_CONTAINS("9 of 9 returns = 1.0000", r.out.c_str());
  const nlohmann::json agreement = json_of(json)["map_agreement"];
  LONGS_EQUAL(9, agreement["on_wall_count"].get<int>());
  DOUBLES_EQUAL(1.0, agreement["share"].get<double>(), 0.0);
  r = run_evaluate("--log " + log() + " --trajectory " + t + " --map " + uniform_map(dir, 0.0F));
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  STRCMP_CONTAINS("0 of 9 returns = 0.0000", r.out.c_str());
}

TEST(CliEvaluate, map_agreement_needs_a_trajectory_and_a_readable_map) {
  const std::string t = put("t.txt", "10.000000 0 0 0\n");
  Run r = run_evaluate("--log " + log() + " --map " + uniform_map(dir, 1.0F));
  LONGS_EQUAL_TEXT(2, r.status, r.out.c_str());
  STRCMP_CONTAINS("--map needs --log and --trajectory", r.out.c_str());
  r = run_evaluate("--log " + log() + " --trajectory " + t + " --map " + dir + "/none.yaml");
  LONGS_EQUAL_TEXT(3, r.status, r.out.c_str());
  STRCMP_CONTAINS("none.yaml: cannot open", r.out.c_str());
}

TEST(CliEvaluate, loop_constraints_are_checked_against_the_ground_truth) {
  const std::string gt = put("gt.txt", "1 0 0 0\n2 4 0 0\n3 4 4 1.5707963267948966\n4 0 4 3.141592653589793\n");
  // Frames at the robot's start poses: the true loop 1 -> 4 is the pose of 4 in 1; the
  // second says 3 m more along x (a corridor one door along).
  const std::string loops =
      put("l.tsv",
          "# older newer source used error_m z_x z_y z_theta older_stamp ... newer_stamp ...\n"
          "0 3 search 1 0.05 0 4 3.141592653589793 1.000000 0 0 0 4.000000 0 0 0\n"
          "0 3 icp 1 0.05 3 4 3.141592653589793 1.000000 0 0 0 4.000000 0 0 0\n"
          "1 2 icp 0 0.05 0 4 1.5707963267948966 2.000000 0 0 0 - 0 0 0\n");
  Run r = run_evaluate("--loops " + loops + " --ground-truth " + gt + " --json " + dir + "/out.json");
  LONGS_EQUAL_TEXT(0, r.status, r.out.c_str());
  STRCMP_CONTAINS(("3 in " + loops + ", 1 without a ground-truth origin").c_str(), r.out.c_str());
  STRCMP_CONTAINS("search      1: right 1, between 0, wrong 0", r.out.c_str());
  STRCMP_CONTAINS("icp         1: right 0, between 0, wrong 1, largest error 3.000 m", r.out.c_str());
  STRCMP_CONTAINS("used        2: right 1, between 0, wrong 1", r.out.c_str());
  // ... and the wrong one is named, so that a run can be looked into where it went wrong.
  STRCMP_CONTAINS("wrong       levels 0-3 (icp, used, stamps 1.0 s and 4.0 s): 3.000 m, 0.00 deg off", r.out.c_str());
  CHECK_TEXT(r.out.find("levels 0-3 (search") == std::string::npos, r.out.c_str());
  const nlohmann::json json = json_of(dir + "/out.json")["loops"];
  STRCMP_EQUAL(loops.c_str(), json["file"].get<std::string>().c_str());
  const nlohmann::json icp = json["icp"];
  LONGS_EQUAL(1, icp["count"].get<int>());
  LONGS_EQUAL(0, icp["right"].get<int>());
  LONGS_EQUAL(0, icp["between"].get<int>());
  LONGS_EQUAL(1, icp["wrong"].get<int>());
  DOUBLES_EQUAL(3.0, icp["max_m"].get<double>(), 1e-9);
  r = run_evaluate("--loops " + loops);
  LONGS_EQUAL_TEXT(2, r.status, r.out.c_str());
  STRCMP_CONTAINS("--loops needs --ground-truth", r.out.c_str());
  const std::string bad = put("bad.txt", "0 3 search 1 0.05 0 4\n");
  r = run_evaluate("--loops " + bad + " --ground-truth " + gt);
  LONGS_EQUAL_TEXT(3, r.status, r.out.c_str());
  STRCMP_CONTAINS((bad + ":1: expected").c_str(), r.out.c_str());
}
