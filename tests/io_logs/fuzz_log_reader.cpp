// libFuzzer: the whole reader (format detection, every format, .gz) over arbitrary file
// contents, written to a scratch file and read to the end.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "sdpslam/io/log_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = [] {
    const char* tmp = std::getenv("TMPDIR");
    return std::string(tmp != nullptr ? tmp : "/tmp") + "/fuzz_log_reader." + std::to_string(::getpid()) + ".log";
  }();
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) return 0;
  std::fwrite(data, 1, size, f);
  std::fclose(f);
  sdpslam::io::LogReaderOptions options;
  options.max_errors_kept = 8;
  sdpslam::io::LogReader reader;
  std::string error;
  if (reader.open(path, options, &error)) {
    std::size_t records = 0;
    while (reader.next() != sdpslam::io::LogReader::Next::kEnd) ++records;
    if (reader.errors().size() > options.max_errors_kept) std::abort();
    // A line gives at most one record or one error, except an impossible odometry jump:
    // it is reported on the line whose record is still delivered (not applied).
    const std::size_t line_errors = reader.error_count() - reader.odometry_jumps_removed();
    if (static_cast<std::int64_t>(records + line_errors) > reader.lines_read()) std::abort();
  }
  std::remove(path.c_str());
  return 0;
}
