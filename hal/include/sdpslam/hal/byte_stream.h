#pragma once
// A bidirectional byte stream to a device (serial port, USB-ACM, pipe, socket), after
// ArduPilot's AP_HAL::UARTDriver: the interface only, no OS header. The Linux termios
// implementation is drivers::SerialPort; tests use pseudo-terminals or fakes.
//
// Every call is non-blocking except wait_readable(), which blocks for at most its
// timeout. Results follow one tri-state convention (as AP_HAL's CAN send/receive):
//   > 0 : that many bytes were transferred;
//   = 0 : nothing could be transferred now (no data yet / output buffer full) — retry;
//   < 0 : the stream is not usable: state() says whether it was closed or hung up.
// A hang-up (device unplugged, peer gone) is detected by the implementation, counted in
// stats().hangup_count, and moves state() to kHungUp. An implementation that can re-open
// its device does so by itself (rate-limited) from wait_readable(); each successful
// (re-)open increments stats().open_count, which is how a protocol driver notices that
// it must start its sensor again.
#include <cstddef>
#include <cstdint>

namespace sdpslam::hal {

enum class StreamState : std::uint8_t {
  kClosed,  // never opened, or closed by its owner
  kOpen,    // usable
  kHungUp,  // the device went away; the implementation may re-open it later
};

// Counters that never decrease (o1heap-style diagnostics).
struct ByteStreamStats {
  std::uint64_t bytes_read = 0U;
  std::uint64_t bytes_written = 0U;
  std::uint64_t read_error_count = 0U;      // read failures other than hang-up
  std::uint64_t write_error_count = 0U;     // write failures other than hang-up
  std::uint64_t short_write_count = 0U;     // write() accepted fewer bytes than offered
  std::uint64_t hangup_count = 0U;          // transitions to kHungUp
  std::uint64_t open_count = 0U;            // successful opens, the first one included
  std::uint64_t reopen_attempt_count = 0U;  // re-open attempts after a hang-up
  std::uint64_t flush_count = 0U;           // flush_input() calls that discarded input
};

class ByteStream {
 public:
  virtual ~ByteStream() = default;

  // Copies up to `max` received bytes into `buf`. Returns the count (> 0), 0 when no byte
  // is waiting, or a negative value when state() != kOpen (hang-up detected now or before).
  virtual std::int32_t read(std::uint8_t* buf, std::size_t max) = 0;

  // Queues up to `n` bytes for transmission. Returns how many were accepted (may be fewer
  // than n: short_write_count bumps), 0 when the output buffer is full, negative when
  // state() != kOpen.
  virtual std::int32_t write(const std::uint8_t* buf, std::size_t n) = 0;

  // Blocks until input is readable or `timeout_us` (>= 0) elapsed. Returns 1 when
  // readable, 0 on timeout, negative when the stream is (still) not open at the end of the
  // wait. While hung up, an implementation that can re-open tries to (rate-limited) and
  // returns 1/0 as usual once it succeeded.
  virtual int wait_readable(std::int64_t timeout_us) = 0;

  // Discards every byte received but not yet read (tcflush(TCIFLUSH) on a tty).
  virtual void flush_input() = 0;

  // Changes the line speed in bits/s. Returns false iff the rate is not supported or the
  // stream is not open. Streams without a line speed (pipes, USB-ACM ignore it) return true.
  virtual bool set_baud_rate(std::uint32_t baud) = 0;
  // The line speed last set successfully (0 when unknown / not applicable).
  virtual std::uint32_t baud_rate() const = 0;

  virtual StreamState state() const = 0;
  virtual const ByteStreamStats& stats() const = 0;
};

}  // namespace sdpslam::hal
