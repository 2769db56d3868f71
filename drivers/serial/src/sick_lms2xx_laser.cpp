// SICK LMS2xx driver (protocols.md §2); contract in sick_lms2xx_laser.h.
#include "sdpslam/drivers/sick_lms2xx_laser.h"

namespace sdpslam::drivers {
namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;
constexpr std::uint32_t kProbeRates[] = {9600U, 19200U, 38400U, 500000U};
constexpr std::uint32_t kProbeCount = sizeof kProbeRates / sizeof kProbeRates[0];

}  // namespace

bool validate(const SickOptions& o) {
  std::uint8_t buf[16];
  return lms2xx::build_baud_switch(o.target_baud, buf, sizeof buf) != 0U &&
         lms2xx::build_variant(o.angle_deg, o.resolution_cdeg, buf, sizeof buf) != 0U;
}

SickLms2xxLaser::SickLms2xxLaser(hal::ByteStream& stream, const hal::MonotonicClock& clock,
                                 const SickOptions& options)
    : SerialLaserLoop(stream, clock), options_(options) {
  if (!validate(options_)) {
    options_.target_baud = 9600U;
    options_.angle_deg = 180U;
    options_.resolution_cdeg = 50U;
  }
}

std::uint32_t SickLms2xxLaser::expected_values() const {
  return static_cast<std::uint32_t>(options_.angle_deg) * 100U / options_.resolution_cdeg + 1U;
}

void SickLms2xxLaser::begin_sequence(std::int64_t now_us) {
  (void)now_us;
  parser_.reset();
  probe_index_ = 0U;
  (void)stream_.set_baud_rate(kProbeRates[0]);
  stream_.flush_input();
  rx_pos_ = rx_len_ = 0U;
  step_ = Step::kStop;
  awaiting_ = false;
  retries_ = 0U;
  sequence_started_ = true;
  health_ = hal::RangeSourceHealth::kStarting;
}

void SickLms2xxLaser::send_step(std::int64_t now_us) {
  std::uint8_t t[32];
  std::size_t n = 0U;
  switch (step_) {
    case Step::kStop: n = lms2xx::build_stop_streaming(t, sizeof t); break;
    case Step::kBaud: n = lms2xx::build_baud_switch(options_.target_baud, t, sizeof t); break;
    case Step::kVariant: n = lms2xx::build_variant(options_.angle_deg, options_.resolution_cdeg, t, sizeof t); break;
    case Step::kStream: n = lms2xx::build_start_streaming(t, sizeof t); break;
    case Step::kStreaming: return;
  }
  std::size_t sent = 0U;
  for (int tries = 0; sent < n && tries < 8; ++tries) {
    const std::int32_t w = stream_.write(t + sent, n - sent);
    if (w < 0) return;
    sent += static_cast<std::size_t>(w);
  }
  awaiting_ = true;
  step_deadline_us_ = now_us + options_.reply_timeout_us;
}

void SickLms2xxLaser::step_done(std::int64_t now_us) {
  awaiting_ = false;
  retries_ = 0U;
  switch (step_) {
    case Step::kStop:
      step_ = stream_.baud_rate() == options_.target_baud ? Step::kVariant : Step::kBaud;
      break;
    case Step::kBaud:
      // The scanner answered at the old rate and switches after A0; now the host follows.
      if (!stream_.set_baud_rate(options_.target_baud)) {
        ++stats_.restart_count;
        begin_sequence(now_us);
        return;
      }
      stream_.flush_input();
      step_ = Step::kVariant;
      break;
    case Step::kVariant: step_ = Step::kStream; break;
    case Step::kStream:
      step_ = Step::kStreaming;
      last_scan_us_ = now_us;
      break;
    case Step::kStreaming: break;
  }
}

void SickLms2xxLaser::retry_or_restart(std::int64_t now_us, bool timed_out) {
  awaiting_ = false;
  if (timed_out && step_ == Step::kStop) {
    // No answer at this rate: probe the next one.
    probe_index_ = (probe_index_ + 1U) % kProbeCount;
    (void)stream_.set_baud_rate(kProbeRates[probe_index_]);
    stream_.flush_input();
    return;
  }
  if (++retries_ > options_.max_retries) {
    ++stats_.restart_count;
    begin_sequence(now_us);
  }
}

void SickLms2xxLaser::sync_parser_stats() {
  const lms2xx::ParserStats& p = parser_.stats();
  stats_.checksum_error_count = p.crc_error_count;
  stats_.garbage_byte_count = p.garbage_byte_count;
  stats_.resync_count = p.resync_count;
  stats_.nak_count = p.nak_count;
  stats_.framing_error_count = p.framing_error_count + decode_error_count_;
}

void SickLms2xxLaser::on_telegram(std::int64_t now_us, RangeScan& out, bool* produced) {
  const lms2xx::Telegram& t = parser_.telegram();
  const std::uint8_t cmd = t.command();
  if (cmd == 0xB0U) {
    if (step_ != Step::kStreaming) return;  // left over from an earlier stream
    if (lms2xx::decode_b0(t, &values_) != lms2xx::B0Error::kNone || values_.count != expected_values() ||
        values_.count > capacity::kMaxBeams) {
      ++decode_error_count_;
      ++stats_.dropped_scan_count;
      return;
    }
    const bool mm = values_.units == lms2xx::Units::kMillimetre;
    const float scale_m = mm ? 0.001F : 0.01F;
    const std::uint32_t baud = stream_.baud_rate() != 0U ? stream_.baud_rate() : 9600U;
    const std::int64_t wire_us =
        static_cast<std::int64_t>((t.length + 6U) * 10U) * 1000000 / static_cast<std::int64_t>(baud);
    out.stamp_us = now_us - wire_us;
    out.geometry.angle_min_rad = static_cast<float>(-0.5 * options_.angle_deg * kDegToRad);
    out.geometry.angle_increment_rad = static_cast<float>(options_.resolution_cdeg * 0.01 * kDegToRad);
    out.geometry.range_min_m = scale_m;
    out.geometry.range_max_m = static_cast<float>(lms2xx::kFirstErrorCode) * scale_m;
    out.geometry.laser_in_base = options_.laser_in_base;
    out.beam_count = values_.count;
    for (std::uint32_t i = 0; i < values_.count; ++i) {
      const std::uint16_t d = values_.distance[i];
      out.ranges_m[i] = (d == 0U || d >= lms2xx::kFirstErrorCode) ? 0.0F : static_cast<float>(d) * scale_m;
    }
    last_scan_us_ = now_us;
    health_ = hal::RangeSourceHealth::kStreaming;
    ++stats_.scan_count;
    *produced = true;
    return;
  }
  if (!awaiting_) return;
  const bool mode_reply = cmd == 0xA0U && (step_ == Step::kStop || step_ == Step::kBaud || step_ == Step::kStream);
  const bool variant_reply = cmd == 0xBBU && step_ == Step::kVariant;
  if (!mode_reply && !variant_reply) return;
  const bool ok = t.length >= 2U && (mode_reply ? t.body[1] == 0x00U : t.body[1] == 0x01U);
  if (ok) {
    step_done(now_us);
  } else {
    ++stats_.sensor_error_count;
    retry_or_restart(now_us, false);
  }
}

bool SickLms2xxLaser::drain(std::int64_t now_us, RangeScan& out) {
  while (rx_pos_ < rx_len_) {
    std::size_t used = 0U;
    const auto ev = parser_.feed(rx_ + rx_pos_, rx_len_ - rx_pos_, &used);
    rx_pos_ += used;
    if (ev == lms2xx::Parser::Event::kTelegram) {
      bool produced = false;
      on_telegram(now_us, out, &produced);
      if (produced) return true;
    } else if (ev == lms2xx::Parser::Event::kNak) {
      if (awaiting_) retry_or_restart(now_us, false);
    } else if (ev == lms2xx::Parser::Event::kError) {
      if (parser_.last_error() == lms2xx::Error::kCrc && step_ == Step::kStreaming) ++stats_.dropped_scan_count;
    }
  }
  return false;
}

}  // namespace sdpslam::drivers
