#pragma once
// CLOCK_MONOTONIC as a hal::MonotonicClock; the conversion of a CLOCK_REALTIME stamp
// (as SO_TIMESTAMP delivers) onto it.
#include <cstdint>

#include "sdpslam/hal/clock.h"

namespace sdpslam::drivers {

class LinuxMonotonicClock final : public hal::MonotonicClock {
 public:
  std::int64_t now_us() const override;
};

// Microseconds of CLOCK_REALTIME now.
std::int64_t realtime_now_us();

// Maps a CLOCK_REALTIME stamp onto CLOCK_MONOTONIC using the current offset between the
// two clocks (valid for stamps taken moments ago, e.g. kernel receive stamps).
std::int64_t realtime_to_monotonic_us(std::int64_t realtime_us);

}  // namespace sdpslam::drivers
