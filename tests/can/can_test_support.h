#pragma once
// Test helpers for the CAN suite: a settable clock and the "other end" of a
// socketpair(AF_UNIX, SOCK_SEQPACKET) that speaks 16-byte struct can_frame datagrams.
#include <linux/can.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdint>
#include <cstring>

#include "sdpslam/hal/can_bus.h"
#include "sdpslam/hal/clock.h"

namespace sdpslam::test {

class FakeClock final : public hal::MonotonicClock {
 public:
  std::int64_t now_us() const override { return t_us; }
  std::int64_t t_us = 1000000;
};

// Both ends of a SOCK_SEQPACKET pair; `peer` plays the bus side (encoders), `local` is
// handed to the driver under test. Closes whatever it still owns.
struct SeqPacketPair {
  int local = -1;
  int peer = -1;
  SeqPacketPair() {
    int fds[2];
    if (::socketpair(AF_UNIX, SOCK_SEQPACKET, 0, fds) == 0) {
      local = fds[0];
      peer = fds[1];
    }
  }
  ~SeqPacketPair() {
    if (peer >= 0) ::close(peer);
  }
  int take_local() {
    const int fd = local;
    local = -1;
    return fd;
  }
  void close_peer() {
    ::close(peer);
    peer = -1;
  }
  bool peer_send(const hal::CanFrame& f) const {
    can_frame raw{};
    raw.can_id = f.id;
    raw.can_dlc = f.dlc;
    std::memcpy(raw.data, f.data, 8);
    return ::send(peer, &raw, sizeof raw, MSG_DONTWAIT | MSG_NOSIGNAL) == static_cast<ssize_t>(sizeof raw);
  }
  // 1 frame read, 0 nothing pending, -1 error / wrong length.
  int peer_receive(hal::CanFrame& f) const {
    can_frame raw{};
    const ssize_t n = ::recv(peer, &raw, sizeof raw, MSG_DONTWAIT);
    if (n < 0) return 0;
    if (n != static_cast<ssize_t>(sizeof raw)) return -1;
    f = hal::CanFrame{};
    f.id = raw.can_id;
    f.dlc = raw.can_dlc;
    std::memcpy(f.data, raw.data, 8);
    return 1;
  }
};

}  // namespace sdpslam::test
