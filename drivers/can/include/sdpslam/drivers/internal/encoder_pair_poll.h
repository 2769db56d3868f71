#pragma once
// The update() of the encoder pair handlers (CANopen, ODrive; not public API: internal/):
// the one loop that reads the bus, hands each frame to the handler's protocol, lets the
// handler transmit what its schedule asks for (SYNC, RTR requests), and judges each
// wheel's freshness.
#include <cstdint>

#include "sdpslam/drivers/internal/wheel_tracker.h"
#include "sdpslam/hal/can_bus.h"
#include "sdpslam/hal/clock.h"
#include "sdpslam/hal/wheel_encoder_source.h"

namespace sdpslam::drivers::internal {

// Reads up to options.max_frames_per_update frames. A receive error is counted
// (stats.rx_errors) and reading goes on, unless the bus is down (then -1 after the rest
// of the work). handle(frame, now_us) decodes a frame into `wheels` and `stats`;
// transmit(now_us) runs once after the reads. Each wheel is then judged at the handler's
// clock, or, when the newest frame read was received more than position_timeout_us
// before (a backlog), at that frame's stamp (WheelTracker::evaluate_at_stamp); a
// heartbeat lost just now is counted (stats.heartbeat_timeouts).
// Returns the positions decoded (stats.positions[0] + [1] grew by that much), or -1.
template <class Options, class Stats, class Handle, class Transmit>
int poll_encoder_pair(hal::CanBus& bus, const hal::MonotonicClock& clock, const Options& options,
                      std::int64_t supervision_start_us, WheelTracker (&wheels)[2], Stats& stats, Handle&& handle,
                      Transmit&& transmit) {
  int new_samples = 0;
  int result = 0;
  std::int64_t newest_frame_stamp_us = 0;
  for (int i = 0; i < options.max_frames_per_update; ++i) {
    hal::CanFrame f;
    const int r = bus.receive(f);
    if (r == 0) break;
    if (r < 0) {
      stats.rx_errors++;
      if (bus.state() == hal::CanBusState::kDown) {
        result = -1;
        break;
      }
      continue;  // e.g. one bad datagram: keep reading
    }
    const auto before = stats.positions[0] + stats.positions[1];
    if (f.stamp_us > newest_frame_stamp_us) newest_frame_stamp_us = f.stamp_us;
    handle(f, clock.now_us());
    new_samples += static_cast<int>(stats.positions[0] + stats.positions[1] - before);
  }
  const std::int64_t now = clock.now_us();
  transmit(now);
  // Frames received long before this read (a backlog) are judged at their own stamps.
  const bool backlog = newest_frame_stamp_us > 0 && now - newest_frame_stamp_us > options.position_timeout_us;
  for (WheelTracker& w : wheels) {
    if (backlog) {
      w.evaluate_at_stamp(newest_frame_stamp_us, options.position_timeout_us);
    } else if (w.evaluate(now, options.position_timeout_us, options.heartbeat_timeout_us, supervision_start_us)) {
      stats.heartbeat_timeouts++;
    }
  }
  return result < 0 ? result : new_samples;
}

// Both wheels' latest ticks (left, right).
inline hal::WheelEncoderSample pair_sample(const WheelTracker (&wheels)[2]) {
  hal::WheelEncoderSample s;
  s.left = wheels[0].ticks;
  s.right = wheels[1].ticks;
  return s;
}

}  // namespace sdpslam::drivers::internal
