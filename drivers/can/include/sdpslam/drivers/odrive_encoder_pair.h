#pragma once
// Two ODrive axes (left and right wheel) speaking CAN Simple, as a
// hal::WheelEncoderSource (protocols.md §3 "ODrive CAN Simple").
//
// Each axis sends Get_Encoder_Estimates (cmd 0x009: f32 position in turns, f32 velocity)
// cyclically, or on an RTR request when request_period_us > 0. Positions are converted to
// a 32-bit counter: raw = round(pos_turns · counts_per_turn) mod 2^32, so the odometry
// takes deltas exactly as for CANopen encoders (use ticks_per_rev = counts_per_turn).
// f32 carries 24 significant bits: at 8192 counts/turn a position stays exact to better
// than one count up to ±1024 turns; beyond that steps are coarser but never lost.
// Positions whose count would not fit in ±2^62 are rejected as decode errors.
// Heartbeats (cmd 0x001) are supervised like CANopen heartbeats; a non-zero axis_error is
// counted (and kept) but does not by itself make the wheel stale.
// A wheel is stale when no estimate arrived within position_timeout_us.
#include <cstdint>

#include "sdpslam/drivers/internal/wheel_tracker.h"
#include "sdpslam/drivers/odrive_codec.h"
#include "sdpslam/hal/can_bus.h"
#include "sdpslam/hal/clock.h"
#include "sdpslam/hal/wheel_encoder_source.h"

namespace sdpslam::drivers {

struct ODriveEncoderOptions {
  std::uint8_t left_node = 0;
  std::uint8_t right_node = 1;
  double counts_per_turn = 8192.0;
  std::int64_t request_period_us = 0;  // 0: axes stream estimates by themselves
  std::int64_t position_timeout_us = 100000;
  std::int64_t heartbeat_timeout_us = 0;  // 0: no heartbeat supervision
  int max_frames_per_update = 64;
};

enum class ODriveOptionsError : std::uint8_t { kOk, kNode, kSameNode, kCountsPerTurn, kTimeout };
ODriveOptionsError validate(const ODriveEncoderOptions& o);

struct ODriveEncoderStats {
  std::uint64_t frames = 0;
  std::uint64_t positions[2] = {0, 0};
  std::uint64_t unexpected_frames = 0;
  std::uint64_t decode_errors = 0;
  std::uint64_t heartbeats = 0;
  std::uint32_t heartbeat_timeouts = 0;
  std::uint32_t axis_error_reports = 0;  // heartbeats with axis_error != 0
  std::uint32_t last_axis_error[2] = {0, 0};
  std::uint8_t axis_state[2] = {0, 0};
  float vel_turns_s[2] = {0.0f, 0.0f};
  std::uint32_t requests_sent = 0;
  std::uint32_t request_try_later = 0;
  std::uint32_t tx_errors = 0;
  std::uint32_t rx_errors = 0;
};

class ODriveEncoderPair final : public hal::WheelEncoderSource {
 public:
  ODriveEncoderPair(hal::CanBus& bus, const hal::MonotonicClock& clock,
                    const ODriveEncoderOptions& options);
  int update() override;
  hal::WheelEncoderSample latest() const override;
  const ODriveEncoderStats& stats() const { return stats_; }
  bool options_ok() const { return options_ok_; }
  bool heartbeat_lost(hal::WheelSide side) const {
    return wheels_[static_cast<int>(side)].heartbeat_lost;
  }

 private:
  void handle(const hal::CanFrame& f, std::int64_t now_us);
  void request(std::int64_t now_us);

  hal::CanBus& bus_;
  const hal::MonotonicClock& clock_;
  ODriveEncoderOptions options_;
  bool options_ok_;
  internal::WheelTracker wheels_[2];
  ODriveEncoderStats stats_;
  std::int64_t supervision_start_us_ = 0;
  std::int64_t next_request_us_ = 0;
};

}  // namespace sdpslam::drivers
