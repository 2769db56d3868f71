#pragma once
// ODrive "CAN Simple" protocol (ODrive docs can-protocol.rst): 11-bit id =
// node_id << 5 | cmd_id, payload little-endian. Pure functions, no I/O
// (protocols.md §3 "ODrive CAN Simple").
#include <cstdint>

#include "sdpslam/drivers/can_decode_error.h"
#include "sdpslam/hal/can_bus.h"

namespace sdpslam::drivers::odrive {

inline constexpr std::uint8_t kCmdHeartbeat = 0x01;
inline constexpr std::uint8_t kCmdGetEncoderEstimates = 0x09;
inline constexpr std::uint8_t kMaxNodeId = 0x3F;  // 6 bits
inline constexpr std::uint8_t kMaxCmdId = 0x1F;   // 5 bits

inline constexpr std::uint32_t make_id(std::uint8_t node, std::uint8_t cmd) {
  return (static_cast<std::uint32_t>(node & kMaxNodeId) << 5) | (cmd & kMaxCmdId);
}
inline constexpr std::uint8_t node_of(std::uint32_t id11) {
  return static_cast<std::uint8_t>((id11 >> 5) & kMaxNodeId);
}
inline constexpr std::uint8_t cmd_of(std::uint32_t id11) {
  return static_cast<std::uint8_t>(id11 & kMaxCmdId);
}

struct EncoderEstimates {
  float pos_turns = 0.0f;   // bytes 0-3, f32 LE
  float vel_turns_s = 0.0f; // bytes 4-7, f32 LE
};

struct Heartbeat {
  std::uint32_t axis_error = 0;  // bytes 0-3, u32 LE
  std::uint8_t axis_state = 0;   // byte 4 (8 = CLOSED_LOOP_CONTROL)
};

// RTR request for Get_Encoder_Estimates (DLC 0, as `029#R` in candump syntax). Returns
// false iff node > 63.
bool make_encoder_estimates_request(std::uint8_t node, hal::CanFrame& out);
// The reply an axis sends (used by test fakes). Returns false iff node > 63.
bool make_encoder_estimates(std::uint8_t node, const EncoderEstimates& est, hal::CanFrame& out);
bool make_heartbeat(std::uint8_t node, const Heartbeat& hb, hal::CanFrame& out);

// Get_Encoder_Estimates reply from `node`: DLC exactly 8, both values finite.
CanDecodeError decode_encoder_estimates(const hal::CanFrame& frame, std::uint8_t node,
                                        EncoderEstimates& out);
// Heartbeat from `node`: DLC 5..8 (firmware 0.5 sends 8; extra bytes ignored).
CanDecodeError decode_heartbeat(const hal::CanFrame& frame, std::uint8_t node, Heartbeat& out);

}  // namespace sdpslam::drivers::odrive
