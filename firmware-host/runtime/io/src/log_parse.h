#pragma once
// Text-field parsing shared by the log readers and the CARMEN writer (internal to
// sdpslam_io). Every function either consumes a whole token or fails: a token such as
// "1.5x" or "" is never read as 1.5 / 0. Locale-independent (std::from_chars).
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace sdpslam::io::detail {

// Longest line the readers accept. A ROBOTLASER1 line with kMaxBeams ranges and as many
// remissions is ~25 kB; anything longer is garbage, reported and skipped.
inline constexpr std::size_t kMaxLineBytes = 64U * 1024U;

// Reason prefix of a line skipped because its CARMEN message type is not known: reported
// as a warning (the line is not malformed, just not ours).
inline constexpr const char* kUnknownTypePrefix = "unknown message type ";

// Splits on spaces and tabs. Views point into `line`.
void split_fields(std::string_view line, std::vector<std::string_view>* out);

// Empty iff every byte is printable ASCII or a tab; otherwise a reason naming the first
// offending byte and its 1-based column.
std::string check_text(std::string_view line);

// Decimal seconds ("976052857.337530", "-0.5", "12") to integer microseconds, exactly
// from the digits (no floating point): up to 6 fraction digits are taken as they are;
// further digits round half away from zero. No exponent, no sign other than a leading
// '-', at most 12 integer digits. False on anything else.
bool parse_stamp_us(std::string_view tok, std::int64_t* out_us);

// Finite double / float, whole token (from_chars general format). False for NaN, inf,
// overflow, trailing characters, empty tokens.
bool parse_finite(std::string_view tok, double* out);
bool parse_finite(std::string_view tok, float* out);

// Decimal integer, optional leading '-', whole token, within int64.
bool parse_int(std::string_view tok, std::int64_t* out);

// "'tok'" shortened to at most 24 characters, for error reasons.
std::string quote(std::string_view tok);

// Shortest text that reads back to exactly the same value, never in exponent form.
std::string format_exact(double v);
std::string format_exact(float v);
// Microseconds as CARMEN decimal seconds with exactly 6 fraction digits.
std::string format_stamp(std::int64_t stamp_us);

}  // namespace sdpslam::io::detail
