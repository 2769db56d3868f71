#pragma once
// CANopen (CiA 301 communication profile, CiA 406 encoder profile) frames used by a
// host reading two wheel encoders: pure functions over hal::CanFrame, no I/O.
// Identifiers and values: protocols.md §3 "CANopen encoder"; CiA 301 §7.2 (pre-defined
// connection set), §7.2.8.3 (NMT), §7.2.5 (SYNC), §7.2.7 (EMCY), §7.2.8.3.2 (heartbeat);
// CiA 406 object 0x6004 (position value, u32).
#include <cstdint>

#include "sdpslam/drivers/can_decode_error.h"
#include "sdpslam/hal/can_bus.h"

namespace sdpslam::drivers::canopen {

inline constexpr std::uint32_t kNmtId = 0x000;
inline constexpr std::uint32_t kSyncId = 0x080;
inline constexpr std::uint32_t kEmcyBase = 0x080;  // + node (1..127)
inline constexpr std::uint32_t kTpdo1Base = 0x180;
inline constexpr std::uint32_t kSdoTxBase = 0x580;  // server -> client
inline constexpr std::uint32_t kSdoRxBase = 0x600;  // client -> server
inline constexpr std::uint32_t kHeartbeatBase = 0x700;
inline constexpr std::uint8_t kMaxNodeId = 127;

enum class NmtCommand : std::uint8_t {
  kStart = 0x01,
  kStop = 0x02,
  kEnterPreOperational = 0x80,
  kResetNode = 0x81,
  kResetCommunication = 0x82,
};

// Heartbeat / boot-up payload (CiA 301 §7.2.8.3.2.2).
enum class NodeState : std::uint8_t {
  kBootUp = 0x00,
  kStopped = 0x04,
  kOperational = 0x05,
  kPreOperational = 0x7F,
};
const char* to_string(NodeState s);

// Which pre-defined connection-set object a standard frame is, and for which node.
enum class ObjectKind : std::uint8_t { kNmt, kSync, kEmcy, kTpdo1, kSdoTx, kSdoRx, kHeartbeat, kOther };
struct ObjectId {
  ObjectKind kind = ObjectKind::kOther;
  std::uint8_t node = 0;  // 0 for NMT/SYNC/other
};
// Classifies by identifier only (extended, RTR and error frames are kOther).
ObjectId classify(const hal::CanFrame& frame);

// NMT command frame `000#<cmd><node>`; node 0 addresses all nodes. Returns false (and
// leaves `out` untouched) iff node > 127.
bool make_nmt(NmtCommand command, std::uint8_t node, hal::CanFrame& out);
// SYNC `080#` with DLC 0 (no counter, CiA 301 sync-counter-overflow value 0).
hal::CanFrame make_sync();
// TPDO1 carrying `position` in `position_bytes` (2 or 4) little-endian bytes; used by
// test encoders. Returns false iff node is out of range or position_bytes is not 2 or 4.
bool make_tpdo1_position(std::uint8_t node, std::uint32_t position, std::uint8_t position_bytes,
                         hal::CanFrame& out);
bool make_heartbeat(std::uint8_t node, NodeState state, hal::CanFrame& out);

struct Emergency {
  std::uint16_t error_code = 0;     // bytes 0-1, little-endian (CiA 301 Table 21)
  std::uint8_t error_register = 0;  // byte 2 (object 0x1001)
  std::uint8_t vendor[5] = {};      // bytes 3-7, manufacturer-specific
};

// Decoders: `node` is the expected node id (1..127). Each checks, in order: error
// frame, extended id, RTR, identifier, DLC, value; the first mismatch is returned.
//
// TPDO1 position (CiA 406 0x6004 in the default mapping): DLC must be at least
// `position_bytes` (2 for a 16-bit counter, 4 for u32; further mapped objects are
// ignored). The value is little-endian.
CanDecodeError decode_tpdo1_position(const hal::CanFrame& frame, std::uint8_t node,
                                     std::uint8_t position_bytes, std::uint32_t& position);
// Heartbeat or boot-up: DLC exactly 1, value one of NodeState (the toggle bit 7 is only
// used by node guarding, which answers RTRs; a heartbeat has it clear).
CanDecodeError decode_heartbeat(const hal::CanFrame& frame, std::uint8_t node, NodeState& state);
// EMCY: DLC exactly 8.
CanDecodeError decode_emcy(const hal::CanFrame& frame, std::uint8_t node, Emergency& emcy);
// NMT command as seen on the bus (used by test encoders): DLC exactly 2, known command.
CanDecodeError decode_nmt(const hal::CanFrame& frame, NmtCommand& command, std::uint8_t& node);
// SYNC: id 0x080, DLC 0 or 1 (optional counter).
CanDecodeError decode_sync(const hal::CanFrame& frame);

}  // namespace sdpslam::drivers::canopen
