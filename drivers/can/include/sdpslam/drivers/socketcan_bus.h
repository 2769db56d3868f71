#pragma once
// hal::CanBus on Linux SocketCAN (CAN_RAW), used the way can-utils' candump does it
// (protocols.md §3 "Linux SocketCAN, used robustly"):
//  - socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK, CAN_RAW), SIOCGIFINDEX, bind; poll() waits.
//  - CAN_RAW_FILTER with the configured ids (and the same filter applied in software, so
//    adopted fds behave alike); CAN_RAW_ERR_FILTER = ACK | CRTL | BUSOFF | BUSERROR.
//  - Error frames are consumed: decoded into CanBusStats::errors and the bus state, never
//    delivered by receive().
//  - SO_TIMESTAMP: the kernel receive stamp (CLOCK_REALTIME) is mapped onto the monotonic
//    clock; without it the frame is stamped with clock.now_us() at read time.
//  - SO_RXQ_OVFL: the kernel's drop counter is exposed as stats().rx_overflows.
//  - Every read must be exactly 16 bytes (struct can_frame); any other length is rejected
//    and counted (bad_length_reads) and receive() returns -1 for that datagram.
//  - send: ENOBUFS / EAGAIN -> 0 (try later, counted); ENETDOWN / ENXIO / ENODEV -> state
//    kDown, -1. While down, every call retries the open at most once per
//    reopen_interval_us; a success counts in reopen_count and restores kActive.
//
// "Adopted fd" mode wraps an fd someone else opened (tests use
// socketpair(AF_UNIX, SOCK_SEQPACKET), which carries 16-byte datagrams like CAN_RAW). The
// CAN socket options are attempted and their failure tolerated; a peer that closes
// (read of 0 bytes, EPIPE / ECONNRESET) puts the bus in kDown; an adopted fd is never
// re-opened. The object closes the fd it owns (adopted ones too) on destruction.
//
// Memory: fixed; no heap. Not thread-safe (one owner thread).
#include <cstddef>
#include <cstdint>

#include "sdpslam/hal/can_bus.h"
#include "sdpslam/hal/clock.h"

namespace sdpslam::drivers {

struct CanIdFilter {
  std::uint32_t id = 0;    // hal::CanFrame::id layout (flags included)
  std::uint32_t mask = 0;  // a frame passes iff (frame.id & mask) == (id & mask)
};

struct SocketCanOptions {
  static constexpr int kMaxFilters = 16;
  char interface_name[16] = "can0";  // IFNAMSIZ including the terminator
  CanIdFilter filters[kMaxFilters] = {};
  int filter_count = 0;  // 0 = receive every frame
  // Error classes requested with CAN_RAW_ERR_FILTER (linux/can/error.h bits):
  // ACK | CRTL | BUSOFF | BUSERROR.
  std::uint32_t error_mask = 0x20u | 0x04u | 0x40u | 0x80u;
  std::int64_t reopen_interval_us = 500000;
  bool kernel_timestamps = true;  // SO_TIMESTAMP
};

// Why the last operation failed (the tri-state result says only that it did).
enum class SocketCanError : std::uint8_t {
  kNone,
  kBadLength,    // a datagram that was not one struct can_frame
  kDown,         // interface down / gone (ENETDOWN, ENXIO, ENODEV) or not open
  kPeerClosed,   // adopted fd: the other end closed
  kNoInterface,  // SIOCGIFINDEX failed (no such interface)
  kOs,           // any other errno (see last_errno())
};
const char* to_string(SocketCanError e);

// The cause of a failure in words a robot builder can act on, written to `out` (always
// terminated): "the kernel has no CAN support ..." (socket(PF_CAN) refused),
// "interface can0 does not exist ...", "interface can0 is down ...", or the error's
// strerror text. Returns `out`.
const char* describe_failure(SocketCanError e, int err, const char* interface_name, char* out, std::size_t size);

class SocketCanBus final : public hal::CanBus {
 public:
  // Opens `options.interface_name` at once; on failure the bus starts in kDown and
  // retries like any other down state.
  SocketCanBus(const SocketCanOptions& options, const hal::MonotonicClock& clock);
  // Adopted-fd mode: takes ownership of `fd` (made non-blocking here).
  struct AdoptFd {
    int fd;
  };
  SocketCanBus(AdoptFd adopted, const SocketCanOptions& options, const hal::MonotonicClock& clock);
  ~SocketCanBus() override;
  SocketCanBus(const SocketCanBus&) = delete;
  SocketCanBus& operator=(const SocketCanBus&) = delete;

  int send(const hal::CanFrame& frame) override;
  int receive(hal::CanFrame& out) override;
  int wait_readable(std::int64_t timeout_us) override;
  hal::CanBusState state() const override { return state_; }
  const hal::CanBusStats& stats() const override { return stats_; }

  SocketCanError last_error() const { return last_error_; }
  int last_errno() const { return last_errno_; }
  // describe_failure() of the last error, for this interface.
  const char* describe_last_failure(char* out, std::size_t size) const {
    return describe_failure(last_error_, last_errno_, options_.interface_name, out, size);
  }
  bool adopted() const { return adopted_; }
  int fd() const { return fd_; }
  // True iff the kernel accepted CAN_RAW_FILTER / SO_TIMESTAMP / SO_RXQ_OVFL on this fd.
  bool kernel_filter_active() const { return kernel_filter_; }
  bool kernel_timestamps_active() const { return kernel_timestamps_; }

  // Decodes one error frame into counters and state (public for tests and replay).
  void account_error_frame(const hal::CanFrame& frame);

 private:
  bool open_interface();
  void configure_socket();
  void go_down(SocketCanError why, int err);
  void close_fd();
  bool maybe_reopen();
  bool passes_filter(const hal::CanFrame& f) const;

  SocketCanOptions options_;
  const hal::MonotonicClock& clock_;
  int fd_ = -1;
  bool adopted_ = false;
  bool kernel_filter_ = false;
  bool kernel_timestamps_ = false;
  bool ever_opened_ = false;
  hal::CanBusState state_ = hal::CanBusState::kDown;
  hal::CanBusStats stats_;
  SocketCanError last_error_ = SocketCanError::kNone;
  int last_errno_ = 0;
  std::int64_t last_open_attempt_us_ = 0;
  std::uint64_t overflow_base_ = 0;    // drops counted by sockets closed before this one
  std::uint32_t overflow_socket_ = 0;  // SO_RXQ_OVFL value of the current socket
};

}  // namespace sdpslam::drivers
