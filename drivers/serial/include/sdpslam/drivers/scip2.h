#pragma once
// Hokuyo SCIP 2.0 codec (protocols.md §1; Hokuyo "SCIP 2.0" spec C-42-03320B): pure
// functions and a streaming reply parser. No I/O, no heap: bytes in, values or errors out.
//
// Reply framing (spec §2): echo line, status line (2 chars + checksum), payload lines,
// empty line — every reply ends with LF LF. Scan payloads (GD/GS/MD/MS) are a timestamp
// line (4 chars + checksum) and data blocks of at most 64 chars + checksum; a multi-char
// value may straddle two blocks. The checksum of EVERY line is enforced.
#include <cstddef>
#include <cstdint>

#include "sdpslam/core/capacities.h"

namespace sdpslam::drivers::scip2 {

inline constexpr std::size_t kMaxLineChars = 80;    // longest line accepted (data: 65)
inline constexpr std::size_t kMaxCommandChars = 40;  // "MDssssEEEEccsnn;" + 16 text + slack
inline constexpr std::size_t kMaxValues = capacity::kMaxBeams;
inline constexpr std::size_t kMaxParams = 16;
inline constexpr std::size_t kMaxParamValueChars = 64;
inline constexpr std::uint32_t kMinValidRangeMm = 20U;  // values below are error codes

// ((sum of bytes) & 0x3F) + 0x30 (spec §2.3).
char checksum(const char* s, std::size_t n);

// Decodes 1..4 chars of the 6-bit encoding (value = char - 0x30, MSB first). False iff
// n is 0 or > 4 or a char lies outside '0'..'o' (0x30..0x6F); *out untouched then.
bool decode(const char* s, std::size_t n, std::uint32_t* out);
// Encodes v into n (1..4) chars; false iff n is out of range or v does not fit in 6n bits.
bool encode(std::uint32_t v, std::size_t n, char* out);

enum class Error : std::uint8_t {
  kNone,
  kChecksum,            // a line's checksum char does not match
  kLineTooLong,         // more than kMaxLineChars before LF
  kNotAnEcho,           // first line of a reply is not a known command echo
  kBadStatus,           // status line malformed
  kBadTimestamp,        // timestamp line malformed
  kBadDataChar,         // data char outside 0x30..0x6F
  kTooManyValues,       // more values than requested / than kMaxValues
  kValueCountMismatch,  // reply ended before all requested values arrived (lost line)
  kBadParamLine,        // VV/PP/II line not KEY:VALUE;c
  kUnexpectedPayload,   // payload lines where the command has none
};
const char* error_name(Error e);
// True for errors that are checksum failures (the rest are framing errors).
inline bool is_checksum_error(Error e) { return e == Error::kChecksum; }

// Range request carried by a GD/GS/MD/MS echo: "GDssssEEEEcc", "MDssssEEEEccsnn".
struct ScanRequest {
  std::uint32_t start_step = 0U;
  std::uint32_t end_step = 0U;
  std::uint32_t cluster = 1U;
  std::uint8_t chars_per_value = 3U;  // GD/MD 3, GS/MS 2
  bool streamed = false;              // MD/MS
  std::uint32_t value_count() const {
    return end_step < start_step ? 0U : (end_step - start_step) / cluster + 1U;
  }
};
// Parses the echo of a scan command. False iff it is not a well-formed GD/GS/MD/MS echo
// (bad digits, end < start, cluster 0, wrong length).
bool parse_scan_request(const char* echo, std::size_t n, ScanRequest* out);

struct Param {
  char key[5] = {};  // 4-char key ("AMIN"), empty for plain data lines (TM1, ...)
  char value[kMaxParamValueChars + 1] = {};
  std::uint8_t value_len = 0U;
};

struct Reply {
  char command[kMaxCommandChars + 1] = {};  // echo line, NUL-terminated
  std::uint8_t command_len = 0U;
  char status[3] = {};  // "00", "99", "0E", or "0" (SCIP1.1 answer to "SCIP2.0")
  bool has_timestamp = false;
  std::uint32_t timestamp_ms = 0U;  // raw 24-bit sensor time
  bool is_scan = false;             // carries scan data (values valid)
  ScanRequest request;              // when is_scan
  std::uint32_t value_count = 0U;
  std::uint32_t values[kMaxValues] = {};  // mm, or error codes < 20
  std::uint8_t param_count = 0U;
  Param params[kMaxParams];

  // Command starts with `prefix` (e.g. "MD", "SCIP2.0").
  bool command_is(const char* prefix) const;
  bool status_is(const char* two) const;
  // Status 00, 99, or the SCIP1.1 "0".
  bool status_ok() const;
  // Value of KEY in a VV/PP/II reply, nullptr iff absent.
  const char* param(const char* key) const;
};

struct ParserStats {
  std::uint64_t byte_count = 0U;
  std::uint64_t reply_count = 0U;     // well-formed replies delivered
  std::uint64_t scan_count = 0U;      // of which carry scan data
  std::uint64_t checksum_error_count = 0U;
  std::uint64_t framing_error_count = 0U;
  std::uint64_t garbage_byte_count = 0U;  // bytes skipped while resynchronising
  std::uint64_t resync_count = 0U;        // resynchronisations completed (LF LF found)
};

// Streaming reply parser, fed arbitrary chunks. After an error it skips to the end of the
// broken reply (the next LF LF) and resumes with the next echo line; a reply that had an
// error is never delivered.
class Parser {
 public:
  enum class Event : std::uint8_t { kNone, kReply, kError };

  // Consumes bytes of data[0..n) and stops right after the byte that completed a reply
  // (kReply: reply() valid until the next feed) or revealed an error (kError:
  // last_error()/last_error_offset() say why and where). *consumed = bytes used (all n
  // with kNone). Cost O(*consumed).
  Event feed(const std::uint8_t* data, std::size_t n, std::size_t* consumed);

  const Reply& reply() const { return reply_; }
  Error last_error() const { return last_error_; }
  // Stream offset (bytes since construction/reset) of the first byte of the offending line.
  std::uint64_t last_error_offset() const { return last_error_offset_; }
  const ParserStats& stats() const { return stats_; }
  // Forgets any partial reply (e.g. after the stream was re-opened); keeps stats.
  void reset();

 private:
  enum class State : std::uint8_t { kEcho, kStatus, kPayload, kSkip };
  Event on_line();
  Event fail(Error e);
  Event on_echo();
  Event on_status();
  Event on_payload_line();
  Event on_end_of_reply();
  Event add_data_chars(const char* s, std::size_t n);

  State state_ = State::kEcho;
  char line_[kMaxLineChars] = {};
  std::size_t line_len_ = 0U;
  std::uint64_t offset_ = 0U;
  std::uint64_t line_start_ = 0U;
  bool skip_saw_lf_ = false;
  bool payload_expected_ = false;  // scan data expected in this reply
  bool param_reply_ = false;       // VV/PP/II
  std::uint8_t payload_lines_ = 0U;
  std::uint32_t acc_ = 0U;        // value being assembled across blocks
  std::uint8_t acc_chars_ = 0U;
  Reply reply_;
  Error last_error_ = Error::kNone;
  std::uint64_t last_error_offset_ = 0U;
  ParserStats stats_;
};

// Sensor geometry from PP (spec "PP" reply) and identity from VV.
struct SensorParams {
  std::uint32_t dmin_mm = 0U, dmax_mm = 0U;
  std::uint32_t ares = 0U, amin = 0U, amax = 0U, afrt = 0U;
  std::uint32_t scan_rpm = 0U;
};
// False iff a field is missing or not a decimal number, or ares == 0, amin > amax.
bool parse_pp(const Reply& r, SensorParams* out);
struct VersionInfo {
  const char* vendor = nullptr;
  const char* product = nullptr;
  const char* firmware = nullptr;
  const char* protocol = nullptr;
  const char* serial = nullptr;
};
// Pointers into r (valid while r is). False iff PROD or PROT is missing.
bool parse_vv(const Reply& r, VersionInfo* out);

// Command builders: write the command line (with its LF) into out; return its length,
// 0 iff it does not fit in cap or a parameter is out of range.
std::size_t build_simple(const char* cmd, char* out, std::size_t cap);  // "VV", "BM", ...
std::size_t build_scan(bool streamed, std::uint8_t chars_per_value, std::uint32_t start_step,
                       std::uint32_t end_step, std::uint32_t cluster, std::uint32_t interval,
                       std::uint32_t scan_count, char* out, std::size_t cap);
std::size_t build_ss(std::uint32_t baud, char* out, std::size_t cap);

// Unwraps the 24-bit millisecond sensor counter and maps it onto the host monotonic clock.
// offset = min over the last kWindow samples of (host receive time - sensor time): the
// transport delay is never negative, so the smallest offset is the least delayed one
// (the same minimum filter as urg_stamped / Olson's passive synchronisation); a window
// lets slow drift between the two clocks through. Output stamps never decrease.
class SensorClock {
 public:
  static constexpr std::size_t kWindow = 32U;
  static constexpr std::uint32_t kCounterBits = 24U;

  // Host stamp (us) of the sensor stamp `sensor_ms` received at `host_receive_us`.
  std::int64_t map_us(std::uint32_t sensor_ms, std::int64_t host_receive_us);
  // Forget history (after a sensor restart / re-open).
  void reset();
  std::uint64_t wrap_count() const { return wrap_count_; }
  std::uint64_t jump_count() const { return jump_count_; }  // backward jumps (resets)

 private:
  bool started_ = false;
  std::uint32_t last_raw_ = 0U;
  std::int64_t epoch_ms_ = 0;  // multiple of 2^24 added to raw
  std::int64_t offsets_us_[kWindow] = {};
  std::size_t offset_count_ = 0U;
  std::size_t offset_next_ = 0U;
  std::int64_t last_out_us_ = 0;
  bool have_out_ = false;
  std::uint64_t wrap_count_ = 0U;
  std::uint64_t jump_count_ = 0U;
};

}  // namespace sdpslam::drivers::scip2
