#include "sdpslam/drivers/candump_log.h"

#include <cinttypes>
#include <cstring>

namespace sdpslam::drivers {

const char* to_string(CandumpError e) {
  switch (e) {
    case CandumpError::kNone: return "ok";
    case CandumpError::kBadTimestamp: return "malformed timestamp, expected (sec.usec) with 6 usec digits";
    case CandumpError::kMissingInterface: return "missing interface name";
    case CandumpError::kInterfaceTooLong: return "interface name longer than 15 characters";
    case CandumpError::kBadInterfaceChar: return "control or non-ASCII byte in the interface name";
    case CandumpError::kMissingFrame: return "missing frame";
    case CandumpError::kBadId: return "identifier must be 3 (standard) or 8 (extended) hex digits";
    case CandumpError::kIdOutOfRange: return "standard identifier above 0x7FF";
    case CandumpError::kMissingSeparator: return "missing '#' (log) or '[dlc]' (screen) after the identifier";
    case CandumpError::kCanFdUnsupported: return "CAN FD frame (##) not supported";
    case CandumpError::kBadHexDigit: return "not a hex digit";
    case CandumpError::kOddHexDigits: return "odd number of hex digits in data";
    case CandumpError::kTooManyBytes: return "more than 8 data bytes";
    case CandumpError::kBadDlc: return "data length not 0..8 or not matching the bytes";
    case CandumpError::kTrailingGarbage: return "unexpected text after the data";
    case CandumpError::kLineTooLong: return "line too long";
    case CandumpError::kIoError: return "read error";
  }
  return "?";
}

namespace {

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}
bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

// Cursor over one line that remembers the column of errors.
struct Cursor {
  std::string_view s;
  std::size_t i = 0;
  bool done() const { return i >= s.size(); }
  char peek() const { return done() ? '\0' : s[i]; }
  void skip_space() {
    while (!done() && is_space(s[i])) ++i;
  }
  std::string_view token() {
    const std::size_t b = i;
    while (!done() && !is_space(s[i])) ++i;
    return s.substr(b, i - b);
  }
};

CandumpParseResult fail(CandumpError e, std::size_t index) {
  return CandumpParseResult{CandumpLineKind::kError, e, index + 1};
}

// "(sec.usec)" at c.i.
CandumpParseResult parse_stamp(Cursor& c, std::int64_t& stamp_us) {
  const std::size_t start = c.i;
  ++c.i;  // '('
  std::int64_t sec = 0;
  int sec_digits = 0;
  while (!c.done() && c.peek() >= '0' && c.peek() <= '9') {
    if (sec_digits >= 12) return fail(CandumpError::kBadTimestamp, c.i);
    sec = sec * 10 + (c.peek() - '0');
    ++sec_digits;
    ++c.i;
  }
  if (sec_digits == 0 || c.peek() != '.') return fail(CandumpError::kBadTimestamp, c.done() ? start : c.i);
  ++c.i;
  std::int64_t usec = 0;
  int usec_digits = 0;
  while (!c.done() && c.peek() >= '0' && c.peek() <= '9') {
    if (usec_digits >= 6) return fail(CandumpError::kBadTimestamp, c.i);
    usec = usec * 10 + (c.peek() - '0');
    ++usec_digits;
    ++c.i;
  }
  if (usec_digits != 6 || c.peek() != ')') return fail(CandumpError::kBadTimestamp, c.done() ? start : c.i);
  ++c.i;
  stamp_us = sec * 1000000 + usec;
  return CandumpParseResult{CandumpLineKind::kFrame, CandumpError::kNone, 0};
}

CandumpParseResult parse_interface(Cursor& c, char (&name)[16]) {
  c.skip_space();
  const std::size_t start = c.i;
  const std::string_view tok = c.token();
  if (tok.empty()) return fail(CandumpError::kMissingInterface, start);
  if (tok.size() > 15) return fail(CandumpError::kInterfaceTooLong, start);
  for (std::size_t k = 0; k < tok.size(); ++k) {
    const auto ch = static_cast<unsigned char>(tok[k]);
    if (ch < 0x21 || ch > 0x7E) return fail(CandumpError::kBadInterfaceChar, start + k);
  }
  std::memcpy(name, tok.data(), tok.size());
  name[tok.size()] = '\0';
  return CandumpParseResult{CandumpLineKind::kFrame, CandumpError::kNone, 0};
}

// Hex id of 3 or 8 digits starting at `offset` in the line; sets flags like can-utils.
CandumpParseResult parse_id(std::string_view digits, std::size_t offset, std::uint32_t& id) {
  if (digits.size() != 3 && digits.size() != 8) return fail(CandumpError::kBadId, offset);
  std::uint32_t v = 0;
  for (std::size_t k = 0; k < digits.size(); ++k) {
    const int h = hex_value(digits[k]);
    if (h < 0) return fail(CandumpError::kBadHexDigit, offset + k);
    v = (v << 4) | static_cast<std::uint32_t>(h);
  }
  if (digits.size() == 3) {
    if (v > hal::CanFrame::kStandardMask) return fail(CandumpError::kIdOutOfRange, offset);
    id = v;
  } else if (v & hal::CanFrame::kErrorFlag) {
    id = v & (hal::CanFrame::kErrorFlag | hal::CanFrame::kExtendedMask);
  } else {
    id = (v & hal::CanFrame::kExtendedMask) | hal::CanFrame::kExtendedFlag;
  }
  return CandumpParseResult{CandumpLineKind::kFrame, CandumpError::kNone, 0};
}

}  // namespace

CandumpParseResult parse_candump_log_line(std::string_view line, CandumpRecord& out) {
  Cursor c{line};
  if (c.peek() != '(') return CandumpParseResult{};  // comment
  CandumpRecord rec;
  if (auto r = parse_stamp(c, rec.stamp_us); r.kind == CandumpLineKind::kError) return r;
  rec.has_stamp = true;
  if (!c.done() && !is_space(c.peek())) return fail(CandumpError::kBadTimestamp, c.i);
  if (auto r = parse_interface(c, rec.interface_name); r.kind == CandumpLineKind::kError) return r;
  c.skip_space();
  const std::size_t frame_start = c.i;
  const std::string_view tok = c.token();
  if (tok.empty()) return fail(CandumpError::kMissingFrame, frame_start);
  const std::size_t hash = tok.find('#');
  if (hash == std::string_view::npos) {
    // Either a missing '#' or an id of the wrong length; name the likelier one.
    return fail(tok.size() == 3 || tok.size() == 8 ? CandumpError::kMissingSeparator : CandumpError::kBadId,
                frame_start + (tok.size() == 3 || tok.size() == 8 ? tok.size() : 0));
  }
  hal::CanFrame& f = rec.frame;
  if (auto r = parse_id(tok.substr(0, hash), frame_start, f.id); r.kind == CandumpLineKind::kError) return r;
  std::size_t k = hash + 1;
  if (k < tok.size() && tok[k] == '#') return fail(CandumpError::kCanFdUnsupported, frame_start + k);
  if (k < tok.size() && (tok[k] == 'R' || tok[k] == 'r')) {
    f.id |= hal::CanFrame::kRtrFlag;
    ++k;
    f.dlc = 0;
    if (k < tok.size()) {
      const char d = tok[k];
      if (d < '0' || d > '8' || k + 1 != tok.size()) return fail(CandumpError::kBadDlc, frame_start + k);
      f.dlc = static_cast<std::uint8_t>(d - '0');
    }
    out = rec;
    return CandumpParseResult{CandumpLineKind::kFrame, CandumpError::kNone, 0};
  }
  std::uint8_t n = 0;
  while (k < tok.size()) {
    if (tok[k] == '.') {  // optional byte separator
      ++k;
      continue;
    }
    const int hi = hex_value(tok[k]);
    if (hi < 0) return fail(CandumpError::kBadHexDigit, frame_start + k);
    if (k + 1 >= tok.size() || tok[k + 1] == '.') return fail(CandumpError::kOddHexDigits, frame_start + k);
    const int lo = hex_value(tok[k + 1]);
    if (lo < 0) return fail(CandumpError::kBadHexDigit, frame_start + k + 1);
    if (n >= hal::CanFrame::kMaxDataBytes) return fail(CandumpError::kTooManyBytes, frame_start + k);
    f.data[n++] = static_cast<std::uint8_t>((hi << 4) | lo);
    k += 2;
  }
  f.dlc = n;
  out = rec;
  return CandumpParseResult{CandumpLineKind::kFrame, CandumpError::kNone, 0};
}

CandumpParseResult parse_candump_screen_line(std::string_view line, CandumpRecord& out) {
  Cursor c{line};
  c.skip_space();
  if (c.done() || c.peek() == '#') return CandumpParseResult{};
  CandumpRecord rec;
  if (c.peek() == '(') {
    if (auto r = parse_stamp(c, rec.stamp_us); r.kind == CandumpLineKind::kError) return r;
    rec.has_stamp = true;
  }
  if (auto r = parse_interface(c, rec.interface_name); r.kind == CandumpLineKind::kError) return r;
  c.skip_space();
  const std::size_t id_start = c.i;
  const std::string_view id_tok = c.token();
  if (id_tok.empty()) return fail(CandumpError::kMissingFrame, id_start);
  hal::CanFrame& f = rec.frame;
  if (auto r = parse_id(id_tok, id_start, f.id); r.kind == CandumpLineKind::kError) return r;
  c.skip_space();
  const std::size_t dlc_start = c.i;
  const std::string_view dlc_tok = c.token();
  if (dlc_tok.size() < 3 || dlc_tok.front() != '[' || dlc_tok.back() != ']') {
    return fail(CandumpError::kMissingSeparator, dlc_start);
  }
  if (dlc_tok.size() != 3 || dlc_tok[1] < '0' || dlc_tok[1] > '8') {
    return fail(CandumpError::kBadDlc, dlc_start + 1);
  }
  const auto dlc = static_cast<std::uint8_t>(dlc_tok[1] - '0');
  c.skip_space();
  if (line.substr(c.i).substr(0, 14) == "remote request") {
    f.id |= hal::CanFrame::kRtrFlag;
    f.dlc = dlc;
    c.i += 14;
    c.skip_space();
    if (!c.done()) return fail(CandumpError::kTrailingGarbage, c.i);
    out = rec;
    return CandumpParseResult{CandumpLineKind::kFrame, CandumpError::kNone, 0};
  }
  std::uint8_t n = 0;
  while (!c.done()) {
    const std::size_t at = c.i;
    const std::string_view b = c.token();
    if (b.size() != 2) {
      return fail(b.size() == 1 ? CandumpError::kOddHexDigits : CandumpError::kTrailingGarbage, at);
    }
    const int hi = hex_value(b[0]);
    const int lo = hex_value(b[1]);
    if (hi < 0) return fail(CandumpError::kBadHexDigit, at);
    if (lo < 0) return fail(CandumpError::kBadHexDigit, at + 1);
    if (n >= dlc) return fail(n >= hal::CanFrame::kMaxDataBytes ? CandumpError::kTooManyBytes : CandumpError::kBadDlc, at);
    f.data[n++] = static_cast<std::uint8_t>((hi << 4) | lo);
    c.skip_space();
  }
  if (n != dlc) return fail(CandumpError::kBadDlc, dlc_start + 1);
  f.dlc = n;
  out = rec;
  return CandumpParseResult{CandumpLineKind::kFrame, CandumpError::kNone, 0};
}

std::size_t format_candump_log_line(const CandumpRecord& rec, char* buf, std::size_t cap) {
  const hal::CanFrame& f = rec.frame;
  if (f.dlc > hal::CanFrame::kMaxDataBytes || rec.interface_name[0] == '\0' ||
      ::strnlen(rec.interface_name, sizeof rec.interface_name) >= sizeof rec.interface_name ||
      cap < kMaxCandumpLogLine || rec.stamp_us < 0) {
    return 0;
  }
  int n = std::snprintf(buf, cap, "(%" PRId64 ".%06" PRId64 ") %s ", rec.stamp_us / 1000000,
                        rec.stamp_us % 1000000, rec.interface_name);
  if (n < 0) return 0;
  auto pos = static_cast<std::size_t>(n);
  int m;
  if (f.is_error()) {
    m = std::snprintf(buf + pos, cap - pos, "%08" PRIX32 "#",
                      f.id & (hal::CanFrame::kErrorFlag | hal::CanFrame::kExtendedMask));
  } else if (f.is_extended()) {
    m = std::snprintf(buf + pos, cap - pos, "%08" PRIX32 "#", f.id & hal::CanFrame::kExtendedMask);
  } else {
    m = std::snprintf(buf + pos, cap - pos, "%03" PRIX32 "#", f.id & hal::CanFrame::kStandardMask);
  }
  if (m < 0) return 0;
  pos += static_cast<std::size_t>(m);
  if (f.is_rtr()) {
    buf[pos++] = 'R';
    if (f.dlc > 0) buf[pos++] = static_cast<char>('0' + f.dlc);
  } else {
    static const char kHex[] = "0123456789ABCDEF";
    for (std::uint8_t i = 0; i < f.dlc; ++i) {
      buf[pos++] = kHex[f.data[i] >> 4];
      buf[pos++] = kHex[f.data[i] & 0xF];
    }
  }
  buf[pos++] = '\n';
  buf[pos] = '\0';
  return pos;
}

CandumpReader::~CandumpReader() {
  if (file_ != nullptr) std::fclose(file_);
}

bool CandumpReader::open(const char* path) {
  if (file_ != nullptr) std::fclose(file_);
  file_ = std::fopen(path, "r");
  line_number_ = 0;
  return file_ != nullptr;
}

int CandumpReader::next(CandumpRecord& out) {
  if (file_ == nullptr) {
    error_ = CandumpError::kIoError;
    column_ = 0;
    return -1;
  }
  for (;;) {
    // Read one line byte by byte (NUL bytes included, so they are reported, not hidden).
    std::size_t len = 0;
    bool too_long = false;
    int ch = EOF;
    while ((ch = std::fgetc(file_)) != EOF) {
      if (len < sizeof line_) {
        line_[len++] = static_cast<char>(ch);
      } else {
        too_long = true;
      }
      if (ch == '\n') break;
    }
    if (len == 0 && ch == EOF) break;
    ++line_number_;
    if (too_long) {
      error_ = CandumpError::kLineTooLong;
      column_ = sizeof line_ + 1;
      errors_++;
      return -1;
    }
    const std::string_view sv(line_, len);
    const CandumpParseResult r = format_ == CandumpFormat::kLog ? parse_candump_log_line(sv, out)
                                                                : parse_candump_screen_line(sv, out);
    if (r.kind == CandumpLineKind::kComment) {
      comments_++;
      continue;
    }
    if (r.kind == CandumpLineKind::kError) {
      error_ = r.error;
      column_ = r.column;
      errors_++;
      return -1;
    }
    frames_++;
    error_ = CandumpError::kNone;
    return 1;
  }
  if (std::ferror(file_)) {
    error_ = CandumpError::kIoError;
    column_ = 0;
    return -1;
  }
  return 0;
}

CandumpWriter::~CandumpWriter() { close(); }

bool CandumpWriter::open(const char* path) {
  close();
  failed_ = false;
  written_ = 0;
  file_ = std::fopen(path, "w");
  return file_ != nullptr;
}

bool CandumpWriter::write(const CandumpRecord& rec) {
  char buf[kMaxCandumpLogLine];
  const std::size_t n = format_candump_log_line(rec, buf, sizeof buf);
  if (n == 0 || file_ == nullptr) return false;
  if (std::fwrite(buf, 1, n, file_) != n) {
    failed_ = true;
    return false;
  }
  written_++;
  return true;
}

bool CandumpWriter::close() {
  if (file_ == nullptr) return !failed_;
  if (std::fflush(file_) != 0) failed_ = true;
  if (std::fclose(file_) != 0) failed_ = true;
  file_ = nullptr;
  return !failed_;
}

}  // namespace sdpslam::drivers
