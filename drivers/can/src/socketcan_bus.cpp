#include "sdpslam/drivers/socketcan_bus.h"

#include <errno.h>
#include <fcntl.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <time.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>

#include "sdpslam/drivers/linux_clock.h"

#ifndef SO_RXQ_OVFL
#define SO_RXQ_OVFL 40
#endif

namespace sdpslam::drivers {

static_assert(sizeof(struct can_frame) == 16, "CAN_RAW carries 16-byte frames");
static_assert(hal::CanFrame::kExtendedFlag == CAN_EFF_FLAG, "id layout follows can_id");
static_assert(hal::CanFrame::kRtrFlag == CAN_RTR_FLAG, "id layout follows can_id");
static_assert(hal::CanFrame::kErrorFlag == CAN_ERR_FLAG, "id layout follows can_id");

const char* to_string(SocketCanError e) {
  switch (e) {
    case SocketCanError::kNone: return "none";
    case SocketCanError::kBadLength: return "datagram is not one 16-byte can_frame";
    case SocketCanError::kDown: return "interface down";
    case SocketCanError::kPeerClosed: return "peer closed";
    case SocketCanError::kNoInterface: return "no such interface";
    case SocketCanError::kOs: return "system error";
  }
  return "?";
}

namespace {

bool is_down_errno(int e) { return e == ENETDOWN || e == ENXIO || e == ENODEV; }
bool is_peer_closed_errno(int e) { return e == EPIPE || e == ECONNRESET || e == ENOTCONN; }

}  // namespace

const char* describe_failure(SocketCanError e, int err, const char* interface_name, char* out, std::size_t size) {
  if (out == nullptr || size == 0U) return "";
  const char* name = interface_name != nullptr ? interface_name : "?";
  if (e == SocketCanError::kOs && (err == EAFNOSUPPORT || err == EPROTONOSUPPORT)) {
    std::snprintf(out, size, "the kernel has no CAN support (load the can and can_raw modules: modprobe can_raw)");
  } else if (e == SocketCanError::kNoInterface && (err == ENODEV || err == ENXIO)) {
    std::snprintf(out, size,
                  "interface %s does not exist (see `ip link`; is the adapter plugged in and its driver loaded?)", name);
  } else if (e == SocketCanError::kDown || (e == SocketCanError::kOs && is_down_errno(err))) {
    std::snprintf(out, size, "interface %s is down (ip link set %s up type can bitrate N)", name, name);
  } else if (e == SocketCanError::kPeerClosed) {
    std::snprintf(out, size, "the other end of the CAN socket closed");
  } else if (e == SocketCanError::kBadLength) {
    std::snprintf(out, size, "a datagram on %s was not one CAN frame", name);
  } else if (e == SocketCanError::kNone) {
    std::snprintf(out, size, "no error");
  } else {
    std::snprintf(out, size, "%s on %s: %s", to_string(e), name, std::strerror(err));
  }
  return out;
}

SocketCanBus::SocketCanBus(const SocketCanOptions& options, const hal::MonotonicClock& clock)
    : options_(options), clock_(clock) {
  options_.interface_name[sizeof options_.interface_name - 1] = '\0';
  if (options_.filter_count < 0) options_.filter_count = 0;
  if (options_.filter_count > SocketCanOptions::kMaxFilters) {
    options_.filter_count = SocketCanOptions::kMaxFilters;
  }
  last_open_attempt_us_ = clock_.now_us();
  if (open_interface()) {
    ever_opened_ = true;
    state_ = hal::CanBusState::kActive;
  } else {
    stats_.down_count++;
  }
}

SocketCanBus::SocketCanBus(AdoptFd adopted, const SocketCanOptions& options,
                           const hal::MonotonicClock& clock)
    : options_(options), clock_(clock), fd_(adopted.fd), adopted_(true) {
  if (options_.filter_count < 0) options_.filter_count = 0;
  if (options_.filter_count > SocketCanOptions::kMaxFilters) {
    options_.filter_count = SocketCanOptions::kMaxFilters;
  }
  if (fd_ < 0) {
    state_ = hal::CanBusState::kDown;
    last_error_ = SocketCanError::kDown;
    stats_.down_count++;
    return;
  }
  const int flags = ::fcntl(fd_, F_GETFL, 0);
  if (flags >= 0) ::fcntl(fd_, F_SETFL, flags | O_NONBLOCK);
  configure_socket();  // failures tolerated: an AF_UNIX fd has no CAN options
  ever_opened_ = true;
  state_ = hal::CanBusState::kActive;
}

SocketCanBus::~SocketCanBus() { close_fd(); }

void SocketCanBus::close_fd() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  overflow_base_ += overflow_socket_;
  overflow_socket_ = 0;
  kernel_filter_ = false;
  kernel_timestamps_ = false;
}

void SocketCanBus::configure_socket() {
  can_filter filters[SocketCanOptions::kMaxFilters];
  for (int i = 0; i < options_.filter_count; ++i) {
    filters[i].can_id = options_.filters[i].id;
    filters[i].can_mask = options_.filters[i].mask;
  }
  if (options_.filter_count > 0) {
    kernel_filter_ = ::setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_FILTER, filters,
                                  static_cast<socklen_t>(sizeof(can_filter) *
                                                         static_cast<unsigned>(options_.filter_count))) == 0;
  }
  const can_err_mask_t err_mask = options_.error_mask;
  ::setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &err_mask, sizeof err_mask);
  const int one = 1;
  if (options_.kernel_timestamps) {
    kernel_timestamps_ = ::setsockopt(fd_, SOL_SOCKET, SO_TIMESTAMP, &one, sizeof one) == 0;
  }
  ::setsockopt(fd_, SOL_SOCKET, SO_RXQ_OVFL, &one, sizeof one);
}

bool SocketCanBus::open_interface() {
  const int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) {
    last_error_ = SocketCanError::kOs;
    last_errno_ = errno;
    return false;
  }
  ifreq ifr{};
  // ifr is zeroed, so the name stays terminated (memcpy: GCC -O2 rejects this strncpy).
  std::memcpy(ifr.ifr_name, options_.interface_name, ::strnlen(options_.interface_name, IFNAMSIZ - 1));
  if (::ioctl(fd, SIOCGIFINDEX, &ifr) < 0) {
    last_error_ = SocketCanError::kNoInterface;
    last_errno_ = errno;
    ::close(fd);
    return false;
  }
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = ifr.ifr_ifindex;
  fd_ = fd;
  configure_socket();  // options before bind: no unfiltered frames slip in
  if (::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) < 0) {
    last_error_ = is_down_errno(errno) ? SocketCanError::kDown : SocketCanError::kOs;
    last_errno_ = errno;
    close_fd();
    return false;
  }
  return true;
}

void SocketCanBus::go_down(SocketCanError why, int err) {
  last_error_ = why;
  last_errno_ = err;
  if (state_ != hal::CanBusState::kDown) stats_.down_count++;
  state_ = hal::CanBusState::kDown;
  // A CAN_RAW socket bound to a vanished ifindex never recovers: drop it and re-open.
  if (!adopted_) close_fd();
}

bool SocketCanBus::maybe_reopen() {
  if (state_ != hal::CanBusState::kDown) return true;
  if (adopted_) return false;
  const std::int64_t now = clock_.now_us();
  if (now - last_open_attempt_us_ < options_.reopen_interval_us) return false;
  last_open_attempt_us_ = now;
  stats_.reopen_attempts++;
  if (!open_interface()) return false;
  if (ever_opened_) stats_.reopen_count++;
  ever_opened_ = true;
  state_ = hal::CanBusState::kActive;
  last_error_ = SocketCanError::kNone;
  return true;
}

bool SocketCanBus::passes_filter(const hal::CanFrame& f) const {
  if (options_.filter_count == 0) return true;
  for (int i = 0; i < options_.filter_count; ++i) {
    const CanIdFilter& flt = options_.filters[i];
    if ((f.id & flt.mask) == (flt.id & flt.mask)) return true;
  }
  return false;
}

int SocketCanBus::send(const hal::CanFrame& frame) {
  if (!maybe_reopen()) {
    stats_.tx_while_down++;  // the bus going down is the event (down_count), not each retry
    return -1;
  }
  if (frame.dlc > hal::CanFrame::kMaxDataBytes || frame.is_error()) {
    last_error_ = SocketCanError::kOs;
    last_errno_ = EINVAL;
    stats_.tx_errors++;
    return -1;
  }
  can_frame raw{};
  raw.can_id = frame.id;
  raw.can_dlc = frame.dlc;
  std::memcpy(raw.data, frame.data, frame.dlc);
  const ssize_t n = ::send(fd_, &raw, sizeof raw, MSG_NOSIGNAL | MSG_DONTWAIT);
  if (n == static_cast<ssize_t>(sizeof raw)) {
    stats_.tx_frames++;
    return 1;
  }
  const int err = n < 0 ? errno : EIO;
  if (err == ENOBUFS || err == EAGAIN || err == EWOULDBLOCK) {
    stats_.tx_try_later++;
    return 0;
  }
  stats_.tx_errors++;
  if (is_down_errno(err)) {
    go_down(SocketCanError::kDown, err);
  } else if (is_peer_closed_errno(err)) {
    go_down(SocketCanError::kPeerClosed, err);
  } else {
    last_error_ = SocketCanError::kOs;
    last_errno_ = err;
  }
  return -1;
}

int SocketCanBus::receive(hal::CanFrame& out) {
  if (!maybe_reopen()) return -1;
  // Bounded: consumed error frames and filtered frames do not starve the caller forever.
  for (int guard = 0; guard < 64; ++guard) {
    // Room for more than one frame so a longer datagram shows up as a wrong length
    // instead of being silently truncated to 16 bytes.
    alignas(can_frame) unsigned char buf[sizeof(can_frame) + 64];
    alignas(cmsghdr) unsigned char control[CMSG_SPACE(sizeof(timeval)) + CMSG_SPACE(sizeof(std::uint32_t)) + 64];
    iovec iov{buf, sizeof buf};
    msghdr msg{};
    msg.msg_iov = &iov;
    msg.msg_iovlen = 1;
    msg.msg_control = control;
    msg.msg_controllen = sizeof control;
    const ssize_t n = ::recvmsg(fd_, &msg, MSG_DONTWAIT);
    if (n < 0) {
      const int err = errno;
      if (err == EAGAIN || err == EWOULDBLOCK || err == EINTR) return 0;
      stats_.rx_errors++;
      if (is_down_errno(err)) {
        go_down(SocketCanError::kDown, err);
      } else if (is_peer_closed_errno(err)) {
        go_down(SocketCanError::kPeerClosed, err);
      } else {
        last_error_ = SocketCanError::kOs;
        last_errno_ = err;
      }
      return -1;
    }
    if (n == 0 && adopted_) {  // SOCK_SEQPACKET end of stream: the peer closed
      stats_.rx_errors++;
      go_down(SocketCanError::kPeerClosed, 0);
      return -1;
    }
    std::int64_t stamp_us = 0;
    for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c != nullptr; c = CMSG_NXTHDR(&msg, c)) {
      if (c->cmsg_level != SOL_SOCKET) continue;
      if (c->cmsg_type == SO_TIMESTAMP && c->cmsg_len >= CMSG_LEN(sizeof(timeval))) {
        timeval tv;
        std::memcpy(&tv, CMSG_DATA(c), sizeof tv);
        stamp_us = realtime_to_monotonic_us(static_cast<std::int64_t>(tv.tv_sec) * 1000000 +
                                            tv.tv_usec);
      } else if (c->cmsg_type == SO_RXQ_OVFL && c->cmsg_len >= CMSG_LEN(sizeof(std::uint32_t))) {
        std::uint32_t drops;
        std::memcpy(&drops, CMSG_DATA(c), sizeof drops);
        overflow_socket_ = drops;
        stats_.rx_overflows = overflow_base_ + overflow_socket_;
      }
    }
    if (n != static_cast<ssize_t>(sizeof(can_frame)) || (msg.msg_flags & MSG_TRUNC) != 0) {
      stats_.bad_length_reads++;
      last_error_ = SocketCanError::kBadLength;
      last_errno_ = 0;
      return -1;
    }
    can_frame raw;
    std::memcpy(&raw, buf, sizeof raw);
    hal::CanFrame f;
    f.id = raw.can_id;
    f.dlc = raw.can_dlc > hal::CanFrame::kMaxDataBytes ? hal::CanFrame::kMaxDataBytes : raw.can_dlc;
    std::memcpy(f.data, raw.data, f.dlc);
    f.stamp_us = stamp_us != 0 ? stamp_us : clock_.now_us();
    if (f.is_error()) {
      account_error_frame(f);
      continue;
    }
    if (!passes_filter(f)) {
      stats_.rx_filtered++;
      continue;
    }
    // A frame received means the controller is on the bus again after bus-off.
    if (state_ == hal::CanBusState::kBusOff) state_ = hal::CanBusState::kActive;
    stats_.rx_frames++;
    out = f;
    return 1;
  }
  return 0;
}

void SocketCanBus::account_error_frame(const hal::CanFrame& f) {
  stats_.error_frames++;
  hal::CanErrorCounts& e = stats_.errors;
  const std::uint32_t cls = f.id & CAN_ERR_MASK;
  if (cls & CAN_ERR_TX_TIMEOUT) e.tx_timeout++;
  if (cls & CAN_ERR_LOSTARB) e.lost_arbitration++;
  if (cls & CAN_ERR_PROT) e.protocol++;
  if (cls & CAN_ERR_TRX) e.transceiver++;
  if (cls & CAN_ERR_ACK) e.no_ack++;
  if (cls & CAN_ERR_BUSERROR) e.bus_error++;
  if (cls & CAN_ERR_CRTL) {
    e.controller++;
    const std::uint8_t ctrl = f.dlc > 1 ? f.data[1] : 0;
    if (ctrl & (CAN_ERR_CRTL_RX_OVERFLOW | CAN_ERR_CRTL_TX_OVERFLOW)) e.controller_overflow++;
    if (ctrl & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) {
      e.passive++;
      if (state_ != hal::CanBusState::kDown) state_ = hal::CanBusState::kPassive;
    } else if (ctrl & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING)) {
      e.warning++;
      if (state_ != hal::CanBusState::kDown) state_ = hal::CanBusState::kWarning;
    }
#ifdef CAN_ERR_CRTL_ACTIVE
    if ((ctrl & CAN_ERR_CRTL_ACTIVE) && state_ != hal::CanBusState::kDown) {
      state_ = hal::CanBusState::kActive;
    }
#endif
  }
  if (cls & CAN_ERR_RESTARTED) {
    e.restarted++;
    if (state_ != hal::CanBusState::kDown) state_ = hal::CanBusState::kActive;
  }
  if (cls & CAN_ERR_BUSOFF) {
    e.bus_off++;
    if (state_ != hal::CanBusState::kDown) state_ = hal::CanBusState::kBusOff;
  }
}

int SocketCanBus::wait_readable(std::int64_t timeout_us) {
  if (timeout_us < 0) timeout_us = 0;
  if (state_ == hal::CanBusState::kDown) {
    if (adopted_) return -1;
    if (maybe_reopen()) return 1;  // re-opened: let the caller read
    // Sleep until the next allowed attempt (or the timeout) instead of spinning.
    const std::int64_t next = last_open_attempt_us_ + options_.reopen_interval_us - clock_.now_us();
    const std::int64_t sleep_us = next < timeout_us ? (next > 0 ? next : 0) : timeout_us;
    timespec ts{static_cast<time_t>(sleep_us / 1000000), static_cast<long>((sleep_us % 1000000) * 1000)};
    ::nanosleep(&ts, nullptr);
    return maybe_reopen() ? 1 : 0;
  }
  pollfd p{fd_, POLLIN, 0};
  const int timeout_ms = static_cast<int>((timeout_us + 999) / 1000);
  const int r = ::poll(&p, 1, timeout_ms);
  if (r < 0) {
    if (errno == EINTR) return 0;
    last_error_ = SocketCanError::kOs;
    last_errno_ = errno;
    return -1;
  }
  if (r == 0) return 0;
  // POLLHUP/POLLERR: let receive() read and classify the condition.
  return 1;
}

}  // namespace sdpslam::drivers
