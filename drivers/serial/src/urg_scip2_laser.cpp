// Hokuyo URG driver over SCIP 2.0 (protocols.md §1); contract in urg_scip2_laser.h.
#include "sdpslam/drivers/urg_scip2_laser.h"

#include <cstring>

namespace sdpslam::drivers {
namespace {

constexpr double kTwoPi = 6.28318530717958647692;

}  // namespace

UrgScip2Laser::UrgScip2Laser(hal::ByteStream& stream, const hal::MonotonicClock& clock,
                             const UrgOptions& options)
    : SerialLaserLoop(stream, clock), options_(options) {
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

bool UrgScip2Laser::drain(std::int64_t now_us, RangeScan& out) {
  while (rx_pos_ < rx_len_) {
    std::size_t used = 0U;
    const auto ev = parser_.feed(rx_ + rx_pos_, rx_len_ - rx_pos_, &used);
    rx_pos_ += used;
    if (ev == scip2::Parser::Event::kReply) {
      bool produced = false;
      on_reply(now_us, out, &produced);
      if (produced) return true;
    } else if (ev == scip2::Parser::Event::kError && step_ == Step::kStreaming) {
      ++stats_.dropped_scan_count;  // while streaming, a broken reply is a lost scan
    }
  }
  return false;
}

}  // namespace sdpslam::drivers
