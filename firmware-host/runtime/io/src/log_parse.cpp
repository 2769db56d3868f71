#include "log_parse.h"

#include <charconv>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <system_error>

namespace sdpslam::io::detail {

void split_fields(std::string_view line, std::vector<std::string_view>* out) {
  out->clear();
  std::size_t i = 0;
  const std::size_t n = line.size();
  while (i < n) {
    while (i < n && (line[i] == ' ' || line[i] == '\t')) ++i;
    if (i >= n) break;
    const std::size_t start = i;
    while (i < n && line[i] != ' ' && line[i] != '\t') ++i;
    out->push_back(line.substr(start, i - start));
  }
}

std::string check_text(std::string_view line) {
  for (std::size_t i = 0; i < line.size(); ++i) {
    const auto c = static_cast<unsigned char>(line[i]);
    if ((c < 0x20U && c != '\t') || c > 0x7EU) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "non-text byte 0x%02x at column %zu", static_cast<unsigned>(c), i + 1);
      return buf;
    }
  }
  return std::string();
}

bool parse_stamp_us(std::string_view tok, std::int64_t* out_us) {
  std::size_t i = 0;
  bool negative = false;
  if (i < tok.size() && tok[i] == '-') {
    negative = true;
    ++i;
  }
  std::int64_t seconds = 0;
  std::size_t int_digits = 0;
  while (i < tok.size() && tok[i] >= '0' && tok[i] <= '9') {
    if (++int_digits > 12) return false;
    seconds = seconds * 10 + (tok[i] - '0');
    ++i;
  }
  std::int64_t micros = 0;
  std::size_t frac_digits = 0;
  bool round_up = false;
  if (i < tok.size() && tok[i] == '.') {
    ++i;
    while (i < tok.size() && tok[i] >= '0' && tok[i] <= '9') {
      if (frac_digits < 6) {
        micros = micros * 10 + (tok[i] - '0');
      } else if (frac_digits == 6) {
        round_up = tok[i] >= '5';
      }
      ++frac_digits;
      ++i;
    }
  }
  if (i != tok.size() || int_digits + frac_digits == 0) return false;
  for (std::size_t k = frac_digits; k < 6; ++k) micros *= 10;
  std::int64_t v = seconds * 1000000 + micros + (round_up ? 1 : 0);
  *out_us = negative ? -v : v;
  return true;
}

namespace {
template <typename T>
bool parse_finite_impl(std::string_view tok, T* out) {
  if (tok.empty()) return false;
  const char* first = tok.data();
  const char* last = tok.data() + tok.size();
  if (*first == '+') ++first;  // from_chars refuses '+', strtod-era writers may emit it
  T v{};
  const auto res = std::from_chars(first, last, v, std::chars_format::general);
  if (res.ec != std::errc() || res.ptr != last || !std::isfinite(v)) return false;
  *out = v;
  return true;
}
}  // namespace

bool parse_finite(std::string_view tok, double* out) { return parse_finite_impl(tok, out); }
bool parse_finite(std::string_view tok, float* out) { return parse_finite_impl(tok, out); }

bool parse_int(std::string_view tok, std::int64_t* out) {
  if (tok.empty()) return false;
  std::int64_t v = 0;
  const auto res = std::from_chars(tok.data(), tok.data() + tok.size(), v, 10);
  if (res.ec != std::errc() || res.ptr != tok.data() + tok.size()) return false;
  *out = v;
  return true;
}

std::string quote(std::string_view tok) {
  constexpr std::size_t kMax = 24;
  if (tok.size() <= kMax) return "'" + std::string(tok) + "'";
  return "'" + std::string(tok.substr(0, kMax)) + "...'";
}

namespace {
template <typename T>
std::string format_exact_impl(T v) {
  char buf[512];
  const auto res = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed);
  if (res.ec != std::errc()) return "nan";  // cannot happen for finite values: buffer fits
  return std::string(buf, res.ptr);
}
}  // namespace

std::string format_exact(double v) { return format_exact_impl(v); }
std::string format_exact(float v) { return format_exact_impl(v); }

std::string format_stamp(std::int64_t stamp_us) {
  const bool negative = stamp_us < 0;
  // Magnitude in unsigned arithmetic so INT64_MIN does not overflow.
  const std::uint64_t mag = negative ? 0U - static_cast<std::uint64_t>(stamp_us) : static_cast<std::uint64_t>(stamp_us);
  char buf[48];
  std::snprintf(buf, sizeof buf, "%s%" PRIu64 ".%06" PRIu64, negative ? "-" : "", mag / 1000000U, mag % 1000000U);
  return buf;
}

}  // namespace sdpslam::io::detail
