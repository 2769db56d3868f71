#pragma once
// Hokuyo URG (URG-04LX, URG-04LX-UG01 and other SCIP 2.0 sensors) as a
// hal::RangeScanSource over any hal::ByteStream (protocols.md §1).
//
// Start sequence (re-run after every re-open of the stream and after a stall):
//   SCIP2.0 (status 00, the SCIP1.1 "0", or 0E from a sensor already in 2.0 are all fine)
//   -> QT (stops a stream left running) -> VV (identity) -> PP (geometry: AMIN, AMAX,
//   AFRT, ARES, DMIN, DMAX, SCAN) -> BM (00, or 02 = already on) -> MD<AMIN><AMAX><cluster>
//   continuous; each scan then arrives with status 99.
// A command without a valid reply within reply_timeout_us is re-sent up to max_retries
// times, then the whole sequence restarts. Broken replies (checksum, lost or truncated
// line, garbage) are dropped and counted; the parser resynchronises at the next reply.
// Scan stamps: the sensor's 24-bit ms stamp, unwrapped and mapped onto the host clock by
// scip2::SensorClock. Error codes (< 20) become 0 (invalid beam), never a range.
// Memory: fixed, inside the object (~12 KiB); no heap.
#include <cstdint>

#include "sdpslam/core/pose2.h"
#include "sdpslam/drivers/scip2.h"
#include "sdpslam/drivers/serial_laser_loop.h"
#include "sdpslam/hal/byte_stream.h"
#include "sdpslam/hal/clock.h"
#include "sdpslam/hal/range_scan_source.h"

namespace sdpslam::drivers {

struct UrgOptions {
  std::int64_t reply_timeout_us = 1000000;
  std::int64_t stall_timeout_us = 1000000;  // no scan for this long while streaming, with nothing left to read
  std::uint32_t max_retries = 3U;
  std::uint32_t cluster = 1U;  // steps merged per beam (1..99)
  Pose2 laser_in_base;
};

class UrgScip2Laser final : public SerialLaserLoop<UrgScip2Laser, 512U> {
 public:
  UrgScip2Laser(hal::ByteStream& stream, const hal::MonotonicClock& clock, const UrgOptions& options);

  // Geometry learnt from PP (zeros before the first PP reply).
  const scip2::SensorParams& sensor_params() const { return params_; }
  // PROD from VV ("" before it arrived).
  const char* product() const { return product_; }
  const scip2::ParserStats& parser_stats() const { return parser_.stats(); }

 private:
  friend class SerialLaserLoop<UrgScip2Laser, 512U>;
  enum class Step : std::uint8_t { kScip2, kQuit, kVersion, kParams, kLaserOn, kStream, kStreaming };
  // The loop's hooks (serial_laser_loop.h).
  void begin_sequence(std::int64_t now_us);
  void send_step(std::int64_t now_us);
  bool streaming() const { return step_ == Step::kStreaming; }
  bool drain(std::int64_t now_us, RangeScan& out);
  void on_reply_timeout(std::int64_t now_us) { retry_or_restart(now_us); }
  std::int64_t stall_timeout_us() const { return options_.stall_timeout_us; }
  void on_reply(std::int64_t now_us, RangeScan& out, bool* produced);
  void advance(std::int64_t now_us);
  void retry_or_restart(std::int64_t now_us);
  void sync_parser_stats();

  UrgOptions options_;
  scip2::Parser parser_;
  scip2::SensorClock sensor_clock_;
  scip2::SensorParams params_;
  char product_[scip2::kMaxParamValueChars + 1] = {};
  Step step_ = Step::kScip2;
  std::uint32_t retries_ = 0U;
};

}  // namespace sdpslam::drivers
