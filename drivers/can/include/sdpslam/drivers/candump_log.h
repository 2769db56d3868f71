#pragma once
// can-utils candump text formats: parse and write, line by line, no heap.
//
// Log format (`candump -l`, replayed by canplayer; protocols.md §3):
//   (1700000000.010300) can0 185#45230100
//   "(" sec "." usec (exactly 6 digits) ")", interface name (1..15 chars), frame:
//   3 hex digits = standard id, 8 hex digits = extended id (or an error frame when the
//   value has CAN_ERR_FLAG 0x20000000 set, e.g. 20000080#...), "#", then 0..8 data bytes
//   as hex pairs (optionally separated by '.', as can-utils' parse_canframe allows), or
//   "R" for a remote request optionally followed by its DLC digit (0..8). Anything after
//   the frame token and whitespace is ignored (canplayer reads the first three fields
//   only). Lines not starting with "(" are comments. CAN FD ("##") is not supported and
//   reported as such.
// Screen format (default `candump` output, e.g. the excerpt in
//   testdata/sensors/canopen-bus-excerpt.txt):
//   "  can0  620   [8]  80 00 10 00 00 00 04 05"; optionally preceded by "(sec.usec)"
//   (candump -ta). "remote request" in place of the bytes marks RTR. Blank lines and
//   lines starting with "#" are comments.
//
// A malformed line yields an error naming the reason and the 1-based column; readers
// report the line number too and carry on with the next line (good data is kept).
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string_view>

#include "sdpslam/hal/can_bus.h"

namespace sdpslam::drivers {

struct CandumpRecord {
  std::int64_t stamp_us = 0;   // the log's clock (candump uses CLOCK_REALTIME); not monotonic
  bool has_stamp = false;
  char interface_name[16] = {};
  hal::CanFrame frame;         // frame.stamp_us is left 0: the log clock is not ours
};

enum class CandumpError : std::uint8_t {
  kNone,
  kBadTimestamp,      // "(sec.usec)" malformed (usec must be 6 digits)
  kMissingInterface,
  kInterfaceTooLong,  // more than 15 characters
  kBadInterfaceChar,  // control or non-ASCII byte in the interface name
  kMissingFrame,
  kBadId,             // not 3 or 8 hex digits
  kIdOutOfRange,      // standard id > 0x7FF
  kMissingSeparator,  // no '#' after the id (log) / no "[dlc]" (screen)
  kCanFdUnsupported,
  kBadHexDigit,
  kOddHexDigits,      // half a byte
  kTooManyBytes,      // more than 8 data bytes
  kBadDlc,            // RTR length or "[n]" not 0..8, or byte count != [n]
  kTrailingGarbage,   // screen format: text after the data bytes
  kLineTooLong,
  kIoError,
};
const char* to_string(CandumpError e);

enum class CandumpLineKind : std::uint8_t { kFrame, kComment, kError };

struct CandumpParseResult {
  CandumpLineKind kind = CandumpLineKind::kComment;
  CandumpError error = CandumpError::kNone;
  std::size_t column = 0;  // 1-based position of the offending character (errors only)
};

// Parses one line (without or with its trailing '\n' / "\r\n"). On kFrame `out` is
// filled; otherwise `out` is untouched.
CandumpParseResult parse_candump_log_line(std::string_view line, CandumpRecord& out);
CandumpParseResult parse_candump_screen_line(std::string_view line, CandumpRecord& out);

// Writes `rec` in log format with '\n' into buf (NUL-terminated). Returns the length
// without the NUL, or 0 when cap is too small (kMaxLogLine suffices) or the record cannot
// be written (dlc > 8, empty interface name).
inline constexpr std::size_t kMaxCandumpLogLine = 96;
std::size_t format_candump_log_line(const CandumpRecord& rec, char* buf, std::size_t cap);

enum class CandumpFormat : std::uint8_t { kLog, kScreen };

// Reads a candump file line by line with a fixed buffer.
class CandumpReader {
 public:
  static constexpr std::size_t kMaxLine = 512;
  explicit CandumpReader(CandumpFormat format = CandumpFormat::kLog) : format_(format) {}
  ~CandumpReader();
  CandumpReader(const CandumpReader&) = delete;
  CandumpReader& operator=(const CandumpReader&) = delete;

  bool open(const char* path);  // false iff the file cannot be opened (errno kept)
  // 1: a frame in `out`; 0: end of file; -1: the current line is malformed (see
  // line_number(), error(), column()); call again to continue with the next line.
  int next(CandumpRecord& out);

  std::size_t line_number() const { return line_number_; }
  CandumpError error() const { return error_; }
  std::size_t column() const { return column_; }
  std::size_t frames() const { return frames_; }
  std::size_t comments() const { return comments_; }
  std::size_t errors() const { return errors_; }

 private:
  CandumpFormat format_;
  std::FILE* file_ = nullptr;
  char line_[kMaxLine];
  std::size_t line_number_ = 0;
  CandumpError error_ = CandumpError::kNone;
  std::size_t column_ = 0;
  std::size_t frames_ = 0;
  std::size_t comments_ = 0;
  std::size_t errors_ = 0;
};

// Writes candump -l lines to a file.
class CandumpWriter {
 public:
  CandumpWriter() = default;
  ~CandumpWriter();
  CandumpWriter(const CandumpWriter&) = delete;
  CandumpWriter& operator=(const CandumpWriter&) = delete;
  bool open(const char* path);
  bool write(const CandumpRecord& rec);  // false iff the record is invalid or I/O failed
  bool close();                          // flushes; false iff any write or the close failed
  std::size_t written() const { return written_; }

 private:
  std::FILE* file_ = nullptr;
  bool failed_ = false;
  std::size_t written_ = 0;
};

}  // namespace sdpslam::drivers
