#pragma once
// Freshness bookkeeping shared by the encoder pair handlers (not public API: internal/).
#include <cstdint>

#include "sdpslam/hal/wheel_encoder_source.h"

namespace sdpslam::drivers::internal {

struct WheelTracker {
  hal::WheelTicks ticks;
  std::int64_t last_position_rx_us = 0;   // handler clock, for the timeout
  std::int64_t last_heartbeat_rx_us = 0;  // handler clock
  bool heartbeat_seen = false;
  bool heartbeat_lost = false;
  bool node_ok = true;  // last heartbeat reported a usable state

  void on_position(std::uint32_t raw, std::uint8_t bits, std::int64_t frame_stamp_us,
                   std::int64_t now_us) {
    ticks.raw_count = raw;
    ticks.counter_bits = bits;
    ticks.stamp_us = frame_stamp_us != 0 ? frame_stamp_us : now_us;
    ticks.sequence++;
    ticks.has_sample = true;
    last_position_rx_us = now_us;
  }
  void on_heartbeat(bool usable, std::int64_t now_us) {
    heartbeat_seen = true;
    heartbeat_lost = false;
    node_ok = usable;
    last_heartbeat_rx_us = now_us;
  }
  // Re-evaluates staleness at `now_us`. Returns true iff the heartbeat was lost just now.
  bool evaluate(std::int64_t now_us, std::int64_t position_timeout_us,
                std::int64_t heartbeat_timeout_us, std::int64_t supervision_start_us) {
    bool newly_lost = false;
    if (heartbeat_timeout_us > 0 && !heartbeat_lost) {
      const std::int64_t ref = heartbeat_seen ? last_heartbeat_rx_us : supervision_start_us;
      if (now_us - ref > heartbeat_timeout_us) {
        heartbeat_lost = true;
        newly_lost = true;
      }
    }
    const bool position_late =
        !ticks.has_sample || now_us - last_position_rx_us > position_timeout_us;
    ticks.stale = position_late || heartbeat_lost || !node_ok;
    return newly_lost;
  }

  // Staleness while draining a backlog: the frames handled were received (kernel stamp)
  // long before they were read, e.g. while the host was busy. Freshness is then judged
  // as of the newest frame's receive stamp, so that reading a backlog frame by frame
  // does not make the wheel whose frame comes next look stale. Heartbeat loss is not
  // decided from a backlog.
  void evaluate_at_stamp(std::int64_t newest_frame_stamp_us, std::int64_t position_timeout_us) {
    const bool position_late =
        !ticks.has_sample || newest_frame_stamp_us - ticks.stamp_us > position_timeout_us;
    ticks.stale = position_late || heartbeat_lost || !node_ok;
  }
};

}  // namespace sdpslam::drivers::internal
