// libFuzzer: whole candump files, written to a scratch file: drivers::CandumpReader in
// both formats read to the end, and sdpslamd's --can-candump input
// (daemon::CandumpReplayBus) played to the end on a simulated clock.
// Checks beyond the sanitizers: every line is counted once, as a frame, a comment or an
// error; line numbers count up; a frame has at most 8 bytes, a
// NUL-terminated interface name and, in log format, a stamp, and formats back to a line
// that parses to the same frame; the end of the file is sticky; the replay bus hands out
// (or consumes as error frames) exactly the frames the reader finds and counts exactly
// its malformed lines.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <string_view>

#include "sdpslam/daemon/candump_replay_bus.h"
#include "sdpslam/drivers/candump_log.h"
#include "fuzz_text.h"

using namespace sdpslam;

namespace {

using sdpslam::test::fuzz::check;

class FakeClock final : public hal::MonotonicClock {
 public:
  std::int64_t now_us() const override { return now; }
  std::int64_t now = 1000000;
};

struct Counts {
  std::size_t frames = 0;
  std::size_t errors = 0;
};

Counts read_all(const std::string& path, drivers::CandumpFormat format, std::size_t lines) {
  drivers::CandumpReader reader(format);
  check(reader.open(path.c_str()));
  Counts counts;
  drivers::CandumpRecord rec;
  std::size_t last_line = 0;
  for (;;) {
    const int r = reader.next(rec);
    if (r == 0) break;
    check(reader.line_number() > last_line);
    last_line = reader.line_number();
    if (r < 0) {
      check(reader.error() != drivers::CandumpError::kNone && reader.error() != drivers::CandumpError::kIoError);
      check(reader.column() >= 1U && reader.column() <= drivers::CandumpReader::kMaxLine + 1U);
      ++counts.errors;
      continue;
    }
    check(r == 1);
    ++counts.frames;
    check(rec.frame.dlc <= 8U);
    check(std::memchr(rec.interface_name, '\0', sizeof rec.interface_name) != nullptr);
    if (format == drivers::CandumpFormat::kLog) {
      check(rec.has_stamp && rec.interface_name[0] != '\0');
      char buf[drivers::kMaxCandumpLogLine];
      const std::size_t n = drivers::format_candump_log_line(rec, buf, sizeof buf);
      check(n > 0U && n < sizeof buf);
      drivers::CandumpRecord back;
      check(drivers::parse_candump_log_line(std::string_view(buf, n), back).kind == drivers::CandumpLineKind::kFrame);
      check(back.frame.id == rec.frame.id && back.frame.dlc == rec.frame.dlc && back.stamp_us == rec.stamp_us);
      if (!rec.frame.is_rtr()) check(std::memcmp(back.frame.data, rec.frame.data, rec.frame.dlc) == 0);
    }
  }
  check(reader.next(rec) == 0);  // the end stays the end
  check(reader.line_number() == lines);
  check(reader.frames() == counts.frames && reader.errors() == counts.errors);
  check(reader.frames() + reader.errors() + reader.comments() == lines);
  return counts;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = [] {
    const char* tmp = std::getenv("TMPDIR");
    return std::string(tmp != nullptr ? tmp : "/tmp") + "/fuzz_candump_file." + std::to_string(::getpid()) + ".log";
  }();
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) return 0;
  std::fwrite(data, 1, size, f);
  std::fclose(f);
  std::size_t lines = 0;
  for (std::size_t i = 0; i < size; ++i) lines += data[i] == '\n' ? 1U : 0U;
  if (size > 0 && data[size - 1] != '\n') ++lines;

  const Counts log = read_all(path, drivers::CandumpFormat::kLog, lines);
  (void)read_all(path, drivers::CandumpFormat::kScreen, lines);

  FakeClock clock;
  daemon::CandumpReplayBus bus(clock, daemon::CandumpReplayOptions{});
  std::string error;
  check(bus.open(path, &error));
  std::size_t received = 0;
  for (std::size_t step = 0; step <= log.frames && !bus.ended(); ++step) {
    const std::int64_t due = bus.next_due_us();
    if (due > clock.now) clock.now = due;
    hal::CanFrame frame;
    int r = 0;
    while ((r = bus.receive(frame)) == 1) {
      check(frame.dlc <= 8U && !frame.is_error());
      ++received;
    }
    check(r == 0);
  }
  check(bus.ended());
  check(received == bus.stats().rx_frames);
  check(bus.stats().rx_frames + bus.stats().error_frames == log.frames);
  check(bus.bad_line_count() == log.errors);
  std::remove(path.c_str());
  return 0;
}
