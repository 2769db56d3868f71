#pragma once
// One line per event on stderr (the journal under systemd), rate-limited per kind: a kind
// logs at most once per interval; what was held back is counted and reported with the
// next line of that kind ("(+N similar)"). Every event is counted whether printed or not.
#include <cstdarg>
#include <cstdint>
#include <cstdio>

#include "sdpslam/hal/clock.h"

namespace sdpslam::daemon {

enum class Event : std::uint8_t {
  kStartup,
  kSession,        // where a resumed session found the robot
  kLaser,          // laser health changes, disconnects, restarts
  kLaserData,      // scans rejected by the laser driver (checksum, framing)
  kCan,            // CAN bus state changes, down / re-open
  kCanData,        // frames lost (kernel overflow), bad candump lines
  kOdometry,       // encoders stale / back
  kScanSkipped,    // scans without odometry, outside the ring, across a gap
  kScanDropped,    // scans dropped because the queue was full
  kOutput,         // output write failures
  kShutdown,
  kCount
};
const char* to_string(Event e);

class EventLog {
 public:
  EventLog(const hal::MonotonicClock& clock, std::int64_t interval_us, std::FILE* out = stderr)
      : clock_(clock), interval_us_(interval_us), out_(out) {}
  __attribute__((format(printf, 3, 4))) void log(Event e, const char* fmt, ...);
  std::uint64_t count(Event e) const { return count_[static_cast<int>(e)]; }
  std::uint64_t printed() const { return printed_; }
  std::uint64_t suppressed() const { return suppressed_total_; }

 private:
  const hal::MonotonicClock& clock_;
  std::int64_t interval_us_;
  std::FILE* out_;
  std::int64_t last_us_[static_cast<int>(Event::kCount)] = {};
  bool ever_[static_cast<int>(Event::kCount)] = {};
  std::uint64_t held_[static_cast<int>(Event::kCount)] = {};
  std::uint64_t count_[static_cast<int>(Event::kCount)] = {};
  std::uint64_t printed_ = 0U;
  std::uint64_t suppressed_total_ = 0U;
};

}  // namespace sdpslam::daemon
