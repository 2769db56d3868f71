// termios serial port (see serial_port.h for the contract). Non-standard rates go through
// termios2_baud.cpp, which cannot share this file's <termios.h>.
#include "sdpslam/drivers/serial_port.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>

#include "termios2_baud.h"

namespace sdpslam::drivers {
namespace {

struct BaudCode {
  std::uint32_t baud;
  speed_t code;
};
constexpr BaudCode kStandardRates[] = {
    {1200U, B1200},       {2400U, B2400},       {4800U, B4800},       {9600U, B9600},
    {19200U, B19200},     {38400U, B38400},     {57600U, B57600},     {115200U, B115200},
    {230400U, B230400},   {460800U, B460800},   {500000U, B500000},   {576000U, B576000},
    {921600U, B921600},   {1000000U, B1000000}, {1152000U, B1152000}, {1500000U, B1500000},
    {2000000U, B2000000}, {3000000U, B3000000}, {4000000U, B4000000},
};

bool standard_code(std::uint32_t baud, speed_t* code) {
  for (const BaudCode& r : kStandardRates) {
    if (r.baud == baud) {
      *code = r.code;
      return true;
    }
  }
  return false;
}

bool is_hangup_errno(int e) { return e == EIO || e == ENXIO || e == ENODEV || e == EPIPE || e == EBADF; }

timespec to_timespec(std::int64_t us) {
  if (us < 0) us = 0;
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(us / 1000000);
  ts.tv_nsec = static_cast<long>((us % 1000000) * 1000);
  return ts;
}

}  // namespace

bool is_standard_baud(std::uint32_t baud) {
  speed_t code = 0;
  return standard_code(baud, &code);
}

std::uint32_t tty_baud_rate(int fd) { return detail::get_termios2_baud(fd); }

SerialPort::SerialPort(const SerialOptions& options, const hal::MonotonicClock& clock)
    : options_(options), clock_(clock) {
  const std::size_t n = std::strlen(options.path);
  const std::size_t keep = n < SerialOptions::kMaxPathChars ? n : SerialOptions::kMaxPathChars;
  std::memcpy(path_, options.path, keep);
  path_[keep] = '\0';
  options_.path = path_;
}

SerialPort::~SerialPort() {
  if (fd_ >= 0) ::close(fd_);
}

bool SerialPort::fail(const char* step, int err) {
  last_error_step_ = step;
  last_errno_ = err;
  if (fd_ >= 0) {
    ::close(fd_);
    fd_ = -1;
  }
  return false;
}

bool SerialPort::open_device() {
  if (path_[0] == '\0') return fail("path", ENOENT);
  fd_ = ::open(path_, O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) return fail("open", errno);
  (void)::ioctl(fd_, TIOCEXCL);  // best effort: keep other programs off the port
  termios tio{};
  if (::tcgetattr(fd_, &tio) != 0) return fail("tcgetattr", errno);
  // The cfmakeraw() set, spelled out (termios(3)).
  tio.c_iflag &= ~static_cast<tcflag_t>(IGNBRK | BRKINT | PARMRK | ISTRIP | INLCR | IGNCR | ICRNL | IXON |
                                        IXOFF | IXANY | INPCK);
  tio.c_oflag &= ~static_cast<tcflag_t>(OPOST);
  tio.c_lflag &= ~static_cast<tcflag_t>(ECHO | ECHONL | ICANON | ISIG | IEXTEN);
  tio.c_cflag &= ~static_cast<tcflag_t>(CSIZE | PARENB | CSTOPB | CRTSCTS);
  tio.c_cflag |= static_cast<tcflag_t>(CS8 | CREAD | CLOCAL);
  tio.c_cc[VMIN] = 0;
  tio.c_cc[VTIME] = 0;
  if (::tcsetattr(fd_, TCSANOW, &tio) != 0) return fail("tcsetattr", errno);
  if (!apply_baud(options_.baud)) return fail(last_error_step_, last_errno_);
  (void)::tcflush(fd_, TCIOFLUSH);
  baud_ = options_.baud;
  return true;
}

bool SerialPort::apply_baud(std::uint32_t baud) {
  speed_t code = 0;
  if (standard_code(baud, &code)) {
    termios tio{};
    if (::tcgetattr(fd_, &tio) != 0) {
      last_error_step_ = "tcgetattr";
      last_errno_ = errno;
      return false;
    }
    if (::cfsetispeed(&tio, code) != 0 || ::cfsetospeed(&tio, code) != 0 || ::tcsetattr(fd_, TCSANOW, &tio) != 0) {
      last_error_step_ = "cfsetspeed";
      last_errno_ = errno;
      return false;
    }
    return true;
  }
  if (baud == 0U) {
    last_error_step_ = "baud";
    last_errno_ = EINVAL;
    return false;
  }
  const int err = detail::set_termios2_baud(fd_, baud);
  if (err != 0) {
    last_error_step_ = "termios2";
    last_errno_ = err;
    return false;
  }
  return true;
}

bool SerialPort::open() {
  if (fd_ >= 0) close();
  last_attempt_us_ = clock_.now_us();
  if (open_device()) {
    state_ = hal::StreamState::kOpen;
    ++stats_.open_count;
    return true;
  }
  state_ = options_.reopen ? hal::StreamState::kHungUp : hal::StreamState::kClosed;
  return false;
}

void SerialPort::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  state_ = hal::StreamState::kClosed;
}

void SerialPort::hang_up() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  state_ = options_.reopen ? hal::StreamState::kHungUp : hal::StreamState::kClosed;
  ++stats_.hangup_count;
  last_attempt_us_ = clock_.now_us();
}

std::int32_t SerialPort::read(std::uint8_t* buf, std::size_t max) {
  if (state_ != hal::StreamState::kOpen) return -1;
  if (max == 0U) return 0;
  if (max > 0x7FFFFFFFU) max = 0x7FFFFFFFU;
  const ssize_t n = ::read(fd_, buf, max);
  if (n > 0) {
    stats_.bytes_read += static_cast<std::uint64_t>(n);
    return static_cast<std::int32_t>(n);
  }
  if (n == 0) {
    // VMIN=0: 0 is "nothing now" unless the line is gone.
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, 0) == 1 && (p.revents & (POLLHUP | POLLERR | POLLNVAL)) != 0) {
      hang_up();
      return -1;
    }
    return 0;
  }
  const int e = errno;
  if (e == EAGAIN || e == EWOULDBLOCK || e == EINTR) return 0;
  if (is_hangup_errno(e)) {
    hang_up();
    return -1;
  }
  ++stats_.read_error_count;
  last_errno_ = e;
  last_error_step_ = "read";
  return 0;
}

std::int32_t SerialPort::write(const std::uint8_t* buf, std::size_t n) {
  if (state_ != hal::StreamState::kOpen) return -1;
  if (n == 0U) return 0;
  if (n > 0x7FFFFFFFU) n = 0x7FFFFFFFU;
  const ssize_t w = ::write(fd_, buf, n);
  if (w >= 0) {
    stats_.bytes_written += static_cast<std::uint64_t>(w);
    if (static_cast<std::size_t>(w) < n) ++stats_.short_write_count;
    return static_cast<std::int32_t>(w);
  }
  const int e = errno;
  if (e == EAGAIN || e == EWOULDBLOCK || e == EINTR) return 0;
  if (is_hangup_errno(e)) {
    hang_up();
    return -1;
  }
  ++stats_.write_error_count;
  last_errno_ = e;
  last_error_step_ = "write";
  return 0;
}

int SerialPort::wait_readable(std::int64_t timeout_us) {
  const std::int64_t deadline = clock_.now_us() + (timeout_us > 0 ? timeout_us : 0);
  for (;;) {
    const std::int64_t now = clock_.now_us();
    if (state_ != hal::StreamState::kOpen) {
      if (state_ != hal::StreamState::kHungUp) return -1;
      const std::int64_t next = last_attempt_us_ + options_.reopen_interval_us;
      if (now >= next) {
        ++stats_.reopen_attempt_count;
        last_attempt_us_ = now;
        if (open_device()) {
          state_ = hal::StreamState::kOpen;
          ++stats_.open_count;
          continue;
        }
      }
      if (now >= deadline) return -1;
      const std::int64_t wake = (next > now && next < deadline) ? next : deadline;
      const timespec ts = to_timespec(wake - now);
      (void)::ppoll(nullptr, 0, &ts, nullptr);
      continue;
    }
    pollfd p{fd_, POLLIN, 0};
    const timespec ts = to_timespec(deadline - now);
    const int r = ::ppoll(&p, 1, &ts, nullptr);
    if (r < 0) {
      if (errno == EINTR) continue;
      ++stats_.read_error_count;
      last_errno_ = errno;
      last_error_step_ = "poll";
      return 0;
    }
    if (r == 0) return 0;
    if ((p.revents & POLLIN) != 0) return 1;  // data first; read() reports a hang-up after it
    if ((p.revents & (POLLHUP | POLLERR | POLLNVAL)) != 0) {
      hang_up();
      continue;
    }
    return 0;
  }
}

void SerialPort::flush_input() {
  if (state_ != hal::StreamState::kOpen) return;
  if (::tcflush(fd_, TCIFLUSH) == 0) ++stats_.flush_count;
}

bool SerialPort::set_baud_rate(std::uint32_t baud) {
  if (state_ != hal::StreamState::kOpen) return false;
  if (!apply_baud(baud)) return false;
  baud_ = baud;
  return true;
}

}  // namespace sdpslam::drivers
