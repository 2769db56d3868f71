// sdpslamd's per-scan path: once created, the SDP engine's process() never touches the heap
// (the core's guarantee plus the engine's own records, reserved at create time), across
// segments; the localize engine's likewise; and the input recorder that hands each scan
// to them allocates nothing (and formats no text) while no recording is open.
#include <CppUTest/TestHarness.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "../localization/localizer_world.h"
#include "alloc_counter.h"
#include "box_world.h"
#include "sdpslam/daemon/daemon.h"
#include "sdpslam/daemon/input_recorder.h"
#include "sdpslam/daemon/slam_engine.h"
#include "sdpslam/io/map_image.h"
#include "shared_data.h"
#include "yaml_statics.h"  // localize mode reads a map YAML

using sdpslam::daemon::DaemonConfig;

using sdpslam::test::box_scan;

TEST_GROUP(SdpEngineNoHeap){};

TEST(SdpEngineNoHeap, process_does_not_allocate_across_segmentations) {
  const DaemonConfig c = sdpslam::test::small_sdp_config();
  std::string error;
  auto engine = sdpslam::daemon::make_engine(c, &error);
  CHECK_TRUE_TEXT(engine != nullptr, error.c_str());
  static sdpslam::RangeScan scan;
  std::size_t allocations = 0U;
  std::uint32_t processed = 0U;
  for (int k = 0; k < 120; ++k) {
    const double x = 2.0 + 0.05 * k;
    box_scan(x, 3.0, 1000000 + 100000LL * k, &scan);
    const sdpslam::OdometrySample odom{scan.stamp_us, sdpslam::Pose2{x - 2.0, 0.0, 0.0}};
    sdpslam::test::AllocationScope scope;
    const sdpslam::daemon::EngineStep step = engine->process(odom, scan);
    allocations += scope.allocations();
    if (step.processed) ++processed;
  }
  LONGS_EQUAL(0, allocations);
  CHECK(processed >= 30U);
  // Several segments ended (so the no-heap claim covers anchorage and the top level).
  CHECK(engine->status_json().at("levels_made_permanent").get<std::uint64_t>() >= 1U);
  LONGS_EQUAL(120, static_cast<long>(engine->trajectory().size()));
}

// A resumed session: the first scan after the restart is checked against the saved map
// (a start-up step that allocates); from then on process() allocates nothing, the
// odometry and stamps still carried across the break.
TEST(SdpEngineNoHeap, a_resumed_engine_allocates_nothing_once_its_place_is_checked) {
  DaemonConfig c = sdpslam::test::small_sdp_config();
  c.output_directory = sdpslam::test::make_temp_dir("sdp_engine_no_heap_resume");
  c.snapshot_interval_us = 1000000;
  std::string error;
  static sdpslam::RangeScan scan;
  auto feed = [](sdpslam::daemon::SlamEngine& e, int k, double odom_origin_x) {
    const double x = 2.0 + 0.05 * k;
    box_scan(x, 3.0, 1000000 + 100000LL * k, &scan);
    return e.process(sdpslam::OdometrySample{scan.stamp_us, sdpslam::Pose2{x - odom_origin_x, 0.0, 0.0}}, scan);
  };
  {
    auto first = sdpslam::daemon::make_engine(c, &error);
    CHECK_TRUE_TEXT(first != nullptr, error.c_str());
    for (int k = 0; k < 60; ++k) feed(*first, k, 2.0);
    std::uint64_t bytes = 0U;
    CHECK_TRUE_TEXT(first->save_snapshot(sdpslam::daemon::snapshot_path(c), 0U, &bytes, &error), error.c_str());
  }
  auto engine = sdpslam::daemon::make_engine(c, &error);
  CHECK_TRUE_TEXT(engine != nullptr, error.c_str());
  std::uint64_t scans = 0U;
  CHECK_TRUE_TEXT(engine->resume_snapshot(sdpslam::daemon::snapshot_path(c), 0U, &scans, &error), error.c_str());
  LONGS_EQUAL(60, static_cast<long>(scans));
  CHECK_TRUE(feed(*engine, 60, 4.95).placed);  // the encoders count from zero again
  std::size_t allocations = 0U;
  for (int k = 61; k < 120; ++k) {
    sdpslam::test::AllocationScope scope;
    const sdpslam::daemon::EngineStep step = feed(*engine, k, 4.95);
    allocations += scope.allocations();
    CHECK_TRUE(step.placed);
  }
  LONGS_EQUAL(0, allocations);
  STRCMP_EQUAL("in place", engine->status_json()["resumed"]["place"].get<std::string>().c_str());
  LONGS_EQUAL(120, static_cast<long>(engine->trajectory().size()));
}

TEST(SdpEngineNoHeap, the_input_recorder_allocates_nothing_while_not_recording) {
  sdpslam::daemon::InputRecorder recorder;
  static sdpslam::RangeScan scan;
  static sdpslam::RangeScan fed;
  scan.geometry.laser_in_base = sdpslam::Pose2{0.145, 0.0123, 0.1};  // a ROBOTLASER1 line
  std::size_t allocations = 0U;
  for (int k = 0; k < 50; ++k) {
    box_scan(2.0 + 0.05 * k, 3.0, 1000000 + 100000LL * k, &scan);
    scan.ranges_m[k] = k % 2 == 0 ? NAN : INFINITY;
    const sdpslam::OdometrySample odom{scan.stamp_us, sdpslam::Pose2{0.05 * k, 0.0, 0.01 * k}};
    sdpslam::OdometrySample fed_odom;
    sdpslam::test::AllocationScope scope;
    recorder.pass(odom, scan, scan.stamp_us + 5, &fed_odom, &fed);
    allocations += scope.allocations();
    LONGS_EQUAL(scan.stamp_us, fed.stamp_us);
  }
  LONGS_EQUAL(0, allocations);
  LONGS_EQUAL(50, recorder.stats().scans);
  LONGS_EQUAL(50, recorder.stats().changed_count);  // range_min, the NaN / inf beams, the mounting
  LONGS_EQUAL(0, recorder.stats().roundtrip_failures);
}

// [slam] mode = localize: the engine localizes on a saved map, follows the robot, and its
// process() allocates nothing once the engine is made (the trajectory record reserved).
TEST(SdpEngineNoHeap, the_localize_engine_follows_the_robot_without_allocating) {
  const sdpslam::test::LocalizerWorld world;
  sdpslam::io::OccupancyImage image;
  image.width = world.kWidth;
  image.height = world.kHeight;
  image.resolution_m = world.kRes;
  for (const std::uint8_t cell : world.cells) {
    image.occupancy.push_back(cell == sdpslam::LocalizerMap::kOccupied ? 1.0F : 0.0F);
  }
  const std::string dir = sdpslam::test::make_temp_dir("localize_engine");
  std::string error;
  CHECK_TRUE_TEXT(sdpslam::io::write_map_pgm_yaml(dir + "/world", image, sdpslam::io::MapWriteOptions{}, &error),
                  error.c_str());
  DaemonConfig c;
  c.mode = sdpslam::daemon::SlamMode::kLocalize;
  c.localize_map = dir + "/world.yaml";
  const std::vector<sdpslam::Pose2> route = sdpslam::test::localizer_route();
  c.localize_have_start = true;
  c.localize_start = route[0];
  c.max_trajectory_scans = static_cast<std::uint32_t>(route.size());
  auto engine = sdpslam::daemon::make_engine(c, &error);
  CHECK_TRUE_TEXT(engine != nullptr, error.c_str());
  STRCMP_EQUAL("localize", engine->name());
  static sdpslam::RangeScan scan;
  std::size_t allocations = 0U;
  double worst_m = 0.0;
  for (std::size_t k = 0; k < route.size(); ++k) {
    world.scan(route[k], static_cast<std::int64_t>(k) * 100000, &scan);
    const sdpslam::OdometrySample odom{scan.stamp_us, route[k]};
    sdpslam::test::AllocationScope scope;
    const sdpslam::daemon::EngineStep step = engine->process(odom, scan);
    allocations += scope.allocations();
    worst_m = std::fmax(worst_m, std::hypot(step.pose.x_m - route[k].x_m, step.pose.y_m - route[k].y_m));
  }
  LONGS_EQUAL(0, allocations);
  CHECK_TEXT(worst_m < 0.25, std::to_string(worst_m).c_str());
  LONGS_EQUAL(route.size(), engine->trajectory().size());
  sdpslam::io::OccupancyImage out;
  CHECK(engine->map_image(&out) > 0U);
  LONGS_EQUAL(world.kWidth, out.width);  // the saved map, unchanged
  LONGS_EQUAL(0, engine->status_json().at("converged_at_scan").get<long>());
}

namespace {

// Sensors and an engine that keep nothing on the heap, so that what is counted below is
// the daemon's own per-scan path: odometry integration, the scan queue, placement by
// interpolation, the input recorder, the engine call and the latency figures.
struct QuietClock final : sdpslam::hal::MonotonicClock {
  std::int64_t now_us() const override { return t; }
  std::int64_t t = 1000000;
};
struct QuietEncoders final : sdpslam::hal::WheelEncoderSource {
  int update() override { return 0; }
  sdpslam::hal::WheelEncoderSample latest() const override { return s; }
  void sample(std::uint32_t ticks, std::int64_t stamp_us) {
    for (sdpslam::hal::WheelTicks* w : {&s.left, &s.right}) {
      w->raw_count = ticks;
      w->stamp_us = stamp_us;
      ++w->sequence;
      w->has_sample = true;
      w->stale = false;
    }
  }
  sdpslam::hal::WheelEncoderSample s;
};
struct QuietLaser final : sdpslam::hal::RangeScanSource {
  int poll(sdpslam::RangeScan& out, std::int64_t) override {
    if (!ready) return 0;
    out = scan;
    ready = false;
    ++st.scan_count;
    return 1;
  }
  sdpslam::hal::RangeSourceHealth health() const override { return sdpslam::hal::RangeSourceHealth::kStreaming; }
  const sdpslam::hal::RangeSourceStats& stats() const override { return st; }
  sdpslam::RangeScan scan;
  bool ready = false;
  sdpslam::hal::RangeSourceStats st;
};
struct CountingEngine final : sdpslam::daemon::SlamEngine {
  const char* name() const override { return "counting"; }
  sdpslam::daemon::EngineStep process(const sdpslam::OdometrySample& odom, const sdpslam::RangeScan&) override {
    ++processed;
    return sdpslam::daemon::EngineStep{true, odom.pose};
  }
  std::vector<sdpslam::io::StampedPose> trajectory() const override { return {}; }
  std::uint32_t map_image(sdpslam::io::OccupancyImage*) const override { return 0U; }
  sdpslam::io::Json status_json() const override { return {{"counting", true}}; }
  std::uint64_t unrecorded_scans() const override { return 0U; }
  std::uint64_t processed = 0U;
};

}  // namespace

// The robot's per-scan path, end to end in the loop: with no recording open and between
// output periods, placing and processing scans allocates nothing.
TEST(SdpEngineNoHeap, the_daemon_loop_places_and_processes_scans_without_allocating) {
  QuietClock clock;
  QuietEncoders encoders;
  QuietLaser laser;
  CountingEngine engine;
  static char log_buffer[4096];
  std::FILE* log_file = std::tmpfile();
  std::setvbuf(log_file, log_buffer, _IOFBF, sizeof log_buffer);  // the log's buffer is not the heap's
  sdpslam::daemon::EventLog log(clock, 0, log_file);
  DaemonConfig config;
  config.output_directory = sdpslam::test::make_temp_dir("daemon_no_heap");
  config.output_period_us = 3600000000LL;  // no output step inside the measurement
  config.write_map = false;
  config.loop_slice_us = 100;
  sdpslam::daemon::DaemonIo io;
  io.clock = &clock;
  io.encoders = &encoders;
  io.laser = &laser;
  io.engine = &engine;
  auto daemon = std::make_unique<sdpslam::daemon::Daemon>(config, io, log);
  std::string error;
  CHECK_TRUE_TEXT(daemon->start(&error), error.c_str());
  laser.scan.beam_count = 181U;
  laser.scan.geometry.angle_min_rad = static_cast<float>(-M_PI / 2.0);
  laser.scan.geometry.angle_increment_rad = static_cast<float>(M_PI / 180.0);
  laser.scan.geometry.range_max_m = 30.0F;
  for (std::uint32_t i = 0; i < 181U; ++i) laser.scan.ranges_m[i] = 2.0F + 0.01F * static_cast<float>(i);
  std::size_t allocations = 0U;
  std::uint64_t measured_from = 0U;
  for (int k = 0; k < 400; ++k) {
    // Odometry every 50 ms, a scan between every other pair of samples.
    const std::int64_t t = 1000000 + 50000LL * k;
    clock.t = t;
    encoders.sample(static_cast<std::uint32_t>(100 * k), t);
    if (k % 2 == 1) {
      laser.scan.stamp_us = t - 25000;
      laser.ready = true;
    }
    if (k == 40) measured_from = engine.processed;  // past the start-up (first log lines, latching)
    sdpslam::test::AllocationScope scope;
    daemon->step();
    if (k >= 40) allocations += scope.allocations();
  }
  LONGS_EQUAL(0, allocations);
  CHECK(engine.processed - measured_from > 150U);  // scans were placed and processed meanwhile
  std::fclose(log_file);
}
