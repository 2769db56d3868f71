// Hokuyo URG driver over SCIP 2.0 (protocols.md §1); contract in urg_scip2_laser.h.
#include "sdpslam/drivers/urg_scip2_laser.h"

#include <cstring>

namespace sdpslam::drivers {
namespace {

constexpr double kTwoPi = 6.28318530717958647692;

}  // namespace

UrgScip2Laser::UrgScip2Laser(hal::ByteStream& stream, const hal::MonotonicClock& clock,
                             const UrgOptions& options)
    : stream_(stream), clock_(clock), options_(options) {
  if (options_.cluster == 0U || options_.cluster > 99U) options_.cluster = 1U;
}

void UrgScip2Laser::begin_sequence(std::int64_t now_us) {
  (void)now_us;
  parser_.reset();
  sensor_clock_.reset();
  stream_.flush_input();
  rx_pos_ = rx_len_ = 0U;
  step_ = Step::kScip2;
  awaiting_ = false;
  retries_ = 0U;
  sequence_started_ = true;
  health_ = hal::RangeSourceHealth::kStarting;
}

void UrgScip2Laser::send_step(std::int64_t now_us) {
  char cmd[32];
  std::size_t n = 0U;
  switch (step_) {
    case Step::kScip2: n = scip2::build_simple("SCIP2.0", cmd, sizeof cmd); break;
    case Step::kQuit: n = scip2::build_simple("QT", cmd, sizeof cmd); break;
    case Step::kVersion: n = scip2::build_simple("VV", cmd, sizeof cmd); break;
    case Step::kParams: n = scip2::build_simple("PP", cmd, sizeof cmd); break;
    case Step::kLaserOn: n = scip2::build_simple("BM", cmd, sizeof cmd); break;
    case Step::kStream:
      n = scip2::build_scan(true, 3U, params_.amin, params_.amax, options_.cluster, 0U, 0U, cmd, sizeof cmd);
      break;
    case Step::kStreaming: return;
  }
  std::size_t sent = 0U;
  for (int tries = 0; sent < n && tries < 8; ++tries) {
    const std::int32_t w = stream_.write(reinterpret_cast<const std::uint8_t*>(cmd) + sent, n - sent);
    if (w < 0) return;  // link down: poll() notices
    sent += static_cast<std::size_t>(w);
  }
  awaiting_ = true;
  step_deadline_us_ = now_us + options_.reply_timeout_us;
}

void UrgScip2Laser::advance(std::int64_t now_us) {
  awaiting_ = false;
  retries_ = 0U;
  switch (step_) {
    case Step::kScip2: step_ = Step::kQuit; break;
    case Step::kQuit: step_ = Step::kVersion; break;
    case Step::kVersion: step_ = Step::kParams; break;
    case Step::kParams: step_ = Step::kLaserOn; break;
    case Step::kLaserOn: step_ = Step::kStream; break;
    case Step::kStream:
      step_ = Step::kStreaming;
      last_scan_us_ = now_us;  // the stall clock starts now
      break;
    case Step::kStreaming: break;
  }
}

void UrgScip2Laser::retry_or_restart(std::int64_t now_us) {
  awaiting_ = false;
  if (++retries_ > options_.max_retries) {
    ++stats_.restart_count;
    begin_sequence(now_us);
  }
}

void UrgScip2Laser::sync_parser_stats() {
  const scip2::ParserStats& p = parser_.stats();
  stats_.checksum_error_count = p.checksum_error_count;
  stats_.framing_error_count = p.framing_error_count;
  stats_.garbage_byte_count = p.garbage_byte_count;
  stats_.resync_count = p.resync_count;
}

void UrgScip2Laser::on_reply(std::int64_t now_us, RangeScan& out, bool* produced) {
  const scip2::Reply& r = parser_.reply();
  if (r.is_scan && r.command_is("MD")) {
    if (step_ != Step::kStreaming) return;  // a stream left running before QT
    if (r.value_count > capacity::kMaxBeams || params_.ares == 0U) {
      ++stats_.dropped_scan_count;
      return;
    }
    const double step_rad = kTwoPi / static_cast<double>(params_.ares);
    out.stamp_us = sensor_clock_.map_us(r.timestamp_ms, now_us);
    out.geometry.angle_min_rad = static_cast<float>(
        (static_cast<double>(r.request.start_step) - static_cast<double>(params_.afrt)) * step_rad);
    out.geometry.angle_increment_rad = static_cast<float>(static_cast<double>(r.request.cluster) * step_rad);
    out.geometry.range_min_m = static_cast<float>(params_.dmin_mm) * 0.001F;
    out.geometry.range_max_m = static_cast<float>(params_.dmax_mm) * 0.001F;
    out.geometry.laser_in_base = options_.laser_in_base;
    out.beam_count = r.value_count;
    for (std::uint32_t i = 0; i < r.value_count; ++i) {
      const std::uint32_t v = r.values[i];
      out.ranges_m[i] = v < scip2::kMinValidRangeMm ? 0.0F : static_cast<float>(v) * 0.001F;
    }
    last_scan_us_ = now_us;
    health_ = hal::RangeSourceHealth::kStreaming;
    ++stats_.scan_count;
    *produced = true;
    return;
  }
  if (step_ == Step::kStreaming) {
    if (r.command_is("MD") && !r.status_ok()) ++stats_.sensor_error_count;
    return;
  }
  if (!awaiting_) return;
  static constexpr const char* kEcho[] = {"SCIP2.0", "QT", "VV", "PP", "BM", "MD"};
  const char* expected = kEcho[static_cast<int>(step_)];
  if (!r.command_is(expected)) return;  // stray reply (e.g. a stream being stopped)
  bool accepted = r.status_ok();
  switch (step_) {
    case Step::kScip2: accepted = accepted || r.status_is("0E"); break;  // UG01: already 2.0
    case Step::kVersion: {
      scip2::VersionInfo v;
      accepted = accepted && scip2::parse_vv(r, &v);
      if (accepted) {
        std::strncpy(product_, v.product, sizeof product_ - 1U);
        product_[sizeof product_ - 1U] = '\0';
      }
      break;
    }
    case Step::kParams: {
      scip2::SensorParams p;
      accepted = accepted && scip2::parse_pp(r, &p) && p.amax - p.amin + 1U <= capacity::kMaxBeams;
      if (accepted) params_ = p;
      break;
    }
    case Step::kLaserOn: accepted = accepted || r.status_is("02"); break;  // already on
    case Step::kStream: accepted = r.status_is("00"); break;
    default: break;
  }
  if (accepted) {
    advance(now_us);
  } else {
    ++stats_.sensor_error_count;
    retry_or_restart(now_us);
  }
}

int UrgScip2Laser::poll(RangeScan& out, std::int64_t timeout_us) {
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
      begin_sequence(now);
    }
    while (rx_pos_ < rx_len_) {
      std::size_t used = 0U;
      const auto ev = parser_.feed(rx_ + rx_pos_, rx_len_ - rx_pos_, &used);
      rx_pos_ += used;
      if (ev == scip2::Parser::Event::kReply) {
        bool produced = false;
        on_reply(now, out, &produced);
        if (produced) {
          sync_parser_stats();
          return 1;
        }
      } else if (ev == scip2::Parser::Event::kError && step_ == Step::kStreaming) {
        ++stats_.dropped_scan_count;  // while streaming, a broken reply is a lost scan
      }
    }
    sync_parser_stats();
    now = clock_.now_us();
    if (!awaiting_ && step_ != Step::kStreaming) send_step(now);
    const std::int32_t n = stream_.read(rx_, sizeof rx_);
    if (n > 0) {
      rx_pos_ = 0U;
      rx_len_ = static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0) continue;
    // Nothing is pending: only now may silence count as a reply timeout or a stall. A
    // poll that was held off (a loaded machine, a long SLAM step) reads its backlog
    // first; judged before that, a healthy sensor would be restarted and its buffered
    // scans thrown away.
    if (awaiting_ && now >= step_deadline_us_) {
      ++stats_.timeout_count;
      retry_or_restart(now);
      continue;
    }
    if (step_ == Step::kStreaming && now - last_scan_us_ >= options_.stall_timeout_us) {
      ++stats_.stall_count;
      ++stats_.restart_count;
      begin_sequence(now);
      health_ = hal::RangeSourceHealth::kStalled;
      continue;
    }
    if (now >= deadline) return 0;
    std::int64_t wake = deadline;
    if (awaiting_ && step_deadline_us_ < wake) wake = step_deadline_us_;
    if (step_ == Step::kStreaming && last_scan_us_ + options_.stall_timeout_us < wake) {
      wake = last_scan_us_ + options_.stall_timeout_us;
    }
    (void)stream_.wait_readable(wake > now ? wake - now : 0);
  }
}

}  // namespace sdpslam::drivers
