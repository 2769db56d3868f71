#include "sdpslam/drivers/odrive_encoder_pair.h"

#include <cmath>

#include "sdpslam/drivers/internal/encoder_pair_poll.h"

namespace sdpslam::drivers {

ODriveOptionsError validate(const ODriveEncoderOptions& o) {
  if (o.left_node > odrive::kMaxNodeId || o.right_node > odrive::kMaxNodeId) {
    return ODriveOptionsError::kNode;
  }
  if (o.left_node == o.right_node) return ODriveOptionsError::kSameNode;
  if (!std::isfinite(o.counts_per_turn) || o.counts_per_turn <= 0.0) {
    return ODriveOptionsError::kCountsPerTurn;
  }
  if (o.position_timeout_us <= 0 || o.request_period_us < 0 || o.heartbeat_timeout_us < 0 ||
      o.max_frames_per_update <= 0) {
    return ODriveOptionsError::kTimeout;
  }
  return ODriveOptionsError::kOk;
}

ODriveEncoderPair::ODriveEncoderPair(hal::CanBus& bus, const hal::MonotonicClock& clock,
                                     const ODriveEncoderOptions& options)
    : bus_(bus), clock_(clock), options_(options),
      options_ok_(validate(options) == ODriveOptionsError::kOk) {
  supervision_start_us_ = clock_.now_us();
  next_request_us_ = supervision_start_us_;
}

void ODriveEncoderPair::handle(const hal::CanFrame& f, std::int64_t now_us) {
  stats_.frames++;
  if (f.is_extended() || f.is_error() || f.is_rtr()) {
    stats_.unexpected_frames++;
    return;
  }
  const std::uint8_t node = odrive::node_of(f.arbitration_id());
  int side = -1;
  if (node == options_.left_node) side = 0;
  if (node == options_.right_node) side = 1;
  const std::uint8_t cmd = odrive::cmd_of(f.arbitration_id());
  if (side < 0 || (cmd != odrive::kCmdGetEncoderEstimates && cmd != odrive::kCmdHeartbeat)) {
    stats_.unexpected_frames++;
    return;
  }
  internal::WheelTracker& w = wheels_[side];
  if (cmd == odrive::kCmdGetEncoderEstimates) {
    odrive::EncoderEstimates est;
    if (odrive::decode_encoder_estimates(f, node, est) != CanDecodeError::kOk) {
      stats_.decode_errors++;
      return;
    }
    const double counts = std::round(static_cast<double>(est.pos_turns) * options_.counts_per_turn);
    if (!(std::fabs(counts) < 4.6e18)) {  // ±2^62
      stats_.decode_errors++;
      return;
    }
    const auto raw = static_cast<std::uint32_t>(static_cast<std::uint64_t>(static_cast<std::int64_t>(counts)));
    w.on_position(raw, 32, f.stamp_us, now_us);
    stats_.positions[side]++;
    stats_.vel_turns_s[side] = est.vel_turns_s;
    return;
  }
  odrive::Heartbeat hb;
  if (odrive::decode_heartbeat(f, node, hb) != CanDecodeError::kOk) {
    stats_.decode_errors++;
    return;
  }
  stats_.heartbeats++;
  stats_.axis_state[side] = hb.axis_state;
  stats_.last_axis_error[side] = hb.axis_error;
  if (hb.axis_error != 0) stats_.axis_error_reports++;
  w.on_heartbeat(true, now_us);
}

void ODriveEncoderPair::request(std::int64_t now_us) {
  if (options_.request_period_us <= 0 || now_us < next_request_us_) return;
  const std::uint8_t nodes[2] = {options_.left_node, options_.right_node};
  for (std::uint8_t node : nodes) {
    hal::CanFrame f;
    odrive::make_encoder_estimates_request(node, f);
    const int r = bus_.send(f);
    if (r > 0) stats_.requests_sent++;
    if (r == 0) stats_.request_try_later++;
    if (r < 0 && bus_.state() != hal::CanBusState::kDown) stats_.tx_errors++;  // down: the bus counts it
  }
  next_request_us_ += options_.request_period_us;
  if (next_request_us_ <= now_us) next_request_us_ = now_us + options_.request_period_us;
}

int ODriveEncoderPair::update() {
  if (!options_ok_) return -1;
  return internal::poll_encoder_pair(
      bus_, clock_, options_, supervision_start_us_, wheels_, stats_,
      [this](const hal::CanFrame& f, std::int64_t now_us) { handle(f, now_us); },
      [this](std::int64_t now_us) { request(now_us); });
}

hal::WheelEncoderSample ODriveEncoderPair::latest() const { return internal::pair_sample(wheels_); }

}  // namespace sdpslam::drivers
