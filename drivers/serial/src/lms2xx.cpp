// SICK LMS2xx telegram codec: protocols.md §2, SICK telegram listing 8007954.
#include "sdpslam/drivers/lms2xx.h"

#include <cstring>

namespace sdpslam::drivers::lms2xx {

std::uint16_t crc16(const std::uint8_t* data, std::size_t n) {
  std::uint16_t crc = 0U;
  std::uint16_t prev = 0U;
  for (std::size_t i = 0; i < n; ++i) {
    if ((crc & 0x8000U) != 0U) {
      crc = static_cast<std::uint16_t>(((crc & 0x7FFFU) << 1U) ^ 0x8005U);
    } else {
      crc = static_cast<std::uint16_t>(crc << 1U);
    }
    crc = static_cast<std::uint16_t>(crc ^ (data[i] | (prev << 8U)));
    prev = data[i];
  }
  return crc;
}

std::size_t build_telegram(std::uint8_t address, const std::uint8_t* body, std::size_t body_len,
                           std::uint8_t* out, std::size_t cap) {
  if (body_len == 0U || body_len > kMaxBody || body_len + 6U > cap) return 0U;
  out[0] = kStxByte;
  out[1] = address;
  out[2] = static_cast<std::uint8_t>(body_len & 0xFFU);
  out[3] = static_cast<std::uint8_t>(body_len >> 8U);
  std::memcpy(out + 4, body, body_len);
  const std::uint16_t crc = crc16(out, 4U + body_len);
  out[4U + body_len] = static_cast<std::uint8_t>(crc & 0xFFU);
  out[5U + body_len] = static_cast<std::uint8_t>(crc >> 8U);
  return body_len + 6U;
}

std::size_t build_baud_switch(std::uint32_t baud, std::uint8_t* out, std::size_t cap) {
  std::uint8_t code = 0U;
  switch (baud) {
    case 9600U: code = 0x42U; break;
    case 19200U: code = 0x41U; break;
    case 38400U: code = 0x40U; break;
    case 500000U: code = 0x48U; break;
    default: return 0U;
  }
  const std::uint8_t body[2] = {0x20U, code};
  return build_telegram(kHostAddress, body, sizeof body, out, cap);
}

std::size_t build_start_streaming(std::uint8_t* out, std::size_t cap) {
  const std::uint8_t body[2] = {0x20U, 0x24U};
  return build_telegram(kHostAddress, body, sizeof body, out, cap);
}

std::size_t build_stop_streaming(std::uint8_t* out, std::size_t cap) {
  const std::uint8_t body[2] = {0x20U, 0x25U};
  return build_telegram(kHostAddress, body, sizeof body, out, cap);
}

std::size_t build_status_request(std::uint8_t* out, std::size_t cap) {
  const std::uint8_t body[1] = {0x31U};
  return build_telegram(kHostAddress, body, sizeof body, out, cap);
}

std::size_t build_variant(std::uint16_t angle_deg, std::uint16_t resolution_cdeg, std::uint8_t* out,
                          std::size_t cap) {
  if (angle_deg != 100U && angle_deg != 180U) return 0U;
  if (resolution_cdeg != 25U && resolution_cdeg != 50U && resolution_cdeg != 100U) return 0U;
  if (angle_deg == 180U && resolution_cdeg == 25U) return 0U;  // not offered by the LMS2xx
  const std::uint8_t body[5] = {0x3BU, static_cast<std::uint8_t>(angle_deg & 0xFFU),
                                static_cast<std::uint8_t>(angle_deg >> 8U),
                                static_cast<std::uint8_t>(resolution_cdeg & 0xFFU),
                                static_cast<std::uint8_t>(resolution_cdeg >> 8U)};
  return build_telegram(kHostAddress, body, sizeof body, out, cap);
}

const char* error_name(Error e) {
  switch (e) {
    case Error::kNone: return "none";
    case Error::kCrc: return "CRC mismatch";
    case Error::kBadLength: return "LEN out of range";
    case Error::kBadAddress: return "address byte not from the expected side";
  }
  return "unknown";
}

void Parser::reset() {
  len_ = 0U;
  replay_pos_ = 0U;
  replay_len_ = 0U;
}

Parser::Event Parser::reject(Error e) {
  last_error_ = e;
  last_error_offset_ = candidate_offset_;
  if (e == Error::kCrc) {
    ++stats_.crc_error_count;
  } else {
    ++stats_.framing_error_count;
  }
  ++stats_.resync_count;
  ++stats_.garbage_byte_count;  // the false STX
  // Re-examine everything after the false STX, ahead of the bytes still queued.
  const std::size_t head = len_ - 1U;
  const std::size_t tail = replay_len_ - replay_pos_;
  if (head + tail <= kMaxTelegram) {
    std::memmove(replay_ + head, replay_ + replay_pos_, tail);
    std::memcpy(replay_, buf_ + 1, head);
    replay_len_ = head + tail;
  } else {
    replay_len_ = 0U;  // cannot happen (see header); never overflow
  }
  replay_pos_ = 0U;
  replay_offset_ = candidate_offset_ + 1U;
  len_ = 0U;
  return Event::kError;
}

Parser::Event Parser::step(std::uint8_t b) {
  if (len_ == 0U) {
    if (b == kStxByte) {
      buf_[0] = b;
      len_ = 1U;
      return Event::kNone;
    }
    if (b == kAckByte) {
      ++stats_.ack_count;
      return Event::kAck;
    }
    if (b == kNakByte) {
      ++stats_.nak_count;
      return Event::kNak;
    }
    ++stats_.garbage_byte_count;
    return Event::kNone;
  }
  buf_[len_++] = b;
  if (len_ == 2U) {
    const bool from_scanner = (b & 0x80U) != 0U;
    if (from_scanner != (source_ == Source::kScanner)) return reject(Error::kBadAddress);
    return Event::kNone;
  }
  if (len_ < 4U) return Event::kNone;
  const std::size_t body_len = static_cast<std::size_t>(buf_[2]) | (static_cast<std::size_t>(buf_[3]) << 8U);
  if (len_ == 4U && (body_len == 0U || body_len > kMaxBody)) return reject(Error::kBadLength);
  if (len_ < body_len + 6U) return Event::kNone;
  const std::uint16_t crc = crc16(buf_, len_ - 2U);
  const auto got = static_cast<std::uint16_t>(buf_[len_ - 2U] | (buf_[len_ - 1U] << 8U));
  if (crc != got) return reject(Error::kCrc);
  telegram_.address = buf_[1];
  telegram_.length = static_cast<std::uint16_t>(body_len);
  std::memcpy(telegram_.body, buf_ + 4, body_len);
  len_ = 0U;
  ++stats_.telegram_count;
  return Event::kTelegram;
}

Parser::Event Parser::feed(const std::uint8_t* data, std::size_t n, std::size_t* consumed) {
  std::size_t i = 0U;
  for (;;) {
    std::uint8_t b = 0U;
    std::uint64_t at = 0U;
    if (replay_pos_ < replay_len_) {
      at = replay_offset_ + replay_pos_;
      b = replay_[replay_pos_++];
    } else if (i < n) {
      at = offset_++;
      b = data[i++];
      ++stats_.byte_count;
    } else {
      break;
    }
    if (len_ == 0U) candidate_offset_ = at;
    const Event ev = step(b);
    if (ev != Event::kNone) {
      *consumed = i;
      return ev;
    }
  }
  *consumed = n;
  return Event::kNone;
}

const char* b0_error_name(B0Error e) {
  switch (e) {
    case B0Error::kNone: return "none";
    case B0Error::kNotB0: return "not a B0 telegram";
    case B0Error::kBadCount: return "value count 0 or above 401";
    case B0Error::kBadUnits: return "unknown units bits";
    case B0Error::kLengthMismatch: return "LEN does not match the value count";
  }
  return "unknown";
}

B0Error decode_b0(const Telegram& t, MeasuredValues* out) {
  if (t.length < 1U || t.command() != 0xB0U) return B0Error::kNotB0;
  if (t.length < 4U) return B0Error::kLengthMismatch;
  const auto word = static_cast<std::uint16_t>(t.body[1] | (t.body[2] << 8U));
  const auto count = static_cast<std::uint16_t>(word & 0x3FFU);
  const unsigned units = (word >> 14U) & 0x3U;
  if (count == 0U || count > kMaxValues) return B0Error::kBadCount;
  if (units > 1U) return B0Error::kBadUnits;
  if (t.length != 4U + 2U * static_cast<std::size_t>(count)) return B0Error::kLengthMismatch;
  out->count = count;
  out->units = units == 1U ? Units::kMillimetre : Units::kCentimetre;
  const std::uint8_t* p = t.body + 3;
  for (std::uint16_t i = 0; i < count; ++i) {
    const auto w = static_cast<std::uint16_t>(p[2U * i] | (p[2U * i + 1U] << 8U));
    out->distance[i] = static_cast<std::uint16_t>(w & 0x1FFFU);
    out->flags[i] = static_cast<std::uint8_t>(w >> 13U);
  }
  out->status = t.body[t.length - 1U];
  return B0Error::kNone;
}

}  // namespace sdpslam::drivers::lms2xx
