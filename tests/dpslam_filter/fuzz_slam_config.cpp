// libFuzzer: the INI configuration of `sdpslam run` (firmware-host/runtime/slam): load_config_ini (the
// filter's sections, on the built-in defaults and on the accurate profile as sdp mode
// starts) and load_sdp_ini ([sdp]) over arbitrary file contents, read from memory.
// Checks beyond the sanitizers: accepted options validate; a refusal names
// "fuzz.ini:N: reason" with N a line of the input, and is the file's first problem: the
// first N lines are refused with the same message, and the first N - 1 lines are
// accepted or refused at an earlier line (options checked as a whole, once the file is
// read, may be invalid before a later key completes them: ini_document.h).
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "sdpslam/core/sdp_profile.h"
#include "sdpslam/slam/config_ini.h"
#include "sdpslam/slam/run_sdp.h"
#include "fuzz_text.h"

namespace {

using sdpslam::test::fuzz::check;
using sdpslam::test::fuzz::error_line;
using sdpslam::test::fuzz::first_lines;
using sdpslam::test::fuzz::line_count;

const char* const kName = "fuzz.ini";

// Opens `text` as a read-only stream.
std::FILE* open_text(std::string& text) { return ::fmemopen(text.data(), text.size(), "r"); }

template <typename Load>
void check_first_problem(std::string& text, const std::string& error, Load load) {
  const std::size_t n = error_line(error, kName);
  check(n >= 1U && n <= line_count(text));
  std::string upto = first_lines(text, n);
  std::string again;
  check(!load(upto, &again));
  check(again == error);
  // The lines before hold no problem of their own; as a whole they may still make
  // invalid options (a key that a later line would have completed), named before line n.
  std::string before = first_lines(text, n - 1U);
  again.clear();
  if (!load(before, &again)) {
    const std::size_t m = error_line(again, kName);
    check(m >= 1U && m < n);
  }
}

bool load_filter(std::string& text, bool profile, std::string* error) {
  sdpslam::slam::SlamConfig config;
  sdpslam::SdpOptions sdp;
  if (profile) sdpslam::apply_profile(sdpslam::SdpProfile::kAccurate, &config.filter, &sdp);
  std::FILE* f = open_text(text);
  if (f == nullptr) std::abort();
  const bool ok = sdpslam::slam::load_config_ini(f, kName, &config, error);
  std::fclose(f);
  if (ok) {
    check(config.filter.validate(nullptr, 0));
    check(config.log.default_range_max_m > 0.0F && config.log.default_range_max_m <= 1000.0F);
    check(config.log.max_speed_mps >= 0.0 && config.log.max_speed_mps <= 1000.0);
    check(config.log.max_turn_rate_radps >= 0.0 && config.log.max_turn_rate_radps <= 1000.0);
  }
  return ok;
}

bool load_sdp(std::string& text, std::string* error) {
  sdpslam::slam::SlamConfig config;
  sdpslam::SdpOptions sdp;
  sdpslam::apply_profile(sdpslam::SdpProfile::kAccurate, &config.filter, &sdp);
  std::FILE* f = open_text(text);
  if (f == nullptr) std::abort();
  const bool ok = sdpslam::slam::load_sdp_ini(f, kName, &sdp, error);
  std::fclose(f);
  if (ok) check(sdp.validate(nullptr, 0));
  return ok;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string text(reinterpret_cast<const char*>(data), size);
  std::string error;
  if (!load_filter(text, false, &error)) {
    check_first_problem(text, error, [](std::string& t, std::string* e) { return load_filter(t, false, e); });
  }
  error.clear();
  (void)load_filter(text, true, &error);
  error.clear();
  if (!load_sdp(text, &error)) {
    check_first_problem(text, error, [](std::string& t, std::string* e) { return load_sdp(t, e); });
  }
  return 0;
}
