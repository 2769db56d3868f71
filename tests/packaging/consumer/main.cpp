// Uses the installed library through its public headers only: an Arena and pools, Pose2
// algebra, a DP-SLAM filter on a small arena, the Linux clock and a trajectory file.
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
