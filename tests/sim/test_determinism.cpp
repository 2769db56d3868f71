// Same seed → byte-identical outputs; different seeds differ; the files read back.
#include <CppUTest/TestHarness.h>

#include <string>

#include "sdpslam/io/log_reader.h"
#include "sdpslam/io/trajectory_io.h"
#include "sdpslam/sim/rng.h"
#include "sdpslam/sim/sim_output.h"
#include "shared_data.h"
#include "sim_test_util.h"

using namespace sdpslam;
using namespace sdpslam::sim;
using sdpslam::test::RecordingSink;

namespace {
std::uint64_t run_hash(std::uint64_t seed, double max_duration_s) {
  SimulationOptions o;
  o.seed = seed;
  o.max_duration_s = max_duration_s;
  RecordingSink sink;
  SimulationSummary s;
  std::string error;
  CHECK_TRUE(run_simulation(builtin_world(), builtin_route(), o, &sink, &s, &error));
  return sink.hash;
}

SimulationOutputs write_run(const std::string& dir, std::uint64_t seed) {
  SimulationOptions o;
  o.seed = seed;
  o.max_duration_s = 40.0;  // 20 m of the route: enough to compare, quick in Debug
  SimulationOutputs out;
  std::string error;
  const OutputStatus st = simulate_to_directory(builtin_world(), "builtin", builtin_route(), o, 0.05, dir, &out, &error);
  CHECK_TRUE_TEXT(st == OutputStatus::kOk, error.c_str());
  return out;
}
}  // namespace

TEST_GROUP(SimDeterminism){};

TEST(SimDeterminism, rng_streams_of_one_seed_differ_and_repeat) {
  sim::Rng a(42, 1), b(42, 1), c(42, 2), d(43, 1);
  const std::uint64_t va = a.next_u64();
  CHECK_EQUAL(va, b.next_u64());
  CHECK(va != c.next_u64());
  CHECK(va != d.next_u64());
}

TEST(SimDeterminism, rng_uniform_is_in_the_unit_interval_and_gaussian_has_unit_spread) {
  sim::Rng r(9);
  double sum = 0.0, sum2 = 0.0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const double u = r.uniform();
    CHECK(u >= 0.0 && u < 1.0);
    const double g = r.gaussian();
    sum += g;
    sum2 += g * g;
  }
  DOUBLES_EQUAL(0.0, sum / n, 0.01);
  DOUBLES_EQUAL(1.0, sum2 / n, 0.02);
}

TEST(SimDeterminism, same_seed_gives_identical_records) {
  CHECK_EQUAL(run_hash(7, 30.0), run_hash(7, 30.0));
}

TEST(SimDeterminism, different_seeds_give_different_records) {
  CHECK(run_hash(7, 30.0) != run_hash(8, 30.0));
}

TEST(SimDeterminism, same_seed_writes_byte_identical_files) {
  const std::string d1 = test::make_temp_dir("sim-a");
  const std::string d2 = test::make_temp_dir("sim-b");
  write_run(d1, 11);
  write_run(d2, 11);
  for (const char* f : {"/sim.clf", "/ground_truth.txt", "/odometry.txt", "/world.txt", "/world.pgm", "/world.yaml",
                        "/world.png"}) {
    const std::string a = test::read_file_bytes(d1 + f);
    CHECK_TEXT(!a.empty(), f);
    CHECK_TEXT(a == test::read_file_bytes(d2 + f), f);
  }
}

TEST(SimDeterminism, different_seed_writes_a_different_log) {
  const std::string d1 = test::make_temp_dir("sim-c");
  const std::string d2 = test::make_temp_dir("sim-d");
  write_run(d1, 11);
  write_run(d2, 12);
  CHECK(test::read_file_bytes(d1 + "/sim.clf") != test::read_file_bytes(d2 + "/sim.clf"));
  CHECK(test::read_file_bytes(d1 + "/world.txt") == test::read_file_bytes(d2 + "/world.txt"));
}

TEST(SimDeterminism, written_log_reads_back_with_ground_truth_at_every_scan_stamp) {
  const std::string dir = test::make_temp_dir("sim-e");
  const SimulationOutputs out = write_run(dir, 3);
  io::LogContents log;
  std::string error;
  CHECK_TRUE_TEXT(io::read_whole_log(dir + "/sim.clf", io::LogReaderOptions{}, &log, &error), error.c_str());
  LONGS_EQUAL(0, log.error_count);
  LONGS_EQUAL(out.summary.scan_count, log.lasers.size());
  LONGS_EQUAL(out.summary.odom_count, log.odoms.size());
  CHECK(log.params.size() >= 10U);
  std::vector<io::StampedPose> gt;
  CHECK_TRUE_TEXT(io::read_trajectory(dir + "/ground_truth.txt", &gt, &error), error.c_str());
  LONGS_EQUAL(log.lasers.size(), gt.size());
  for (std::size_t i = 0; i < gt.size(); ++i) {
    CHECK_EQUAL(log.lasers[i].stamp_us, gt[i].stamp_us);
    DOUBLES_EQUAL(out.ground_truth[i].pose.x_m, gt[i].pose.x_m, 1e-6);
  }
  // Max-range readings survive the round trip as "no return".
  const RangeScan& scan = log.lasers.front().scan;
  LONGS_EQUAL(181, scan.beam_count);
  DOUBLES_EQUAL(8.0, scan.geometry.range_max_m, 1e-6);
}

TEST(SimDeterminism, invalid_options_write_nothing_and_say_why) {
  const std::string dir = test::make_temp_dir("sim-f");
  SimulationOptions o;
  o.robot.max_speed_mps = -1.0;
  SimulationOutputs out;
  std::string error;
  CHECK(simulate_to_directory(builtin_world(), "builtin", builtin_route(), o, 0.05, dir, &out, &error) ==
        OutputStatus::kBadOptions);
  STRCMP_EQUAL("invalid simulation option: speed must be > 0 m/s", error.c_str());
  CHECK(test::read_file_bytes(dir + "/sim.clf").empty());
}

TEST(SimDeterminism, unwritable_directory_is_an_io_error) {
  SimulationOutputs out;
  std::string error;
  CHECK(simulate_to_directory(builtin_world(), "builtin", builtin_route(), SimulationOptions{}, 0.05,
                              "/proc/sdpslam-cannot-exist", &out, &error) == OutputStatus::kIoError);
  CHECK(!error.empty());
}
