#pragma once
// Helpers shared by the libFuzzer targets over text readers (header only: the fuzz
// build links no test framework).
#include <cstddef>
#include <string>

namespace sdpslam::test::fuzz {

// A property that cannot fail for correct code: a failure stops the fuzzer as a crash.
inline void check(bool ok) {
  if (!ok) __builtin_trap();
}

// Lines of `text`: the '\n's, plus one for a last line without one.
inline std::size_t line_count(const std::string& text) {
  std::size_t n = 0;
  for (const char c : text) n += c == '\n' ? 1U : 0U;
  return n + (text.empty() || text.back() == '\n' ? 0U : 1U);
}

// The first `lines` lines of `text`, each with its '\n'.
inline std::string first_lines(const std::string& text, std::size_t lines) {
  std::size_t end = 0;
  for (std::size_t n = 0; n < lines && end < text.size(); ++n) {
    const std::size_t nl = text.find('\n', end);
    end = nl == std::string::npos ? text.size() : nl + 1U;
  }
  return text.substr(0, end);
}

// N of a reader's message "NAME:N: reason"; 0 when the message does not start so (for
// example "NAME: reason", a problem of the whole file).
inline std::size_t error_line(const std::string& error, const std::string& name) {
  const std::string prefix = name + ":";
  if (error.compare(0, prefix.size(), prefix) != 0) return 0;
  std::size_t i = prefix.size();
  std::size_t n = 0;
  while (i < error.size() && error[i] >= '0' && error[i] <= '9' && n < 100000000U) {
    n = n * 10U + static_cast<std::size_t>(error[i] - '0');
    ++i;
  }
  return i < error.size() && error[i] == ':' ? n : 0U;
}

}  // namespace sdpslam::test::fuzz
