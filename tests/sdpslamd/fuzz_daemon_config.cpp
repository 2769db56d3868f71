// libFuzzer: sdpslamd's INI configuration (load_daemon_config: every section, the
// offline runner's filter and [sdp] sections, the checks made once the file is read and
// the sizing of the SLAM state) over arbitrary file contents, read from memory.
// Checks beyond the sanitizers: an accepted configuration holds only values in the ranges
// sdpslamd.ini documents and sizes a state within its budget; a refusal either names
// "fuzz.ini:N: reason" with N a line of the input or, for the checks over several keys,
// "fuzz.ini: reason".
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "sdpslam/daemon/daemon_config.h"
#include "sdpslam/daemon/slam_engine.h"
#include "fuzz_text.h"

namespace {

using sdpslam::test::fuzz::check;
using sdpslam::test::fuzz::error_line;
using sdpslam::test::fuzz::line_count;

const char* const kName = "fuzz.ini";

void check_refusal(const std::string& text, const std::string& error) {
  if (error.compare(0, std::string(kName).size() + 2U, std::string(kName) + ": ") == 0) return;  // several keys
  const std::size_t n = error_line(error, kName);
  check(n >= 1U && n <= line_count(text));
}

void check_accepted(const sdpslam::daemon::DaemonConfig& c) {
  using sdpslam::daemon::DaemonConfig;
  check(!c.can_interface.empty() && c.can_interface.size() <= 15U);
  check(!c.laser_device.empty() && !c.output_directory.empty());
  check(c.scan_queue >= 1U && c.scan_queue <= DaemonConfig::kMaxScanQueue);
  check(c.max_trajectory_scans >= 1U);
  check(c.memory_budget_mib >= 8U && c.memory_budget_mib <= 65536U);
  check(c.odometry_wait_us >= 0 && c.max_interpolation_gap_us > 0 && c.loop_slice_us > 0);
  check(c.output_period_us > 0 && c.log_interval_us >= 0);
  check(c.can_reopen_interval_us > 0 && c.laser_reopen_interval_us > 0);
  check(sdpslam::drivers::validate(c.drive) == sdpslam::drivers::DiffDriveParamsError::kOk);
  check(c.slam.filter.validate(nullptr, 0));
  if (c.mode == sdpslam::daemon::SlamMode::kSdp) check(c.sdp.validate(nullptr, 0));
  const std::size_t arena = sdpslam::daemon::engine_arena_bytes(c);
  check(arena > 0U && arena <= static_cast<std::size_t>(c.memory_budget_mib) * 1024U * 1024U);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string text(reinterpret_cast<const char*>(data), size);
  std::FILE* f = ::fmemopen(text.data(), text.size(), "r");
  if (f == nullptr) std::abort();
  sdpslam::daemon::DaemonConfig config;
  std::string error;
  const bool ok = sdpslam::daemon::load_daemon_config(f, kName, &config, &error);
  std::fclose(f);
  if (ok) {
    check_accepted(config);
  } else {
    check_refusal(text, error);
  }
  return 0;
}
