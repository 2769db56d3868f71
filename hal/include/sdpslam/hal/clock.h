#pragma once
// Monotonic time source. Every time stamp that meets another inside the program (scan
// stamps, encoder stamps, timeouts) is on this one clock.
#include <cstdint>

namespace sdpslam::hal {

class MonotonicClock {
 public:
  virtual ~MonotonicClock() = default;
  // Microseconds since an arbitrary fixed origin; never decreases.
  virtual std::int64_t now_us() const = 0;
};

}  // namespace sdpslam::hal
