#pragma once
// Classic CAN (2.0A/B) bus interface, after ArduPilot's AP_HAL::CANIface: a tiny seam
// between the encoder protocol handlers and whatever moves frames (SocketCAN, a test
// socketpair, a log replay). No OS headers here.
//
// Tri-state results (ArduPilot convention): every operation returns
//   < 0  error (the implementation says which through its own accessors and stats),
//     0  nothing to receive / no room to send: try later, not a failure,
//     1  done.
#include <cstdint>

namespace sdpslam::hal {

// One classic CAN frame. `id` uses the same bit layout as SocketCAN's `can_id`
// (linux/can.h) so drivers copy it unchanged: bits 0-28 identifier, bit 31 extended
// (29-bit) frame, bit 30 remote request, bit 29 error frame.
struct CanFrame {
  static constexpr std::uint32_t kExtendedFlag = 0x80000000u;  // CAN_EFF_FLAG
  static constexpr std::uint32_t kRtrFlag = 0x40000000u;       // CAN_RTR_FLAG
  static constexpr std::uint32_t kErrorFlag = 0x20000000u;     // CAN_ERR_FLAG
  static constexpr std::uint32_t kStandardMask = 0x7FFu;       // CAN_SFF_MASK
  static constexpr std::uint32_t kExtendedMask = 0x1FFFFFFFu;  // CAN_EFF_MASK
  static constexpr std::uint8_t kMaxDataBytes = 8;

  std::uint32_t id = 0;
  std::uint8_t dlc = 0;  // 0..8; for RTR frames the requested length
  std::uint8_t data[kMaxDataBytes] = {};
  // Receive (or log) time on the hal::MonotonicClock; 0 when unknown.
  std::int64_t stamp_us = 0;

  bool is_extended() const { return (id & kExtendedFlag) != 0; }
  bool is_rtr() const { return (id & kRtrFlag) != 0; }
  bool is_error() const { return (id & kErrorFlag) != 0; }
  // The identifier without flag bits (11 bits for standard frames, 29 for extended).
  std::uint32_t arbitration_id() const {
    return id & (is_extended() ? kExtendedMask : kStandardMask);
  }
  // A standard (11-bit) data frame; copies min(dlc, 8) bytes from `bytes` (may be null
  // when dlc is 0).
  static CanFrame standard(std::uint32_t id11, const std::uint8_t* bytes, std::uint8_t dlc) {
    CanFrame f;
    f.id = id11 & kStandardMask;
    f.dlc = dlc > kMaxDataBytes ? kMaxDataBytes : dlc;
    for (std::uint8_t i = 0; i < f.dlc; ++i) f.data[i] = bytes[i];
    return f;
  }
};

// Controller / interface state (ISO 11898-1 fault confinement plus "interface down").
enum class CanBusState : std::uint8_t {
  kActive,   // error-active, normal operation
  kWarning,  // an error counter passed 96
  kPassive,  // an error counter passed 127
  kBusOff,   // TEC > 255: the controller left the bus
  kDown,     // the interface is down / gone / not open
};

const char* to_string(CanBusState state);

// Error frames by class (bits of can_id in linux/can/error.h) and controller details.
struct CanErrorCounts {
  std::uint32_t tx_timeout = 0;
  std::uint32_t lost_arbitration = 0;
  std::uint32_t controller = 0;  // CAN_ERR_CRTL (details below)
  std::uint32_t protocol = 0;
  std::uint32_t transceiver = 0;
  std::uint32_t no_ack = 0;
  std::uint32_t bus_off = 0;
  std::uint32_t bus_error = 0;
  std::uint32_t restarted = 0;
  std::uint32_t warning = 0;              // data[1] RX/TX warning
  std::uint32_t passive = 0;              // data[1] RX/TX passive
  std::uint32_t controller_overflow = 0;  // data[1] RX/TX buffer overflow
};

// Counters never decrease for the lifetime of the bus object (re-opens included).
struct CanBusStats {
  std::uint64_t tx_frames = 0;
  std::uint64_t rx_frames = 0;         // data/RTR frames delivered to the caller
  std::uint64_t tx_try_later = 0;      // send() returned 0 (ENOBUFS / EAGAIN)
  std::uint64_t tx_errors = 0;         // frames refused on an open bus (bad frame, kernel error)
  std::uint64_t tx_while_down = 0;     // send() calls refused while the bus was down
  std::uint64_t rx_errors = 0;         // receive() returned < 0 (bad length excluded)
  std::uint64_t rx_overflows = 0;      // frames the kernel dropped (SO_RXQ_OVFL)
  std::uint64_t rx_filtered = 0;       // frames dropped by the software id filter
  std::uint64_t error_frames = 0;      // error frames received (consumed, not delivered)
  CanErrorCounts errors;
  std::uint64_t bad_length_reads = 0;  // datagrams that were not exactly one frame
  std::uint32_t down_count = 0;        // transitions into CanBusState::kDown
  std::uint32_t reopen_attempts = 0;
  std::uint32_t reopen_count = 0;      // successful re-opens after a down state
};

class CanBus {
 public:
  virtual ~CanBus() = default;
  // Queues one frame. 1 sent, 0 no room (try later), < 0 error (bus down, bad frame).
  virtual int send(const CanFrame& frame) = 0;
  // Takes one received data/RTR frame, stamped on the monotonic clock. 1 a frame was
  // written to `out`, 0 nothing pending, < 0 error (`out` untouched). Never blocks.
  virtual int receive(CanFrame& out) = 0;
  // Blocks up to `timeout_us` until receive() may have something. 1 readable, 0 timed
  // out, < 0 error (bus down and cannot be re-opened now).
  virtual int wait_readable(std::int64_t timeout_us) = 0;
  virtual CanBusState state() const = 0;
  virtual const CanBusStats& stats() const = 0;
};

inline const char* to_string(CanBusState state) {
  switch (state) {
    case CanBusState::kActive: return "active";
    case CanBusState::kWarning: return "warning";
    case CanBusState::kPassive: return "passive";
    case CanBusState::kBusOff: return "bus-off";
    case CanBusState::kDown: return "down";
  }
  return "?";
}

}  // namespace sdpslam::hal
