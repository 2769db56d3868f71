// sdpslamd's per-scan path: once created, the SDP engine's process() never touches the heap
// (the core's guarantee plus the engine's own records, reserved at create time), across
// segments; the localize engine's likewise; and the input recorder that hands each scan
// to them allocates nothing (and formats no text) while no recording is open.
#include <CppUTest/TestHarness.h>

#include <cmath>
#include <string>

#include "../localization/localizer_world.h"
#include "alloc_counter.h"
#include "sdpslam/daemon/input_recorder.h"
#include "sdpslam/daemon/slam_engine.h"
#include "sdpslam/io/map_image.h"
#include "shared_data.h"

using sdpslam::daemon::DaemonConfig;

namespace {

// A 10 m x 6 m box seen from (x, y) looking along +x: 181 beams over 180 degrees.
void box_scan(double x, double y, std::int64_t stamp_us, sdpslam::RangeScan* s) {
  s->stamp_us = stamp_us;
  s->beam_count = 181U;
  s->geometry.angle_min_rad = static_cast<float>(-M_PI / 2.0);
  s->geometry.angle_increment_rad = static_cast<float>(M_PI / 180.0);
  s->geometry.range_min_m = 0.05F;
  s->geometry.range_max_m = 30.0F;
  for (std::uint32_t i = 0; i < s->beam_count; ++i) {
    const double a = static_cast<double>(s->beam_angle_rad(i));
    const double c = std::cos(a), n = std::sin(a);
    double t = 1e9;
    if (c > 1e-9) t = std::fmin(t, (10.0 - x) / c);
    if (c < -1e-9) t = std::fmin(t, (0.0 - x) / c);
    if (n > 1e-9) t = std::fmin(t, (6.0 - y) / n);
    if (n < -1e-9) t = std::fmin(t, (0.0 - y) / n);
    s->ranges_m[i] = static_cast<float>(t);
  }
}

}  // namespace

TEST_GROUP(SdpEngineNoHeap){};

TEST(SdpEngineNoHeap, process_does_not_allocate_across_segmentations) {
  DaemonConfig c;
  c.mode = sdpslam::daemon::SlamMode::kSdp;
  c.slam.filter.particle_count = 5U;
  c.slam.filter.update_min_travel_m = 0.1;
  c.slam.filter.map_width_m = 30.0;
  c.slam.filter.map_height_m = 30.0;
  c.sdp.top_particles = 8U;
  c.sdp.period_scans = 5U;
  c.sdp.period_travel_m = 0.0;
  c.sdp.min_segment_scans = 3U;
  c.sdp.max_levels = 3U;
  c.sdp.map_tile_capacity = 2000U;
  c.sdp.map_observation_capacity = 300000U;
  c.max_trajectory_scans = 200U;
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
  const std::string status = engine->status_json();
  const std::size_t at = status.find("\"levels_made_permanent\": ");
  CHECK(at != std::string::npos);
  CHECK(std::stoul(status.substr(at + 25)) >= 1U);
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
  STRCMP_CONTAINS("\"converged_at_scan\": 0", engine->status_json().c_str());
}
