#pragma once
// hal::ByteStream on a Linux tty (UART, USB-serial, USB-ACM, pseudo-terminal) through
// POSIX termios, without libserialport (protocols.md §1 "Serial setup").
//
// - open(): O_RDWR|O_NOCTTY|O_NONBLOCK|O_CLOEXEC, TIOCEXCL, raw mode with explicit flags
//   (the cfmakeraw set: no ICANON/ECHO/ISIG/IEXTEN, no input/output processing, CS8 |
//   CREAD | CLOCAL, no parity/flow control), VMIN = 0, VTIME = 0, then both queues flushed.
// - Line speed: standard rates through cfsetispeed/cfsetospeed (B9600 ... B4000000);
//   any other rate (250000, 750000 for the URG) through termios2 + BOTHER (TCSETS2).
// - Hang-up: POLLHUP/POLLERR from poll, EIO/ENXIO/ENODEV from read/write (USB unplug,
//   pty master closed). read() == 0 is the normal "no data" answer of a VMIN=0 tty, so it
//   only counts as hang-up when poll confirms POLLHUP. The fd is closed at once.
// - Re-open: while hung up, wait_readable() re-opens the same path (so a udev symlink that
//   comes back pointing at a new node works) at most once per reopen_interval_us, with the
//   configured initial baud rate. stats().open_count increments on each success.
// No heap; no exceptions.
#include <cstddef>
#include <cstdint>

#include "sdpslam/hal/byte_stream.h"
#include "sdpslam/hal/clock.h"

namespace sdpslam::drivers {

struct SerialOptions {
  static constexpr std::size_t kMaxPathChars = 127U;
  const char* path = "";               // copied at construction
  std::uint32_t baud = 115200U;        // initial rate, also used after a re-open
  std::int64_t reopen_interval_us = 500000;
  bool reopen = true;                  // re-open after a hang-up
};

// True iff the rate has a termios Bxxx constant (no termios2 needed).
bool is_standard_baud(std::uint32_t baud);
// Output line speed the kernel holds for this tty (TCGETS2), 0 on error. For diagnostics
// and tests (a pty stores whatever rate was set).
std::uint32_t tty_baud_rate(int fd);

class SerialPort final : public hal::ByteStream {
 public:
  SerialPort(const SerialOptions& options, const hal::MonotonicClock& clock);
  ~SerialPort() override;
  SerialPort(const SerialPort&) = delete;
  SerialPort& operator=(const SerialPort&) = delete;

  // Opens and configures the device. False iff any step failed: last_errno() and
  // last_error_step() say which and why; the port is then kClosed, or kHungUp when
  // options.reopen is set (so wait_readable() keeps trying, as after an unplug).
  bool open();
  // Closes the device; no re-open follows (state kClosed).
  void close();

  std::int32_t read(std::uint8_t* buf, std::size_t max) override;
  std::int32_t write(const std::uint8_t* buf, std::size_t n) override;
  int wait_readable(std::int64_t timeout_us) override;
  void flush_input() override;
  bool set_baud_rate(std::uint32_t baud) override;
  std::uint32_t baud_rate() const override { return baud_; }
  hal::StreamState state() const override { return state_; }
  const hal::ByteStreamStats& stats() const override { return stats_; }

  int fd() const { return fd_; }
  const char* path() const { return path_; }
  int last_errno() const { return last_errno_; }
  // Name of the step that failed last ("open", "tcgetattr", "tcsetattr", "termios2", ...).
  const char* last_error_step() const { return last_error_step_; }

 private:
  bool open_device();
  bool apply_baud(std::uint32_t baud);
  void hang_up();
  bool fail(const char* step, int err);

  SerialOptions options_;
  char path_[SerialOptions::kMaxPathChars + 1U] = {};
  const hal::MonotonicClock& clock_;
  int fd_ = -1;
  std::uint32_t baud_ = 0U;
  hal::StreamState state_ = hal::StreamState::kClosed;
  std::int64_t last_attempt_us_ = 0;
  int last_errno_ = 0;
  const char* last_error_step_ = "";
  hal::ByteStreamStats stats_;
};

}  // namespace sdpslam::drivers
