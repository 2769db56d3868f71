#include "sdpslam/drivers/canopen_encoder_pair.h"

#include "sdpslam/drivers/internal/encoder_pair_poll.h"

namespace sdpslam::drivers {

CanOpenOptionsError validate(const CanOpenEncoderOptions& o) {
  auto node_ok = [](std::uint8_t n) { return n >= 1 && n <= canopen::kMaxNodeId; };
  if (!node_ok(o.left_node) || !node_ok(o.right_node)) return CanOpenOptionsError::kNode;
  if (o.left_node == o.right_node) return CanOpenOptionsError::kSameNode;
  if (o.position_bytes != 2 && o.position_bytes != 4) return CanOpenOptionsError::kPositionBytes;
  if (o.position_timeout_us <= 0 || o.sync_period_us < 0 || o.heartbeat_timeout_us < 0 ||
      o.max_frames_per_update <= 0) {
    return CanOpenOptionsError::kTimeout;
  }
  return CanOpenOptionsError::kOk;
}

CanOpenEncoderPair::CanOpenEncoderPair(hal::CanBus& bus, const hal::MonotonicClock& clock,
                                       const CanOpenEncoderOptions& options)
    : bus_(bus), clock_(clock), options_(options),
      options_ok_(validate(options) == CanOpenOptionsError::kOk) {
  supervision_start_us_ = clock_.now_us();
  next_sync_us_ = supervision_start_us_;
  const std::uint8_t bits = options_.position_bytes == 2 ? 16 : 32;
  for (auto& w : wheels_) w.ticks.counter_bits = bits;
}

int CanOpenEncoderPair::send_nmt_start(std::uint8_t node) {
  hal::CanFrame f;
  if (!canopen::make_nmt(canopen::NmtCommand::kStart, node, f)) return -1;
  const int r = bus_.send(f);
  if (r > 0) stats_.nmt_sent++;
  if (r < 0 && bus_.state() != hal::CanBusState::kDown) stats_.tx_errors++;  // down: the bus counts it
  return r;
}

int CanOpenEncoderPair::start() {
  if (!options_ok_) return -1;
  if (!started_) {
    started_ = true;
    supervision_start_us_ = clock_.now_us();
    next_sync_us_ = supervision_start_us_;
    nmt_pending_ = options_.send_nmt_start ? 3 : 0;
  }
  const std::uint8_t nodes[2] = {options_.left_node, options_.right_node};
  for (int i = 0; i < 2; ++i) {
    if ((nmt_pending_ & (1 << i)) == 0) continue;
    const int r = send_nmt_start(nodes[i]);
    if (r <= 0) return r;
    nmt_pending_ &= ~(1 << i);
  }
  return 1;
}

void CanOpenEncoderPair::produce_sync(std::int64_t now_us) {
  if (options_.sync_period_us <= 0 || now_us < next_sync_us_) return;
  const int r = bus_.send(canopen::make_sync());
  if (r == 0) {
    stats_.sync_try_later++;  // keep next_sync_us_: retried on the next update()
    return;
  }
  if (r > 0) {
    stats_.sync_sent++;
  } else if (bus_.state() != hal::CanBusState::kDown) {
    stats_.tx_errors++;  // while down, the bus counts the refusals (CanBusStats::tx_while_down)
  }
  // Keep the grid of the schedule (no drift); periods that passed entirely are skipped.
  next_sync_us_ += options_.sync_period_us;
  if (next_sync_us_ <= now_us) {
    const std::int64_t behind = (now_us - next_sync_us_) / options_.sync_period_us + 1;
    stats_.sync_missed += static_cast<std::uint32_t>(behind);
    next_sync_us_ += behind * options_.sync_period_us;
  }
}

void CanOpenEncoderPair::handle(const hal::CanFrame& f, std::int64_t now_us) {
  stats_.frames++;
  const canopen::ObjectId obj = canopen::classify(f);
  int side = -1;
  if (obj.node != 0 && obj.node == options_.left_node) side = 0;
  if (obj.node != 0 && obj.node == options_.right_node) side = 1;
  if (side < 0) {
    stats_.unexpected_frames++;
    return;
  }
  internal::WheelTracker& w = wheels_[side];
  switch (obj.kind) {
    case canopen::ObjectKind::kTpdo1: {
      std::uint32_t pos = 0;
      if (canopen::decode_tpdo1_position(f, obj.node, options_.position_bytes, pos) !=
          CanDecodeError::kOk) {
        stats_.decode_errors++;
        return;
      }
      w.on_position(pos, w.ticks.counter_bits, f.stamp_us, now_us);
      stats_.positions[side]++;
      return;
    }
    case canopen::ObjectKind::kHeartbeat: {
      canopen::NodeState st{};
      if (canopen::decode_heartbeat(f, obj.node, st) != CanDecodeError::kOk) {
        stats_.decode_errors++;
        return;
      }
      stats_.heartbeats++;
      w.on_heartbeat(st == canopen::NodeState::kOperational, now_us);
      if (st == canopen::NodeState::kBootUp) {
        // The node (re)started and sits in pre-operational: start it again.
        stats_.boot_ups++;
        if (started_ && options_.send_nmt_start) {
          nmt_pending_ |= 1 << side;
          if (send_nmt_start(obj.node) > 0) nmt_pending_ &= ~(1 << side);
        }
      } else if (st != canopen::NodeState::kOperational) {
        stats_.not_operational++;
      }
      return;
    }
    case canopen::ObjectKind::kEmcy: {
      canopen::Emergency e;
      if (canopen::decode_emcy(f, obj.node, e) != CanDecodeError::kOk) {
        stats_.decode_errors++;
        return;
      }
      stats_.emcy_count++;
      stats_.last_emcy = e;
      stats_.last_emcy_node = obj.node;
      return;
    }
    default:
      stats_.unexpected_frames++;
      return;
  }
}

int CanOpenEncoderPair::update() {
  if (!options_ok_) return -1;
  if (started_ && nmt_pending_ != 0) start();
  return internal::poll_encoder_pair(
      bus_, clock_, options_, supervision_start_us_, wheels_, stats_,
      [this](const hal::CanFrame& f, std::int64_t now_us) { handle(f, now_us); },
      [this](std::int64_t now_us) { produce_sync(now_us); });
}

hal::WheelEncoderSample CanOpenEncoderPair::latest() const { return internal::pair_sample(wheels_); }

}  // namespace sdpslam::drivers
