#include "sdpslam/drivers/linux_clock.h"

#include <time.h>

namespace sdpslam::drivers {
namespace {
std::int64_t read_us(clockid_t id) {
  timespec ts{};
  ::clock_gettime(id, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000 + ts.tv_nsec / 1000;
}
}  // namespace

std::int64_t LinuxMonotonicClock::now_us() const { return read_us(CLOCK_MONOTONIC); }

std::int64_t realtime_now_us() { return read_us(CLOCK_REALTIME); }

std::int64_t realtime_to_monotonic_us(std::int64_t realtime_us) {
  const std::int64_t mono = read_us(CLOCK_MONOTONIC);
  const std::int64_t real = read_us(CLOCK_REALTIME);
  return realtime_us - real + mono;
}

}  // namespace sdpslam::drivers
