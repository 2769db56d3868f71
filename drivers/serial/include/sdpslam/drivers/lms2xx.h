#pragma once
// SICK LMS200/LMS291 (LMS2xx) telegram codec (protocols.md §2; SICK "Telegram Listing
// LMS2xx" 8007954): CRC, builders, a streaming telegram parser with resynchronisation and
// the B0 measured-values decoder. Pure: no I/O, no heap.
//
// Telegram: STX 02 | ADR | LEN u16 LE | CMD | DATA... | [STATUS] | CRC u16 LE.
// LEN counts CMD + DATA (+ STATUS). The CRC covers STX .. the byte before the CRC.
#include <cstddef>
#include <cstdint>

namespace sdpslam::drivers::lms2xx {

inline constexpr std::uint8_t kStxByte = 0x02U;
inline constexpr std::uint8_t kAckByte = 0x06U;
inline constexpr std::uint8_t kNakByte = 0x15U;
inline constexpr std::uint8_t kHostAddress = 0x00U;
// Largest LEN accepted: a B0 reply with 401 values (100 deg / 0.25 deg) is 1+2+802+1.
inline constexpr std::size_t kMaxBody = 812U;
inline constexpr std::size_t kMaxTelegram = 4U + kMaxBody + 2U;
inline constexpr std::size_t kMaxValues = 401U;

// CRC of protocols.md §2 (sicktoolbox SickLMS2xxMessage::_computeCRC, poly 0x8005).
std::uint16_t crc16(const std::uint8_t* data, std::size_t n);

// Frames body = CMD + DATA into out (STX, address, LEN, body, CRC LE). Returns the
// telegram length, 0 iff body_len is 0 or > kMaxBody or it does not fit in cap.
std::size_t build_telegram(std::uint8_t address, const std::uint8_t* body, std::size_t body_len,
                           std::uint8_t* out, std::size_t cap);
// 20 42/41/40/48: 9600, 19200, 38400, 500000. 0 iff the rate is not one of those.
std::size_t build_baud_switch(std::uint32_t baud, std::uint8_t* out, std::size_t cap);
std::size_t build_start_streaming(std::uint8_t* out, std::size_t cap);  // 20 24
std::size_t build_stop_streaming(std::uint8_t* out, std::size_t cap);   // 20 25
std::size_t build_status_request(std::uint8_t* out, std::size_t cap);   // 31
// 3B aa aa rr rr: angle 100 or 180 deg, resolution 25/50/100 (1/100 deg). 0 iff invalid.
std::size_t build_variant(std::uint16_t angle_deg, std::uint16_t resolution_cdeg, std::uint8_t* out,
                          std::size_t cap);

struct Telegram {
  std::uint8_t address = 0U;
  std::uint16_t length = 0U;  // LEN: bytes in body
  std::uint8_t body[kMaxBody] = {};
  std::uint8_t command() const { return body[0]; }
};

enum class Error : std::uint8_t { kNone, kCrc, kBadLength, kBadAddress };
const char* error_name(Error e);

struct ParserStats {
  std::uint64_t byte_count = 0U;
  std::uint64_t telegram_count = 0U;
  std::uint64_t ack_count = 0U;
  std::uint64_t nak_count = 0U;
  std::uint64_t crc_error_count = 0U;
  std::uint64_t framing_error_count = 0U;  // bad LEN or address after an STX
  std::uint64_t garbage_byte_count = 0U;   // bytes outside any valid telegram / ACK / NAK
  std::uint64_t resync_count = 0U;         // rescans after a failed candidate telegram
};

// Streaming parser, fed arbitrary chunks. Outside a telegram, 06 and 15 are ACK/NAK and
// 02 starts a candidate telegram; a candidate is accepted only when its address, LEN and
// CRC check. On failure the parser rescans the candidate's bytes from the one after its
// STX, so a real telegram hidden behind a false STX (garbage, a truncated telegram) is
// still found.
class Parser {
 public:
  enum class Event : std::uint8_t { kNone, kTelegram, kAck, kNak, kError };
  enum class Source : std::uint8_t { kScanner, kHost };  // which side's telegrams to accept

  explicit Parser(Source source = Source::kScanner) : source_(source) {}

  // Same contract as scip2::Parser::feed: stops after the byte completing an event.
  Event feed(const std::uint8_t* data, std::size_t n, std::size_t* consumed);
  const Telegram& telegram() const { return telegram_; }
  Error last_error() const { return last_error_; }
  std::uint64_t last_error_offset() const { return last_error_offset_; }  // offset of the STX
  const ParserStats& stats() const { return stats_; }
  void reset();

 private:
  Event step(std::uint8_t b);
  Event reject(Error e);

  Source source_;
  std::uint8_t buf_[kMaxTelegram] = {};
  std::size_t len_ = 0U;
  std::uint64_t candidate_offset_ = 0U;
  std::uint64_t offset_ = 0U;  // stream offset of the next new byte
  // Bytes of a rejected candidate waiting to be re-examined.
  std::uint8_t replay_[kMaxTelegram] = {};
  std::size_t replay_pos_ = 0U;
  std::size_t replay_len_ = 0U;
  std::uint64_t replay_offset_ = 0U;
  Telegram telegram_;
  Error last_error_ = Error::kNone;
  std::uint64_t last_error_offset_ = 0U;
  ParserStats stats_;
};

enum class Units : std::uint8_t { kCentimetre, kMillimetre };

struct MeasuredValues {
  std::uint16_t count = 0U;
  Units units = Units::kCentimetre;
  std::uint16_t distance[kMaxValues] = {};  // w & 0x1FFF, in `units`
  std::uint8_t flags[kMaxValues] = {};      // w >> 13 (range-mode dependent flag bits)
  std::uint8_t status = 0U;
};

enum class B0Error : std::uint8_t { kNone, kNotB0, kBadCount, kBadUnits, kLengthMismatch };
const char* b0_error_name(B0Error e);

// Decodes a B0 telegram (count word: bits 0-9 count, bits 14-15 units 00 cm / 01 mm;
// count x u16 LE; status byte). Distances in 8/80 m modes are w & 0x1FFF; values
// >= kFirstErrorCode are error codes (overflow, dazzle), not ranges (sicktoolbox).
inline constexpr std::uint16_t kFirstErrorCode = 0x1FF7U;
B0Error decode_b0(const Telegram& t, MeasuredValues* out);

}  // namespace sdpslam::drivers::lms2xx
