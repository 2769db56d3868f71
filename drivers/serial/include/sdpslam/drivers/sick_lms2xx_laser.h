#pragma once
// SICK LMS200/LMS291 as a hal::RangeScanSource over a hal::ByteStream whose line speed
// it controls (protocols.md §2).
//
// Start sequence (re-run after every re-open of the stream and after a stall):
//   1. host at 9600 baud (power-on default), stop streaming (20 25) -> ACK, A0 00. With
//      no answer the host probes 19200, 38400 and 500000 in turn (a scanner left at a
//      high rate by an earlier run).
//   2. if target_baud differs: baud switch (20 40/41/42/48) -> ACK, A0 00, then the HOST
//      changes its own speed (the scanner switches after sending A0).
//   3. scan variant 3B (angle, resolution) -> ACK, BB 01 ...
//   4. start streaming (20 24) -> ACK, A0 00; then B0 telegrams arrive continuously.
// A NAK or a timeout re-sends the request up to max_retries times, then the sequence
// restarts. Telegrams are accepted only with a valid CRC; the parser rescans after any
// corrupt candidate. Scan stamp: arrival of the last byte minus the telegram's time on
// the wire at the current rate (10 bits per byte). Distances 0 and the error codes
// >= 0x1FF7 become 0 (invalid beam). Memory: fixed, inside the object; no heap.
#include <cstdint>

#include "sdpslam/core/pose2.h"
#include "sdpslam/drivers/lms2xx.h"
#include "sdpslam/drivers/serial_laser_loop.h"
#include "sdpslam/hal/byte_stream.h"
#include "sdpslam/hal/clock.h"
#include "sdpslam/hal/range_scan_source.h"

namespace sdpslam::drivers {

struct SickOptions {
  std::uint32_t target_baud = 38400U;  // 9600, 19200, 38400 or 500000
  std::uint16_t angle_deg = 180U;      // 100 or 180
  std::uint16_t resolution_cdeg = 50U;  // 25, 50, 100 (1/100 deg)
  std::int64_t reply_timeout_us = 1000000;
  std::int64_t stall_timeout_us = 500000;  // no scan for this long while streaming, with nothing left to read
  std::uint32_t max_retries = 3U;
  Pose2 laser_in_base;
};

// False iff the options name a rate/variant the LMS2xx does not offer.
bool validate(const SickOptions& options);

class SickLms2xxLaser final : public SerialLaserLoop<SickLms2xxLaser, 1024U> {
 public:
  SickLms2xxLaser(hal::ByteStream& stream, const hal::MonotonicClock& clock, const SickOptions& options);
  const lms2xx::ParserStats& parser_stats() const { return parser_.stats(); }
  // Values per scan the configured variant yields (361 for 180 deg / 0.5 deg).
  std::uint32_t expected_values() const;

 private:
  friend class SerialLaserLoop<SickLms2xxLaser, 1024U>;
  enum class Step : std::uint8_t { kStop, kBaud, kVariant, kStream, kStreaming };
  // The loop's hooks (serial_laser_loop.h).
  void begin_sequence(std::int64_t now_us);
  void send_step(std::int64_t now_us);
  bool streaming() const { return step_ == Step::kStreaming; }
  bool drain(std::int64_t now_us, RangeScan& out);
  void on_reply_timeout(std::int64_t now_us) { retry_or_restart(now_us, true); }
  std::int64_t stall_timeout_us() const { return options_.stall_timeout_us; }
  void on_telegram(std::int64_t now_us, RangeScan& out, bool* produced);
  void step_done(std::int64_t now_us);
  void retry_or_restart(std::int64_t now_us, bool timed_out);
  void sync_parser_stats();

  SickOptions options_;
  lms2xx::Parser parser_{lms2xx::Parser::Source::kScanner};
  lms2xx::MeasuredValues values_;
  Step step_ = Step::kStop;
  std::uint32_t retries_ = 0U;
  std::uint32_t probe_index_ = 0U;
  std::uint64_t decode_error_count_ = 0U;  // valid-CRC B0 telegrams that fail decode_b0
};

}  // namespace sdpslam::drivers
