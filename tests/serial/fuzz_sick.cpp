// libFuzzer: the LMS2xx telegram parser (with its rescan/replay) and the B0 decoder on
// arbitrary bytes in arbitrary chunks. Accepted telegrams must verify their own CRC.
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "sdpslam/drivers/lms2xx.h"

namespace lms2xx = sdpslam::drivers::lms2xx;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static lms2xx::Parser parser;
  static lms2xx::MeasuredValues mv;
  parser = lms2xx::Parser{};
  const std::size_t chunk = size > 0 ? (data[0] % 97U) + 1U : 1U;
  std::size_t pos = size > 0 ? 1U : 0U;
  std::size_t stalls = 0;
  while (pos < size) {
    const std::size_t n = size - pos < chunk ? size - pos : chunk;
    std::size_t used = 0;
    const auto ev = parser.feed(data + pos, n, &used);
    if (used > n) std::abort();
    if (used == 0 && ++stalls > 4 * lms2xx::kMaxTelegram) std::abort();  // replay must drain
    pos += used;
    if (ev == lms2xx::Parser::Event::kTelegram) {
      const lms2xx::Telegram& t = parser.telegram();
      std::uint8_t framed[lms2xx::kMaxTelegram];
      const std::size_t len = lms2xx::build_telegram(t.address, t.body, t.length, framed, sizeof framed);
      if (len != t.length + 6U) std::abort();
      if (lms2xx::decode_b0(t, &mv) == lms2xx::B0Error::kNone && mv.count > lms2xx::kMaxValues) std::abort();
    }
  }
  return 0;
}
