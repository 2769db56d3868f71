#pragma once
// Real-time player for hardware-in-the-loop replay: CAN frames of a candump log onto a
// hal::CanBus (SocketCAN in use, a socketpair in tests) and a LaserEngine on its
// pseudo-terminal, both scheduled on ONE monotonic clock through one ReplayTimeline, so
// encoder frames and scans keep their recorded alignment at any speed.
//
// Sending: a frame goes out when its time has come. "Try later" from the bus (ENOBUFS /
// EAGAIN) is retried every retry_interval_us, never dropped silently: the frame is only
// given up after give_up_us of failures and then counted in frames_dropped, as are
// frames the bus refuses with an error for that long. A frame sent more than
// late_threshold_us after its time counts in frames_late.
#include <cstdint>
#include <vector>

#include "sdpslam/drivers/candump_log.h"
#include "sdpslam/hal/can_bus.h"
#include "sdpslam/hal/clock.h"
#include "sdpslam/replay/laser_emulator.h"

namespace sdpslam::replay {

struct PlayerOptions {
  std::int64_t late_threshold_us = 5000;
  std::int64_t retry_interval_us = 200;
  std::int64_t give_up_us = 1000000;
  // Extra time after the last event before run() returns (lets the laser's last reply
  // drain).
  std::int64_t tail_us = 50000;
};

struct PlayerStats {
  std::uint64_t frames_sent = 0;
  std::uint64_t frames_late = 0;
  std::uint64_t frames_dropped = 0;
  std::uint64_t send_try_later = 0;  // ENOBUFS / EAGAIN retries
  std::uint64_t send_errors = 0;     // send() < 0 (retried until give_up_us)
  std::int64_t max_frame_lateness_us = 0;
  std::int64_t wall_us = 0;          // run() duration
};

class Player {
 public:
  // `bus`/`frames` may be null (laser only); `laser`/`pty` may be null (CAN only). The
  // timeline's play_start_us is set by run() to the clock at start + start_delay_us.
  Player(const hal::MonotonicClock& clock, const PlayerOptions& options);
  void set_can(hal::CanBus* bus, const std::vector<drivers::CandumpRecord>* frames);
  void set_laser(LaserEngine* engine, LaserPty* pty);
  // Plays everything; returns when all frames are sent or dropped and the laser engine is
  // done. log_start_us: the log time mapped to the start (normally the earliest stamp of
  // frames and scans).
  void run(std::int64_t log_start_us, double speed, std::int64_t start_delay_us = 0);
  const PlayerStats& stats() const { return stats_; }
  const ReplayTimeline& timeline() const { return timeline_; }

 private:
  const hal::MonotonicClock& clock_;
  PlayerOptions options_;
  hal::CanBus* bus_ = nullptr;
  const std::vector<drivers::CandumpRecord>* frames_ = nullptr;
  LaserEngine* engine_ = nullptr;
  LaserPty* pty_ = nullptr;
  ReplayTimeline timeline_;
  PlayerStats stats_;
};

}  // namespace sdpslam::replay
