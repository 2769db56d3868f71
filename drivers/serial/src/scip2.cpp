// SCIP 2.0 codec: protocols.md §1, Hokuyo spec C-42-03320B §2 (framing, checksum, encoding).
#include "sdpslam/drivers/scip2.h"

#include <cstdio>
#include <cstring>

namespace sdpslam::drivers::scip2 {
namespace {

constexpr char kLf = '\n';
constexpr std::uint8_t kCharBase = 0x30U;
constexpr std::uint8_t kCharMax = 0x6FU;  // 0x30 + 63

// Commands whose echo may open a reply. Anything else in the echo position is garbage.
constexpr const char* kKnownCommands[] = {"SCIP2.0", "MD", "MS", "GD", "GS", "VV", "PP", "II",
                                          "BM",      "QT", "RS", "RT", "TM", "SS", "CR", "HS"};

bool starts_with(const char* s, std::size_t n, const char* prefix) {
  const std::size_t p = std::strlen(prefix);
  return n >= p && std::memcmp(s, prefix, p) == 0;
}

bool parse_decimal(const char* s, std::size_t n, std::uint32_t* out) {
  if (n == 0U || n > 9U) return false;
  std::uint32_t v = 0U;
  for (std::size_t i = 0; i < n; ++i) {
    if (s[i] < '0' || s[i] > '9') return false;
    v = v * 10U + static_cast<std::uint32_t>(s[i] - '0');
  }
  *out = v;
  return true;
}

bool parse_decimal_cstr(const char* s, std::uint32_t* out) {
  return s != nullptr && parse_decimal(s, std::strlen(s), out);
}

}  // namespace

char checksum(const char* s, std::size_t n) {
  std::uint32_t sum = 0U;
  for (std::size_t i = 0; i < n; ++i) sum += static_cast<std::uint8_t>(s[i]);
  return static_cast<char>((sum & 0x3FU) + kCharBase);
}

bool decode(const char* s, std::size_t n, std::uint32_t* out) {
  if (n == 0U || n > 4U) return false;
  std::uint32_t v = 0U;
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = static_cast<std::uint8_t>(s[i]);
    if (c < kCharBase || c > kCharMax) return false;
    v = (v << 6U) | static_cast<std::uint32_t>(c - kCharBase);
  }
  *out = v;
  return true;
}

bool encode(std::uint32_t v, std::size_t n, char* out) {
  if (n == 0U || n > 4U) return false;
  if (n < 4U && v >= (1U << (6U * n))) return false;
  if (n == 4U && v >= (1U << 24U)) return false;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t shift = static_cast<std::uint32_t>(6U * (n - 1U - i));
    out[i] = static_cast<char>(((v >> shift) & 0x3FU) + kCharBase);
  }
  return true;
}

const char* error_name(Error e) {
  switch (e) {
    case Error::kNone: return "none";
    case Error::kChecksum: return "checksum mismatch";
    case Error::kLineTooLong: return "line too long";
    case Error::kNotAnEcho: return "not a command echo";
    case Error::kBadStatus: return "malformed status line";
    case Error::kBadTimestamp: return "malformed timestamp line";
    case Error::kBadDataChar: return "data char outside 0x30..0x6F";
    case Error::kTooManyValues: return "more values than requested";
    case Error::kValueCountMismatch: return "reply ended before all values arrived";
    case Error::kBadParamLine: return "malformed KEY:VALUE;c line";
    case Error::kUnexpectedPayload: return "unexpected payload line";
  }
  return "unknown";
}

bool parse_scan_request(const char* echo, std::size_t n, ScanRequest* out) {
  // Free text after ';' is not part of the request.
  for (std::size_t i = 0; i < n; ++i) {
    if (echo[i] == ';') {
      n = i;
      break;
    }
  }
  if (n < 2U) return false;
  ScanRequest r;
  if (echo[0] == 'G') {
    r.streamed = false;
  } else if (echo[0] == 'M') {
    r.streamed = true;
  } else {
    return false;
  }
  if (echo[1] == 'D') {
    r.chars_per_value = 3U;
  } else if (echo[1] == 'S') {
    r.chars_per_value = 2U;
  } else {
    return false;
  }
  if (n != (r.streamed ? 15U : 12U)) return false;
  if (!parse_decimal(echo + 2, 4U, &r.start_step) || !parse_decimal(echo + 6, 4U, &r.end_step) ||
      !parse_decimal(echo + 10, 2U, &r.cluster)) {
    return false;
  }
  if (r.streamed) {
    std::uint32_t ignored = 0U;
    if (!parse_decimal(echo + 12, 3U, &ignored)) return false;
  }
  if (r.cluster == 0U) r.cluster = 1U;  // spec: 00 means no grouping
  if (r.end_step < r.start_step) return false;
  *out = r;
  return true;
}

bool Reply::command_is(const char* prefix) const {
  return starts_with(command, command_len, prefix);
}

bool Reply::status_is(const char* two) const {
  return status[0] == two[0] && status[1] == two[1];
}

bool Reply::status_ok() const {
  return status_is("00") || status_is("99") || (status[0] == '0' && status[1] == '\0');
}

const char* Reply::param(const char* key) const {
  for (std::uint8_t i = 0; i < param_count; ++i) {
    if (std::strncmp(params[i].key, key, 4U) == 0 && params[i].key[0] != '\0') return params[i].value;
  }
  return nullptr;
}

void Parser::reset() {
  state_ = State::kEcho;
  line_len_ = 0U;
  line_start_ = offset_;
  skip_saw_lf_ = false;
}

Parser::Event Parser::fail(Error e) {
  last_error_ = e;
  last_error_offset_ = line_start_;
  if (e == Error::kChecksum) {
    ++stats_.checksum_error_count;
  } else {
    ++stats_.framing_error_count;
  }
  return Event::kError;
}

Parser::Event Parser::feed(const std::uint8_t* data, std::size_t n, std::size_t* consumed) {
  for (std::size_t i = 0; i < n; ++i) {
    const char c = static_cast<char>(data[i]);
    ++offset_;
    if (state_ == State::kSkip) {
      ++stats_.garbage_byte_count;
      if (c == kLf) {
        if (skip_saw_lf_) {
          state_ = State::kEcho;
          skip_saw_lf_ = false;
          line_len_ = 0U;
          line_start_ = offset_;
          ++stats_.resync_count;
        } else {
          skip_saw_lf_ = true;
        }
      } else {
        skip_saw_lf_ = false;
      }
      continue;
    }
    if (c == kLf) {
      const Event ev = on_line();
      line_len_ = 0U;
      line_start_ = offset_;
      if (ev == Event::kError) {
        // The broken line ended with this LF; an empty line next ends the reply. A reply
        // found broken at its final empty line is already over.
        if (state_ != State::kEcho) {
          state_ = State::kSkip;
          skip_saw_lf_ = true;
        }
      }
      if (ev != Event::kNone) {
        stats_.byte_count += i + 1U;
        *consumed = i + 1U;
        return ev;
      }
      continue;
    }
    if (line_len_ == kMaxLineChars) {
      const Event ev = fail(Error::kLineTooLong);
      state_ = State::kSkip;
      skip_saw_lf_ = false;
      stats_.byte_count += i + 1U;
      *consumed = i + 1U;
      return ev;
    }
    line_[line_len_++] = c;
  }
  stats_.byte_count += n;
  *consumed = n;
  return Event::kNone;
}

Parser::Event Parser::on_line() {
  if (line_len_ == 0U) {
    switch (state_) {
      case State::kEcho:
        ++stats_.garbage_byte_count;  // stray LF between replies
        return Event::kNone;
      case State::kStatus:
        state_ = State::kEcho;
        return fail(Error::kBadStatus);
      case State::kPayload:
        return on_end_of_reply();
      case State::kSkip:
        break;
    }
    return Event::kNone;
  }
  switch (state_) {
    case State::kEcho: return on_echo();
    case State::kStatus: return on_status();
    case State::kPayload: return on_payload_line();
    case State::kSkip: break;
  }
  return Event::kNone;
}

Parser::Event Parser::on_echo() {
  bool printable = line_len_ >= 2U && line_len_ <= kMaxCommandChars;
  for (std::size_t i = 0; printable && i < line_len_; ++i) {
    printable = line_[i] >= 0x20 && line_[i] <= 0x7E;
  }
  bool known = false;
  for (const char* cmd : kKnownCommands) {
    if (printable && starts_with(line_, line_len_, cmd)) known = true;
  }
  if (!known) {
    state_ = State::kSkip;  // mark: the reply is broken (feed() keeps kSkip)
    return fail(Error::kNotAnEcho);
  }
  std::memcpy(reply_.command, line_, line_len_);
  reply_.command[line_len_] = '\0';
  reply_.command_len = static_cast<std::uint8_t>(line_len_);
  reply_.status[0] = reply_.status[1] = reply_.status[2] = '\0';
  reply_.has_timestamp = false;
  reply_.timestamp_ms = 0U;
  reply_.value_count = 0U;
  reply_.param_count = 0U;
  reply_.is_scan = false;
  acc_ = 0U;
  acc_chars_ = 0U;
  payload_lines_ = 0U;
  payload_expected_ = false;
  param_reply_ = reply_.command_is("VV") || reply_.command_is("PP") || reply_.command_is("II");
  const bool scan_command = (line_[0] == 'G' || line_[0] == 'M') && (line_[1] == 'D' || line_[1] == 'S');
  if (scan_command && !parse_scan_request(line_, line_len_, &reply_.request)) {
    state_ = State::kSkip;
    return fail(Error::kNotAnEcho);
  }
  if (scan_command && reply_.request.value_count() > kMaxValues) {
    state_ = State::kSkip;
    return fail(Error::kTooManyValues);
  }
  reply_.is_scan = scan_command;
  state_ = State::kStatus;
  return Event::kNone;
}

Parser::Event Parser::on_status() {
  if (line_len_ == 1U && line_[0] == '0' && reply_.command_is("SCIP2.0")) {
    reply_.status[0] = '0';  // SCIP1.1 sensor switching to 2.0 answers "0" without checksum
  } else if (line_len_ == 3U) {
    if (checksum(line_, 2U) != line_[2]) return fail(Error::kChecksum);
    reply_.status[0] = line_[0];
    reply_.status[1] = line_[1];
  } else {
    return fail(Error::kBadStatus);
  }
  if (reply_.is_scan) {
    payload_expected_ = reply_.request.streamed ? reply_.status_is("99") : reply_.status_is("00");
  }
  state_ = State::kPayload;
  return Event::kNone;
}

Parser::Event Parser::add_data_chars(const char* s, std::size_t n) {
  const std::uint32_t expected = reply_.request.value_count();
  const std::uint8_t width = reply_.request.chars_per_value;
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = static_cast<std::uint8_t>(s[i]);
    if (c < kCharBase || c > kCharMax) return fail(Error::kBadDataChar);
    if (reply_.value_count >= expected) return fail(Error::kTooManyValues);
    acc_ = (acc_ << 6U) | static_cast<std::uint32_t>(c - kCharBase);
    if (++acc_chars_ == width) {
      reply_.values[reply_.value_count++] = acc_;
      acc_ = 0U;
      acc_chars_ = 0U;
    }
  }
  return Event::kNone;
}

Parser::Event Parser::on_payload_line() {
  const std::size_t n = line_len_;
  ++payload_lines_;
  if (reply_.is_scan) {
    if (!payload_expected_) return fail(Error::kUnexpectedPayload);
    if (!reply_.has_timestamp) {
      if (n != 5U) return fail(Error::kBadTimestamp);
      if (checksum(line_, 4U) != line_[4]) return fail(Error::kChecksum);
      if (!decode(line_, 4U, &reply_.timestamp_ms)) return fail(Error::kBadTimestamp);
      reply_.has_timestamp = true;
      return Event::kNone;
    }
    if (n < 2U || n > 65U) return fail(Error::kLineTooLong);
    if (checksum(line_, n - 1U) != line_[n - 1U]) return fail(Error::kChecksum);
    return add_data_chars(line_, n - 1U);
  }
  if (reply_.param_count >= kMaxParams) return fail(Error::kUnexpectedPayload);
  Param& p = reply_.params[reply_.param_count];
  if (param_reply_) {
    // "KEY:VALUE;c", checksum over KEY:VALUE (protocols.md §1).
    if (n < 7U || line_[4] != ':' || line_[n - 2U] != ';') return fail(Error::kBadParamLine);
    if (checksum(line_, n - 2U) != line_[n - 1U]) return fail(Error::kChecksum);
    const std::size_t value_len = n - 7U;
    if (value_len > kMaxParamValueChars) return fail(Error::kBadParamLine);
    std::memcpy(p.key, line_, 4U);
    p.key[4] = '\0';
    std::memcpy(p.value, line_ + 5, value_len);
    p.value[value_len] = '\0';
    p.value_len = static_cast<std::uint8_t>(value_len);
  } else {
    // Plain data line ("TM1" timestamp, ...): data + checksum.
    if (n < 2U || n - 1U > kMaxParamValueChars) return fail(Error::kBadParamLine);
    if (checksum(line_, n - 1U) != line_[n - 1U]) return fail(Error::kChecksum);
    p.key[0] = '\0';
    std::memcpy(p.value, line_, n - 1U);
    p.value[n - 1U] = '\0';
    p.value_len = static_cast<std::uint8_t>(n - 1U);
  }
  ++reply_.param_count;
  return Event::kNone;
}

Parser::Event Parser::on_end_of_reply() {
  state_ = State::kEcho;
  if (payload_expected_) {
    if (!reply_.has_timestamp || acc_chars_ != 0U ||
        reply_.value_count != reply_.request.value_count()) {
      return fail(Error::kValueCountMismatch);
    }
  }
  if (!payload_expected_) reply_.value_count = 0U;
  reply_.is_scan = reply_.is_scan && payload_expected_;
  ++stats_.reply_count;
  if (reply_.is_scan) ++stats_.scan_count;
  return Event::kReply;
}

bool parse_pp(const Reply& r, SensorParams* out) {
  SensorParams p;
  if (!parse_decimal_cstr(r.param("DMIN"), &p.dmin_mm) || !parse_decimal_cstr(r.param("DMAX"), &p.dmax_mm) ||
      !parse_decimal_cstr(r.param("ARES"), &p.ares) || !parse_decimal_cstr(r.param("AMIN"), &p.amin) ||
      !parse_decimal_cstr(r.param("AMAX"), &p.amax) || !parse_decimal_cstr(r.param("AFRT"), &p.afrt) ||
      !parse_decimal_cstr(r.param("SCAN"), &p.scan_rpm)) {
    return false;
  }
  if (p.ares == 0U || p.amin > p.amax || p.dmin_mm >= p.dmax_mm) return false;
  *out = p;
  return true;
}

bool parse_vv(const Reply& r, VersionInfo* out) {
  VersionInfo v;
  v.vendor = r.param("VEND");
  v.product = r.param("PROD");
  v.firmware = r.param("FIRM");
  v.protocol = r.param("PROT");
  v.serial = r.param("SERI");
  if (v.product == nullptr || v.protocol == nullptr) return false;
  *out = v;
  return true;
}

std::size_t build_simple(const char* cmd, char* out, std::size_t cap) {
  const std::size_t n = std::strlen(cmd);
  if (n == 0U || n + 1U > cap) return 0U;
  std::memcpy(out, cmd, n);
  out[n] = kLf;
  return n + 1U;
}

std::size_t build_scan(bool streamed, std::uint8_t chars_per_value, std::uint32_t start_step,
                       std::uint32_t end_step, std::uint32_t cluster, std::uint32_t interval,
                       std::uint32_t scan_count, char* out, std::size_t cap) {
  if ((chars_per_value != 2U && chars_per_value != 3U) || start_step > 9999U || end_step > 9999U ||
      end_step < start_step || cluster > 99U || interval > 9U || scan_count > 99U) {
    return 0U;
  }
  char buf[24];
  const char kind = chars_per_value == 3U ? 'D' : 'S';
  int n = 0;
  if (streamed) {
    n = std::snprintf(buf, sizeof buf, "M%c%04u%04u%02u%01u%02u\n", kind, start_step, end_step, cluster,
                      interval, scan_count);
  } else {
    n = std::snprintf(buf, sizeof buf, "G%c%04u%04u%02u\n", kind, start_step, end_step, cluster);
  }
  if (n <= 0 || static_cast<std::size_t>(n) > cap) return 0U;
  std::memcpy(out, buf, static_cast<std::size_t>(n));
  return static_cast<std::size_t>(n);
}

std::size_t build_ss(std::uint32_t baud, char* out, std::size_t cap) {
  if (baud == 0U || baud > 999999U) return 0U;
  char buf[16];
  const int n = std::snprintf(buf, sizeof buf, "SS%06u\n", baud);
  if (n <= 0 || static_cast<std::size_t>(n) > cap) return 0U;
  std::memcpy(out, buf, static_cast<std::size_t>(n));
  return static_cast<std::size_t>(n);
}

std::int64_t SensorClock::map_us(std::uint32_t sensor_ms, std::int64_t host_receive_us) {
  constexpr std::uint32_t kMask = (1U << kCounterBits) - 1U;
  constexpr std::uint32_t kHalf = 1U << (kCounterBits - 1U);
  const std::uint32_t raw = sensor_ms & kMask;
  if (!started_) {
    started_ = true;
    epoch_ms_ = 0;
  } else if (raw < last_raw_) {
    if (last_raw_ - raw >= kHalf) {
      epoch_ms_ += static_cast<std::int64_t>(1) << kCounterBits;  // counter wrapped (~4.66 h)
      ++wrap_count_;
    } else {
      // Sensor time went backwards: it restarted. Old offsets no longer apply.
      ++jump_count_;
      epoch_ms_ = 0;
      offset_count_ = 0U;
      offset_next_ = 0U;
    }
  }
  last_raw_ = raw;
  const std::int64_t sensor_us = (epoch_ms_ + static_cast<std::int64_t>(raw)) * 1000;
  offsets_us_[offset_next_] = host_receive_us - sensor_us;
  offset_next_ = (offset_next_ + 1U) % kWindow;
  if (offset_count_ < kWindow) ++offset_count_;
  std::int64_t min_offset = offsets_us_[0];
  for (std::size_t i = 1; i < offset_count_; ++i) {
    if (offsets_us_[i] < min_offset) min_offset = offsets_us_[i];
  }
  std::int64_t out = sensor_us + min_offset;
  if (have_out_ && out <= last_out_us_) out = last_out_us_ + 1;
  have_out_ = true;
  last_out_us_ = out;
  return out;
}

void SensorClock::reset() {
  started_ = false;
  offset_count_ = 0U;
  offset_next_ = 0U;
  epoch_ms_ = 0;
}

}  // namespace sdpslam::drivers::scip2
