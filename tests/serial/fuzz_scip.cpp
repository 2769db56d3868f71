// libFuzzer: the SCIP 2.0 parser fed arbitrary bytes in arbitrary chunks, plus the PP/VV
// interpreters on whatever replies come out. Invariants checked on every reply.
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "sdpslam/drivers/scip2.h"

namespace scip2 = sdpslam::drivers::scip2;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static scip2::Parser parser;  // ~6 KiB: keep it off the stack
  parser = scip2::Parser{};
  scip2::SensorClock clock;
  // The first byte chooses the chunk size, so chunk boundaries get fuzzed too.
  const std::size_t chunk = size > 0 ? (data[0] % 67U) + 1U : 1U;
  std::size_t pos = size > 0 ? 1U : 0U;
  std::int64_t host_us = 0;
  while (pos < size) {
    const std::size_t n = size - pos < chunk ? size - pos : chunk;
    std::size_t used = 0;
    const auto ev = parser.feed(data + pos, n, &used);
    if (used == 0 || used > n) std::abort();
    pos += used;
    if (ev == scip2::Parser::Event::kReply) {
      const scip2::Reply& r = parser.reply();
      if (r.value_count > scip2::kMaxValues) std::abort();
      if (r.is_scan && r.value_count != r.request.value_count()) std::abort();
      scip2::SensorParams sp;
      (void)scip2::parse_pp(r, &sp);
      scip2::VersionInfo vv;
      (void)scip2::parse_vv(r, &vv);
      if (r.has_timestamp) {
        host_us += 100000;
        (void)clock.map_us(r.timestamp_ms, host_us);
      }
    }
  }
  return 0;
}
