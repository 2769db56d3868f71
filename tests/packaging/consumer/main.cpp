// Uses the installed library through its public headers only: an Arena and pools, Pose2
// algebra, a DP-SLAM filter and the SDP-SLAM engine on small arenas, the Linux clock and
// a trajectory file.
// Prints one line per check; exit status 0 iff every check holds.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "sdpslam/core/arena.h"
#include "sdpslam/core/bottom/dpslam_filter.h"
#include "sdpslam/core/pool.h"
#include "sdpslam/core/pose2.h"
#include "sdpslam/core/sdp_slam.h"
#include "sdpslam/core/version.h"
#include "sdpslam/drivers/linux_clock.h"
#include "sdpslam/io/trajectory_io.h"

namespace {

int failures = 0;

void check(bool ok, const char* what) {
  std::printf("%s %s\n", ok ? "ok  " : "FAIL", what);
  std::fflush(stdout);
  if (!ok) ++failures;
}

struct Item {
  int value = 0;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: consumer SCRATCH_DIR\n");
    return 2;
  }
  check(std::strcmp(sdpslam::version_string(), SDPSLAM_PACKAGE_VERSION) == 0,
        "library version matches the CMake package version");

  // Arena + pool: capacity fixed at init, exhaustion is a null result and a counter.
  alignas(std::max_align_t) static unsigned char buffer[4096];
  sdpslam::Arena arena(buffer, sizeof buffer);
  sdpslam::ArenaPool<Item> pool;
  check(pool.init(arena, 4U), "ArenaPool carved from an Arena");
  Item* items[4] = {};
  for (auto*& it : items) it = pool.create();
  check(items[3] != nullptr && pool.full() && pool.create() == nullptr && pool.oom_count() == 1U,
        "a full pool refuses and counts");
  check(arena.allocate(1U << 20U, 8U) == nullptr && arena.oom_count() == 1U, "an exhausted arena refuses and counts");

  // Pose2: a quarter turn then one metre ahead lands at (0, 1); between() undoes compose().
  const sdpslam::Pose2 a{0.0, 0.0, std::acos(0.0)};
  const sdpslam::Pose2 b{1.0, 0.0, 0.0};
  const sdpslam::Pose2 ab = a.compose(b);
  check(std::fabs(ab.x_m) < 1e-12 && std::fabs(ab.y_m - 1.0) < 1e-12, "Pose2 composition");
  const sdpslam::Pose2 back = sdpslam::between(a, ab);
  check(std::fabs(back.x_m - 1.0) < 1e-12 && std::fabs(back.y_m) < 1e-12, "between() inverts compose()");

  // DP-SLAM filter on a small arena: sized by required_arena_bytes(), too small refused.
  sdpslam::DpSlamOptions o;
  o.particle_count = 4U;
  o.map_width_m = 8.0;
  o.map_height_m = 8.0;
  o.map_observations_base = 20000U;
  o.map_observations_per_particle = 2000U;
  // The arena buffers are declared first: they must outlive the filters carved from them.
  const std::size_t need = sdpslam::DpSlamFilter::required_arena_bytes(o);
  std::vector<unsigned char> small(need / 2U);
  std::vector<unsigned char> storage(need);
  sdpslam::Arena small_arena(small.data(), small.size());
  auto refused = std::make_unique<sdpslam::DpSlamFilter>();
  check(need > 0U && !refused->init(o, small_arena, 1U), "DpSlamFilter refuses a too-small arena");
  sdpslam::Arena filter_arena(storage.data(), storage.size());
  auto filter = std::make_unique<sdpslam::DpSlamFilter>();
  const bool init_ok = filter->init(o, filter_arena, 42U);
  if (!init_ok) std::printf("     why: %s\n", filter->why());
  check(init_ok && filter->initialised() && filter->particle_count() == 4U, "DpSlamFilter init on a small arena");

  // SDP-SLAM: the engine's API compiles from the installed headers alone (its parts'
  // headers are not installed), checks its options, refuses a too-small arena and runs.
  sdpslam::SdpOptions sdp;
  sdp.top_particles = 8U;
  sdp.max_levels = 4U;
  sdp.max_permanent_submaps = 8U;
  char why[200] = {};
  const bool sdp_ok = sdpslam::SdpSlam::check_options(o, sdp, why, sizeof why);
  if (!sdp_ok) std::printf("     why: %s\n", why);
  const std::size_t sdp_need = sdpslam::SdpSlam::required_arena_bytes(o, sdp);
  std::vector<unsigned char> sdp_small(sdp_need / 2U);
  std::vector<unsigned char> sdp_storage(sdp_need);
  sdpslam::Arena sdp_small_arena(sdp_small.data(), sdp_small.size());
  auto sdp_refused = std::make_unique<sdpslam::SdpSlam>();
  check(sdp_ok && sdp_need > 0U && !sdp_refused->init(o, sdp, sdp_small_arena, 1U) && sdp_refused->why()[0] != '\0',
        "SdpSlam checks its options and refuses a too-small arena");
  sdpslam::Arena sdp_arena(sdp_storage.data(), sdp_storage.size());
  auto slam = std::make_unique<sdpslam::SdpSlam>();
  const bool slam_ok = slam->init(o, sdp, sdp_arena, 7U);
  if (!slam_ok) std::printf("     why: %s\n", slam->why());
  // Two scans 0.5 m apart in a 4 m square room: the first is processed, the estimate stays
  // in the global frame's first segment.
  auto scan = std::make_unique<sdpslam::RangeScan>();
  scan->beam_count = 181U;
  scan->geometry.angle_min_rad = static_cast<float>(-std::acos(0.0));
  scan->geometry.angle_increment_rad = static_cast<float>(2.0 * std::acos(0.0) / 180.0);
  scan->geometry.range_max_m = 10.0F;
  std::uint64_t processed = 0U;
  for (int k = 0; slam_ok && k < 2; ++k) {
    const double x = 0.5 * k;
    scan->stamp_us = 1000000 * (k + 1);
    for (std::uint32_t i = 0; i < scan->beam_count; ++i) {
      const double angle = scan->beam_angle_rad(i);
      const double c = std::cos(angle);
      const double s = std::sin(angle);
      const double to_x = c > 1e-9 ? (2.0 - x) / c : 1e9;
      const double to_y = std::fabs(s) > 1e-9 ? 2.0 / std::fabs(s) : 1e9;
      scan->ranges_m[i] = static_cast<float>(to_x < to_y ? to_x : to_y);
    }
    sdpslam::OdometrySample odom;
    odom.stamp_us = scan->stamp_us;
    odom.pose = sdpslam::Pose2{x, 0.0, 0.0};
    if (slam->process(odom, *scan).bottom.status == sdpslam::StepResult::Status::kProcessed) ++processed;
  }
  check(slam_ok && processed >= 1U && slam->stats().segments == 0U && slam->state_bytes() > 0U,
        "SdpSlam init and process on a small arena");

  // Drivers: the monotonic clock moves forward.
  sdpslam::drivers::LinuxMonotonicClock clock;
  const std::int64_t t0 = clock.now_us();
  const std::int64_t t1 = clock.now_us();
  check(t0 > 0 && t1 >= t0, "LinuxMonotonicClock");

  // io: a trajectory written atomically reads back.
  const std::string path = std::string(argv[1]) + "/trajectory.txt";
  std::vector<sdpslam::io::StampedPose> poses(2);
  poses[1].stamp_us = 1500000;
  poses[1].pose = ab;
  std::string error;
  std::vector<sdpslam::io::StampedPose> read;
  const bool io_ok = sdpslam::io::write_trajectory(path, poses, &error) &&
                     sdpslam::io::read_trajectory(path, &read, &error);
  if (!io_ok) std::printf("     error: %s\n", error.c_str());
  check(io_ok && read.size() == 2U && read[1].stamp_us == 1500000, "trajectory file round trip");

  std::printf("consumer: sdpslam %s, %d failure(s)\n", sdpslam::version_string(), failures);
  return failures == 0 ? 0 : 1;
}
