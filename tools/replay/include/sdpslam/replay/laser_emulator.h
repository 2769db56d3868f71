#pragma once
// Laser sensors emulated from a log, for hardware-in-the-loop replay: the protocol
// engines (bytes from the host in, bytes to the host out, on a caller-given clock; no
// I/O) and the pseudo-terminal that carries them (LaserPty).
//
// Timing: scan k of the log is due at ReplayTimeline::due_us(stamp_k) on the player's
// monotonic clock, i.e. at its recorded time scaled by 1/speed. A scan is served only
// while the host has streaming switched on; one that falls due while it is off is
// counted in not_requested. Scans are sent in order, each at most once; when the engine
// is woken so late that the next scan is also due, the older one is dropped (a real
// sensor never sends an old scan) and counted; a scan sent more than late_threshold_us
// after its time is counted late.
//
// SCIP 2.0 (protocols.md §1): answers SCIP2.0 (first time "0" as a URG-04LX switching
// from SCIP1.1, then "0E"), VV, PP, II, BM (00 / 02 already on), QT, RS, MD/MS
// (continuous or nn scans; the skip field is accepted and ignored), anything else 0E.
// Geometry advertised in PP (scip_geometry_for): the smallest integer k >= 1 for which
// both ARES = k·2π/increment and AFRT = k·(−angle_min)/increment are integers; beam i owns
// steps AMIN + k·i .. AMIN + k·i + k − 1, AMIN = 0 (44 with AFRT 384 for a grid equal to
// the URG-04LX's, so such logs get the sensor's own numbers), AMAX = AMIN + k·n − 1. A driver asking MD<AMIN><AMAX> with cluster k therefore
// receives exactly the log's n beams at the log's angles (URG-04LX logs: k = 1, the
// sensor's own 1024/384/44/725; CARMEN 180-beam FLASER: k = 2, ARES 716, AFRT 179,
// AMIN 0, AMAX 359). A cluster value is the smallest valid (>= 20 mm) value of its steps,
// or the first step's error code when none is valid (as the URG does).
// Ranges: round(range_m · 1000) mm, 3-char encoding, capped at 262143. Beams at or
// beyond the log's range_max go out as their value (>= DMAX, so the driver classifies
// them as no-return); invalid beams (0, NaN, below 20 mm) as error code 0 ... 19, i.e.
// their rounded mm value when below 20, else 0: the driver maps both to 0 (invalid).
// DMIN = 20, DMAX = round(range_max_m · 1000). Timestamps: 24-bit ms counter of the
// sensor's own clock (the player clock in ms; it wraps after 4.66 h).
//
// SICK LMS2xx (protocols.md §2): power-on 9600 baud; 20 40/41/42/48 baud switch (the
// scanner changes speed after its A0 reply), 20 24 / 20 25 start/stop streaming, 31
// status (B1 reply), 3B variant (180°/1°, 180°/0.5°, 100°/1°, 0.5°, 0.25°; others refused
// with BB 00), unknown requests NAK. While the host tty's line speed differs from the
// scanner's, bytes are lost both ways, as on a real line. B0 telegrams carry the
// variant's values (181 or 361 for 180°) in mm units (count word bit 14): value i at
// angle −fov/2 + i·resolution takes the log beam nearest in angle (0 = no echo outside
// the log's field of view or for invalid beams); ranges of 8183 mm and more (beyond the
// 13-bit mm range) go out as the overflow code 0x1FF7. The last byte of a telegram is
// written at due + its time on the wire at the current rate (10 bits per byte), so a
// driver stamping "last byte − wire time" recovers the scan's time.
#include <cstdint>
#include <string>
#include <vector>

#include "sdpslam/core/range_scan.h"
#include "sdpslam/drivers/lms2xx.h"

namespace sdpslam::replay {

struct ReplayScan {
  std::int64_t stamp_us = 0;  // the log's time base
  RangeScan scan;
};

// Maps log time onto the player's monotonic clock: due = play_start + (t − log_start)/speed.
struct ReplayTimeline {
  std::int64_t log_start_us = 0;
  std::int64_t play_start_us = 0;
  double speed = 1.0;  // > 0
  std::int64_t due_us(std::int64_t log_stamp_us) const {
    return play_start_us +
           static_cast<std::int64_t>(static_cast<double>(log_stamp_us - log_start_us) / speed);
  }
};

struct LaserReplayStats {
  std::uint64_t commands = 0;           // host requests understood
  std::uint64_t unknown_commands = 0;   // answered 0E / NAK
  std::uint64_t scans_served = 0;
  std::uint64_t scans_late = 0;         // served more than late_threshold_us after due
  std::uint64_t scans_dropped = 0;      // overtaken by the next scan, or the line was down
  std::uint64_t scans_not_requested = 0;  // due while streaming was off
  std::uint64_t bytes_lost_line_speed = 0;  // SICK: bytes lost to a line-speed mismatch
  std::int64_t max_lateness_us = 0;
};

class LaserEngine {
 public:
  LaserEngine(const std::vector<ReplayScan>& scans, const ReplayTimeline& timeline);
  virtual ~LaserEngine() = default;
  // Bytes the host wrote, received at now_us; host_baud is the line speed the host's
  // tty is set to (0 = unknown: assume it matches).
  virtual void on_host_bytes(const std::uint8_t* data, std::size_t n, std::int64_t now_us,
                             std::uint32_t host_baud) = 0;
  // Emits whatever is due at now_us into the output buffer.
  void advance(std::int64_t now_us, std::uint32_t host_baud);
  // When advance() next has something to do (INT64_MAX: nothing scheduled).
  std::int64_t next_wake_us() const;
  // True once every scan has been served, dropped or passed unrequested.
  bool done() const { return next_scan_ >= scans_.size(); }
  std::vector<std::uint8_t>& output() { return out_; }
  const LaserReplayStats& stats() const { return stats_; }
  void set_timeline(const ReplayTimeline& t) { timeline_ = t; }
  std::int64_t late_threshold_us = 5000;

 protected:
  // Emit scan k (its send time is send_us); return false if the line cannot carry it.
  virtual bool emit_scan(const ReplayScan& s, std::int64_t send_us, std::uint32_t host_baud) = 0;
  virtual bool streaming() const = 0;
  // Delay between a scan's due time and the moment its last byte is written.
  virtual std::int64_t send_delay_us() const { return 0; }
  void put(const std::string& s) { out_.insert(out_.end(), s.begin(), s.end()); }
  void put(const std::uint8_t* b, std::size_t n) { out_.insert(out_.end(), b, b + n); }

  const std::vector<ReplayScan>& scans_;
  ReplayTimeline timeline_;
  std::size_t next_scan_ = 0;
  std::vector<std::uint8_t> out_;
  LaserReplayStats stats_;
};

// Step geometry a SCIP emulator advertises for a log's scans (see header comment).
struct ScipGeometry {
  std::uint32_t ares = 0, afrt = 0, amin = 0, amax = 0;
  std::uint32_t steps_per_beam = 1;  // k: the cluster a driver should ask for
  std::uint32_t beam_count = 0;
  std::uint32_t dmin_mm = 20, dmax_mm = 0;
  std::uint32_t scan_rpm = 600;
};
// False iff no k <= 16 puts the log's grid on integer steps (*error says why) or the
// geometry is degenerate (no beams, increment <= 0).
bool scip_geometry_for(const ScanGeometry& g, std::uint32_t beam_count, ScipGeometry* out,
                       std::string* error);
// mm value the emulator sends for a log range (see header comment).
std::uint32_t scip_value_mm(float range_m);

class ScipEngine final : public LaserEngine {
 public:
  // `geometry` from scip_geometry_for on the first scan; every scan must have the same
  // beam count (the caller checks).
  ScipEngine(const std::vector<ReplayScan>& scans, const ReplayTimeline& timeline, const ScipGeometry& geometry);
  void on_host_bytes(const std::uint8_t* data, std::size_t n, std::int64_t now_us, std::uint32_t host_baud) override;
  const ScipGeometry& geometry() const { return geo_; }

 private:
  bool emit_scan(const ReplayScan& s, std::int64_t send_us, std::uint32_t host_baud) override;
  bool streaming() const override { return streaming_; }
  void handle(const std::string& cmd);
  void reply(const std::string& echo, const char* status, const std::string& payload = "");
  std::uint32_t step_value(const ReplayScan& s, std::uint32_t step) const;

  ScipGeometry geo_;
  std::string line_;
  bool scip2_ = false;
  bool laser_on_ = false;
  bool streaming_ = false;
  std::string md_cmd_;        // the MD/MS command being served
  std::uint32_t md_start_ = 0, md_end_ = 0, md_cluster_ = 1, md_chars_ = 3;
  std::uint32_t md_remaining_ = 0;  // 0 = continuous
};

class SickEngine final : public LaserEngine {
 public:
  SickEngine(const std::vector<ReplayScan>& scans, const ReplayTimeline& timeline);
  void on_host_bytes(const std::uint8_t* data, std::size_t n, std::int64_t now_us, std::uint32_t host_baud) override;
  std::uint32_t baud() const { return baud_; }
  std::uint16_t angle_deg() const { return angle_deg_; }
  std::uint16_t resolution_cdeg() const { return res_cdeg_; }
  // Values of the current variant for scan s (raw words, mm units).
  std::vector<std::uint16_t> values_for(const RangeScan& s) const;

 private:
  bool emit_scan(const ReplayScan& s, std::int64_t send_us, std::uint32_t host_baud) override;
  bool streaming() const override { return streaming_; }
  std::int64_t send_delay_us() const override;
  void reply(const std::vector<std::uint8_t>& body);
  void handle();

  std::uint32_t baud_ = 9600;
  bool streaming_ = false;
  std::uint16_t angle_deg_ = 180;
  std::uint16_t res_cdeg_ = 50;
  drivers::lms2xx::Parser parser_{drivers::lms2xx::Parser::Source::kHost};
};

// A pseudo-terminal carrying a LaserEngine: openpty(), the slave set raw and kept open,
// a symlink `link_path` -> slave device (replacing an existing symlink, refusing to
// replace anything else). Single-threaded: pump() from the player loop.
class LaserPty {
 public:
  LaserPty() = default;
  ~LaserPty();
  LaserPty(const LaserPty&) = delete;
  LaserPty& operator=(const LaserPty&) = delete;
  bool open(const std::string& link_path, std::string* error);
  // Reads what the host wrote, advances the engine, writes its output (what the pty
  // cannot take now stays queued; more than kMaxQueued bytes are dropped and counted).
  void pump(LaserEngine& engine, std::int64_t now_us);
  int master_fd() const { return master_; }
  std::uint32_t host_baud() const;
  bool has_queued_output() const { return !queued_.empty(); }
  std::uint64_t bytes_dropped() const { return bytes_dropped_; }
  const std::string& slave_name() const { return slave_name_; }
  static constexpr std::size_t kMaxQueued = 1U << 20;

 private:
  int master_ = -1;
  int slave_ = -1;
  std::string link_;
  std::string slave_name_;
  std::vector<std::uint8_t> queued_;
  std::uint64_t bytes_dropped_ = 0;
};

}  // namespace sdpslam::replay
