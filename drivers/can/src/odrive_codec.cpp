#include "sdpslam/drivers/odrive_codec.h"

#include <cmath>
#include <cstring>

namespace sdpslam::drivers::odrive {
namespace {

std::uint32_t read_u32_le(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}
void write_u32_le(std::uint32_t v, std::uint8_t* p) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
// IEEE 754 binary32 from its bit pattern; host float is binary32 on every target we build.
float f32_from_bits(std::uint32_t bits) {
  static_assert(sizeof(float) == 4, "binary32 float expected");
  float f;
  std::memcpy(&f, &bits, sizeof f);
  return f;
}
std::uint32_t bits_from_f32(float f) {
  std::uint32_t bits;
  std::memcpy(&bits, &f, sizeof bits);
  return bits;
}

CanDecodeError check_frame(const hal::CanFrame& f, std::uint8_t node, std::uint8_t cmd) {
  if (node > kMaxNodeId) return CanDecodeError::kBadNode;
  if (f.is_error()) return CanDecodeError::kErrorFrame;
  if (f.is_extended()) return CanDecodeError::kExtendedId;
  if (f.is_rtr()) return CanDecodeError::kRtr;
  if (f.arbitration_id() != make_id(node, cmd)) return CanDecodeError::kWrongId;
  return CanDecodeError::kOk;
}

}  // namespace

bool make_encoder_estimates_request(std::uint8_t node, hal::CanFrame& out) {
  if (node > kMaxNodeId) return false;
  out = hal::CanFrame{};
  out.id = make_id(node, kCmdGetEncoderEstimates) | hal::CanFrame::kRtrFlag;
  out.dlc = 0;
  return true;
}

bool make_encoder_estimates(std::uint8_t node, const EncoderEstimates& est, hal::CanFrame& out) {
  if (node > kMaxNodeId) return false;
  std::uint8_t b[8];
  write_u32_le(bits_from_f32(est.pos_turns), b);
  write_u32_le(bits_from_f32(est.vel_turns_s), b + 4);
  out = hal::CanFrame::standard(make_id(node, kCmdGetEncoderEstimates), b, 8);
  return true;
}

bool make_heartbeat(std::uint8_t node, const Heartbeat& hb, hal::CanFrame& out) {
  if (node > kMaxNodeId) return false;
  std::uint8_t b[8] = {};
  write_u32_le(hb.axis_error, b);
  b[4] = hb.axis_state;
  out = hal::CanFrame::standard(make_id(node, kCmdHeartbeat), b, 8);
  return true;
}

CanDecodeError decode_encoder_estimates(const hal::CanFrame& f, std::uint8_t node,
                                        EncoderEstimates& out) {
  if (const auto e = check_frame(f, node, kCmdGetEncoderEstimates); e != CanDecodeError::kOk) {
    return e;
  }
  if (f.dlc != 8) return CanDecodeError::kWrongLength;
  const float pos = f32_from_bits(read_u32_le(f.data));
  const float vel = f32_from_bits(read_u32_le(f.data + 4));
  if (!std::isfinite(pos) || !std::isfinite(vel)) return CanDecodeError::kBadValue;
  out.pos_turns = pos;
  out.vel_turns_s = vel;
  return CanDecodeError::kOk;
}

CanDecodeError decode_heartbeat(const hal::CanFrame& f, std::uint8_t node, Heartbeat& out) {
  if (const auto e = check_frame(f, node, kCmdHeartbeat); e != CanDecodeError::kOk) return e;
  if (f.dlc < 5 || f.dlc > 8) return CanDecodeError::kWrongLength;
  out.axis_error = read_u32_le(f.data);
  out.axis_state = f.data[4];
  return CanDecodeError::kOk;
}

}  // namespace sdpslam::drivers::odrive
