#pragma once
// Two CANopen CiA 406 encoders (left and right wheel) as a hal::WheelEncoderSource.
//
// Protocol (protocols.md §3, CiA 301): start() sends NMT "start remote node" to each node;
// with sync_period_us > 0 the handler is the SYNC producer (080#, DLC 0) and the encoders,
// configured with TPDO1 transmission type 1, answer every SYNC with TPDO1 = position
// (object 0x6004, u32 or a 16-bit counter, little-endian), so both wheels are sampled
// together. Heartbeats (0x700+node) are supervised: none within heartbeat_timeout_us makes
// the wheel stale (counted once per loss); a heartbeat in a state other than operational
// makes it stale too, and a boot-up message (node restarted) is answered with NMT start.
// EMCY frames are decoded and counted, the newest kept. Frames of other objects or nodes
// are counted as unexpected and otherwise ignored; frames for our nodes that fail to
// decode (wrong DLC, unknown state) are counted as decode errors. Nothing is fatal.
//
// A wheel is stale when no position arrived within position_timeout_us (handler clock).
// Memory: fixed. update() handles at most max_frames_per_update frames per call.
#include <cstdint>

#include "sdpslam/drivers/canopen_codec.h"
#include "sdpslam/hal/can_bus.h"
#include "sdpslam/hal/clock.h"
#include "sdpslam/hal/wheel_encoder_source.h"
#include "sdpslam/drivers/internal/wheel_tracker.h"

namespace sdpslam::drivers {

struct CanOpenEncoderOptions {
  std::uint8_t left_node = 5;
  std::uint8_t right_node = 6;
  std::uint8_t position_bytes = 4;          // 4: u32 counter; 2: 16-bit counter
  bool send_nmt_start = true;
  std::int64_t sync_period_us = 0;          // 0: do not produce SYNC
  std::int64_t position_timeout_us = 100000;
  std::int64_t heartbeat_timeout_us = 0;    // 0: no heartbeat supervision
  int max_frames_per_update = 64;
};

enum class CanOpenOptionsError : std::uint8_t { kOk, kNode, kSameNode, kPositionBytes, kTimeout };
CanOpenOptionsError validate(const CanOpenEncoderOptions& o);

struct CanOpenEncoderStats {
  std::uint64_t frames = 0;
  std::uint64_t positions[2] = {0, 0};  // by hal::WheelSide
  std::uint64_t unexpected_frames = 0;
  std::uint64_t decode_errors = 0;
  std::uint64_t heartbeats = 0;
  std::uint32_t heartbeat_timeouts = 0;
  std::uint32_t not_operational = 0;   // heartbeats reporting stopped / pre-operational
  std::uint32_t boot_ups = 0;
  std::uint32_t emcy_count = 0;
  canopen::Emergency last_emcy;
  std::uint8_t last_emcy_node = 0;
  std::uint32_t nmt_sent = 0;
  std::uint32_t sync_sent = 0;
  std::uint32_t sync_try_later = 0;
  std::uint32_t sync_missed = 0;       // periods skipped because update() ran late
  std::uint32_t tx_errors = 0;
  std::uint32_t rx_errors = 0;
};

class CanOpenEncoderPair final : public hal::WheelEncoderSource {
 public:
  // Options must pass validate(); otherwise start()/update() return -1 and do nothing.
  CanOpenEncoderPair(hal::CanBus& bus, const hal::MonotonicClock& clock,
                     const CanOpenEncoderOptions& options);
  // Sends NMT start to both nodes (if configured) and starts heartbeat supervision and
  // the SYNC schedule. Returns 1 when both commands were sent, 0 when the bus said try
  // later (call again), < 0 on error.
  int start();
  int update() override;
  hal::WheelEncoderSample latest() const override;

  const CanOpenEncoderStats& stats() const { return stats_; }
  bool heartbeat_lost(hal::WheelSide side) const { return wheel(side).heartbeat_lost; }
  bool options_ok() const { return options_ok_; }

 private:
  const internal::WheelTracker& wheel(hal::WheelSide s) const {
    return wheels_[static_cast<int>(s)];
  }
  void handle(const hal::CanFrame& f, std::int64_t now_us);
  int send_nmt_start(std::uint8_t node);
  void produce_sync(std::int64_t now_us);

  hal::CanBus& bus_;
  const hal::MonotonicClock& clock_;
  CanOpenEncoderOptions options_;
  bool options_ok_;
  internal::WheelTracker wheels_[2];
  CanOpenEncoderStats stats_;
  std::int64_t supervision_start_us_ = 0;
  std::int64_t next_sync_us_ = 0;
  bool started_ = false;
  int nmt_pending_ = 0;  // bit 0 left, bit 1 right: NMT start still to be sent
};

}  // namespace sdpslam::drivers
