#pragma once
// The poll loop the serial lasers share (UrgScip2Laser, SickLms2xxLaser): a
// hal::RangeScanSource over a hal::ByteStream that runs a start sequence of commands
// and replies, then streams scans. The protocol is the driver's; the loop is this:
//   - stream closed: counted once as a disconnect, health kDisconnected, the bytes
//     pending dropped; wait for the stream to re-open (ByteStream re-opens it);
//   - stream (re-)opened, or first call: the start sequence (re)starts (a re-open after
//     the first is a restart);
//   - bytes pending: the driver parses them, and a finished scan is returned at once;
//   - no command in flight and not streaming: the driver sends the next step;
//   - nothing left to read: only then may silence count as a reply timeout (the driver
//     retries or restarts) or, while streaming, a stall (the sequence restarts, health
//     kStalled). A poll that was held off (a loaded machine, a long SLAM step) reads
//     its backlog first; judged before that, a healthy sensor would be restarted and its
//     buffered scans thrown away;
//   - otherwise wait for bytes until the caller's deadline, a reply's deadline or the
//     stall deadline, whichever comes first.
//
// CRTP: Driver derives from SerialLaserLoop<Driver, kRxBytes>, declares it a friend and
// provides
//   void begin_sequence(std::int64_t now_us);   // (re)starts; sets sequence_started_
//   void send_step(std::int64_t now_us);        // sends the current step's command
//   bool streaming() const;                     // the sequence is done, scans flow
//   bool drain(std::int64_t now_us, RangeScan& out);  // parses rx_[rx_pos_, rx_len_),
//                                               // true (stopping there) when `out` got a scan
//   void on_reply_timeout(std::int64_t now_us); // the reply awaited did not come in time
//   void sync_parser_stats();                   // parser counters into stats_
//   std::int64_t stall_timeout_us() const;
// Memory: the members below, inside the object; no heap.
#include <cstddef>
#include <cstdint>

#include "sdpslam/hal/byte_stream.h"
#include "sdpslam/hal/clock.h"
#include "sdpslam/hal/range_scan_source.h"

namespace sdpslam::drivers {

template <class Driver, std::size_t kRxBytes>
class SerialLaserLoop : public hal::RangeScanSource {
 public:
  int poll(RangeScan& out, std::int64_t timeout_us) override;
  hal::RangeSourceHealth health() const override { return health_; }
  const hal::RangeSourceStats& stats() const override { return stats_; }

 protected:
  SerialLaserLoop(hal::ByteStream& stream, const hal::MonotonicClock& clock) : stream_(stream), clock_(clock) {}

  hal::ByteStream& stream_;
  const hal::MonotonicClock& clock_;
  bool awaiting_ = false;               // a command is in flight ...
  std::int64_t step_deadline_us_ = 0;   // ... and its reply is due by then
  std::int64_t last_scan_us_ = 0;       // the stall clock (set by the driver)
  std::uint64_t seen_open_count_ = 0U;  // the stream's open_count the sequence ran for
  bool sequence_started_ = false;
  bool disconnected_ = false;
  std::uint8_t rx_[kRxBytes] = {};
  std::size_t rx_pos_ = 0U;  // rx_[rx_pos_, rx_len_) not parsed yet
  std::size_t rx_len_ = 0U;
  hal::RangeSourceHealth health_ = hal::RangeSourceHealth::kStarting;
  hal::RangeSourceStats stats_;
};

template <class Driver, std::size_t kRxBytes>
int SerialLaserLoop<Driver, kRxBytes>::poll(RangeScan& out, std::int64_t timeout_us) {
  Driver& d = static_cast<Driver&>(*this);
  const std::int64_t deadline = clock_.now_us() + (timeout_us > 0 ? timeout_us : 0);
  for (;;) {
    std::int64_t now = clock_.now_us();
    if (stream_.state() != hal::StreamState::kOpen) {
      if (!disconnected_) {
        disconnected_ = true;
        ++stats_.disconnect_count;
      }
      health_ = hal::RangeSourceHealth::kDisconnected;
      rx_pos_ = rx_len_ = 0U;
      (void)stream_.wait_readable(deadline > now ? deadline - now : 0);
      if (stream_.state() != hal::StreamState::kOpen) return -1;
      continue;
    }
    if (!sequence_started_ || stream_.stats().open_count != seen_open_count_) {
      if (sequence_started_) ++stats_.restart_count;
      seen_open_count_ = stream_.stats().open_count;
      disconnected_ = false;
      d.begin_sequence(now);
    }
    if (rx_pos_ < rx_len_ && d.drain(now, out)) {
      d.sync_parser_stats();
      return 1;
    }
    d.sync_parser_stats();
    now = clock_.now_us();
    if (!awaiting_ && !d.streaming()) d.send_step(now);
    const std::int32_t n = stream_.read(rx_, sizeof rx_);
    if (n > 0) {
      rx_pos_ = 0U;
      rx_len_ = static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0) continue;
    const std::int64_t stall_us = d.stall_timeout_us();
    if (awaiting_ && now >= step_deadline_us_) {
      ++stats_.timeout_count;
      d.on_reply_timeout(now);
      continue;
    }
    if (d.streaming() && now - last_scan_us_ >= stall_us) {
      ++stats_.stall_count;
      ++stats_.restart_count;
      d.begin_sequence(now);
      health_ = hal::RangeSourceHealth::kStalled;
      continue;
    }
    if (now >= deadline) return 0;
    std::int64_t wake = deadline;
    if (awaiting_ && step_deadline_us_ < wake) wake = step_deadline_us_;
    if (d.streaming() && last_scan_us_ + stall_us < wake) wake = last_scan_us_ + stall_us;
    (void)stream_.wait_readable(wake > now ? wake - now : 0);
  }
}

}  // namespace sdpslam::drivers
