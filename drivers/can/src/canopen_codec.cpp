#include "sdpslam/drivers/canopen_codec.h"

namespace sdpslam::drivers {

const char* to_string(CanDecodeError e) {
  switch (e) {
    case CanDecodeError::kOk: return "ok";
    case CanDecodeError::kWrongId: return "unexpected identifier";
    case CanDecodeError::kExtendedId: return "extended (29-bit) identifier";
    case CanDecodeError::kRtr: return "remote request (no data)";
    case CanDecodeError::kErrorFrame: return "error frame";
    case CanDecodeError::kWrongLength: return "wrong data length (DLC)";
    case CanDecodeError::kBadValue: return "value outside the object's range";
    case CanDecodeError::kBadNode: return "node id out of range";
  }
  return "?";
}

namespace canopen {
namespace {

bool node_ok(std::uint8_t node) { return node >= 1 && node <= kMaxNodeId; }

// Common checks of every decoder: a standard data frame with the expected id.
CanDecodeError check_frame(const hal::CanFrame& f, std::uint32_t expected_id) {
  if (f.is_error()) return CanDecodeError::kErrorFrame;
  if (f.is_extended()) return CanDecodeError::kExtendedId;
  if (f.is_rtr()) return CanDecodeError::kRtr;
  if (f.arbitration_id() != expected_id) return CanDecodeError::kWrongId;
  if (f.dlc > hal::CanFrame::kMaxDataBytes) return CanDecodeError::kWrongLength;
  return CanDecodeError::kOk;
}

}  // namespace

const char* to_string(NodeState s) {
  switch (s) {
    case NodeState::kBootUp: return "boot-up";
    case NodeState::kStopped: return "stopped";
    case NodeState::kOperational: return "operational";
    case NodeState::kPreOperational: return "pre-operational";
  }
  return "?";
}

ObjectId classify(const hal::CanFrame& f) {
  ObjectId o;
  if (f.is_error() || f.is_extended() || f.is_rtr()) return o;
  const std::uint32_t id = f.arbitration_id();
  if (id == kNmtId) {
    o.kind = ObjectKind::kNmt;
    return o;
  }
  if (id == kSyncId) {
    o.kind = ObjectKind::kSync;
    return o;
  }
  const std::uint32_t function = id & 0x780u;
  const auto node = static_cast<std::uint8_t>(id & 0x7Fu);
  if (node == 0) return o;
  switch (function) {
    case kEmcyBase: o.kind = ObjectKind::kEmcy; break;
    case kTpdo1Base: o.kind = ObjectKind::kTpdo1; break;
    case kSdoTxBase: o.kind = ObjectKind::kSdoTx; break;
    case kSdoRxBase: o.kind = ObjectKind::kSdoRx; break;
    case kHeartbeatBase: o.kind = ObjectKind::kHeartbeat; break;
    default: return o;
  }
  o.node = node;
  return o;
}

bool make_nmt(NmtCommand command, std::uint8_t node, hal::CanFrame& out) {
  if (node > kMaxNodeId) return false;
  const std::uint8_t bytes[2] = {static_cast<std::uint8_t>(command), node};
  out = hal::CanFrame::standard(kNmtId, bytes, 2);
  return true;
}

hal::CanFrame make_sync() { return hal::CanFrame::standard(kSyncId, nullptr, 0); }

bool make_tpdo1_position(std::uint8_t node, std::uint32_t position, std::uint8_t position_bytes,
                         hal::CanFrame& out) {
  if (!node_ok(node) || (position_bytes != 2 && position_bytes != 4)) return false;
  std::uint8_t bytes[4];
  for (int i = 0; i < 4; ++i) bytes[i] = static_cast<std::uint8_t>(position >> (8 * i));
  out = hal::CanFrame::standard(kTpdo1Base + node, bytes, position_bytes);
  return true;
}

bool make_heartbeat(std::uint8_t node, NodeState state, hal::CanFrame& out) {
  if (!node_ok(node)) return false;
  const std::uint8_t b = static_cast<std::uint8_t>(state);
  out = hal::CanFrame::standard(kHeartbeatBase + node, &b, 1);
  return true;
}

CanDecodeError decode_tpdo1_position(const hal::CanFrame& f, std::uint8_t node,
                                     std::uint8_t position_bytes, std::uint32_t& position) {
  if (!node_ok(node)) return CanDecodeError::kBadNode;
  if (const auto e = check_frame(f, kTpdo1Base + node); e != CanDecodeError::kOk) return e;
  if ((position_bytes != 2 && position_bytes != 4) || f.dlc < position_bytes) {
    return CanDecodeError::kWrongLength;
  }
  std::uint32_t v = 0;
  for (int i = position_bytes - 1; i >= 0; --i) v = (v << 8) | f.data[i];
  position = v;
  return CanDecodeError::kOk;
}

CanDecodeError decode_heartbeat(const hal::CanFrame& f, std::uint8_t node, NodeState& state) {
  if (!node_ok(node)) return CanDecodeError::kBadNode;
  if (const auto e = check_frame(f, kHeartbeatBase + node); e != CanDecodeError::kOk) return e;
  if (f.dlc != 1) return CanDecodeError::kWrongLength;
  switch (f.data[0]) {
    case 0x00:
    case 0x04:
    case 0x05:
    case 0x7F:
      state = static_cast<NodeState>(f.data[0]);
      return CanDecodeError::kOk;
    default:
      return CanDecodeError::kBadValue;
  }
}

CanDecodeError decode_emcy(const hal::CanFrame& f, std::uint8_t node, Emergency& emcy) {
  if (!node_ok(node)) return CanDecodeError::kBadNode;
  if (const auto e = check_frame(f, kEmcyBase + node); e != CanDecodeError::kOk) return e;
  if (f.dlc != 8) return CanDecodeError::kWrongLength;
  emcy.error_code = static_cast<std::uint16_t>(f.data[0] | (f.data[1] << 8));
  emcy.error_register = f.data[2];
  for (int i = 0; i < 5; ++i) emcy.vendor[i] = f.data[3 + i];
  return CanDecodeError::kOk;
}

CanDecodeError decode_nmt(const hal::CanFrame& f, NmtCommand& command, std::uint8_t& node) {
  if (const auto e = check_frame(f, kNmtId); e != CanDecodeError::kOk) return e;
  if (f.dlc != 2) return CanDecodeError::kWrongLength;
  if (f.data[1] > kMaxNodeId) return CanDecodeError::kBadNode;
  switch (f.data[0]) {
    case 0x01:
    case 0x02:
    case 0x80:
    case 0x81:
    case 0x82:
      command = static_cast<NmtCommand>(f.data[0]);
      node = f.data[1];
      return CanDecodeError::kOk;
    default:
      return CanDecodeError::kBadValue;
  }
}

CanDecodeError decode_sync(const hal::CanFrame& f) {
  if (const auto e = check_frame(f, kSyncId); e != CanDecodeError::kOk) return e;
  return f.dlc <= 1 ? CanDecodeError::kOk : CanDecodeError::kWrongLength;
}

}  // namespace canopen
}  // namespace sdpslam::drivers
