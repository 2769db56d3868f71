#pragma once
// A source of complete planar laser scans (a rangefinder driver, a log replayer), after
// ArduPilot's AP_RangeFinder backends: the interface only, no OS header.
//
// poll() hands out one finished RangeScan at a time. Its stamp_us is on the monotonic
// clock of the program (hal::MonotonicClock) and is the best estimate of when the scan
// was measured (not when its last byte arrived). Beams follow RangeScan's documented
// semantics: sensor error codes become 0 (invalid), never a range. A scan that failed any
// integrity check (checksum, CRC, count, framing) never comes out of poll(): it is
// counted in stats() instead.
#include <cstdint>

#include "sdpslam/core/range_scan.h"

namespace sdpslam::hal {

enum class RangeSourceHealth : std::uint8_t {
  kStarting,      // configuring the sensor (handshake, geometry, start of streaming)
  kStreaming,     // scans are arriving
  kStalled,       // streaming was started but no good scan arrived within the stall timeout
  kDisconnected,  // the byte stream is hung up / closed; waiting for it to come back
};

// Counters that never decrease. The *_error_count fields count rejected replies or
// telegrams (one per bad unit, not per bad byte).
struct RangeSourceStats {
  std::uint64_t scan_count = 0U;            // scans handed out by poll()
  std::uint64_t dropped_scan_count = 0U;    // scan data received but rejected
  std::uint64_t checksum_error_count = 0U;  // SCIP line checksum / SICK CRC mismatches
  std::uint64_t framing_error_count = 0U;   // malformed line/telegram, wrong value count, ...
  std::uint64_t garbage_byte_count = 0U;    // bytes discarded while resynchronising
  std::uint64_t resync_count = 0U;          // times the decoder had to hunt for a frame start
  std::uint64_t sensor_error_count = 0U;    // error status replies from the sensor
  std::uint64_t nak_count = 0U;             // NAKs (SICK)
  std::uint64_t timeout_count = 0U;         // command replies that did not come in time
  std::uint64_t stall_count = 0U;           // streaming stalls (no scan within the timeout)
  std::uint64_t disconnect_count = 0U;      // hang-ups of the byte stream seen by the driver
  std::uint64_t restart_count = 0U;         // sensor start sequences run after the first
};

class RangeScanSource {
 public:
  virtual ~RangeScanSource() = default;

  // Runs the driver for at most `timeout_us` (>= 0). Returns 1 when a complete scan was
  // written to `out`, 0 when none was finished in time, negative when the underlying
  // stream is disconnected (call again later: re-opening and restarting are automatic).
  // `out` is only written when 1 is returned.
  virtual int poll(RangeScan& out, std::int64_t timeout_us) = 0;

  virtual RangeSourceHealth health() const = 0;
  virtual const RangeSourceStats& stats() const = 0;
};

}  // namespace sdpslam::hal
