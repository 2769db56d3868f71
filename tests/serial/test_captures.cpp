// SCIP 2.0 and SICK LMS2xx codecs against the real captures and published vectors in
// ../shared/testdata/sensors (see its README). Registered NEEDS_SHARED.
#include <CppUTest/TestHarness.h>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "sdpslam/drivers/lms2xx.h"
#include "sdpslam/drivers/scip2.h"
#include "shared_data.h"

namespace scip2 = sdpslam::drivers::scip2;
namespace lms2xx = sdpslam::drivers::lms2xx;

namespace {

std::vector<std::uint8_t> read_bytes(const std::string& rel) {
  std::ifstream f(sdpslam::test::shared_path(rel), std::ios::binary);
  return std::vector<std::uint8_t>((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
}

std::vector<std::string> read_lines(const std::string& rel) {
  std::ifstream f(sdpslam::test::shared_path(rel));
  std::vector<std::string> lines;
  std::string line;
  while (std::getline(f, line)) lines.push_back(line);
  return lines;
}

// Feeds bytes in chunks of `chunk`, collecting replies; fails the test on any error event.
struct ScipRun {
  scip2::Parser parser;
  std::vector<scip2::Reply> replies;
  int errors = 0;
  void feed(const std::vector<std::uint8_t>& bytes, std::size_t chunk) {
    std::size_t pos = 0;
    while (pos < bytes.size()) {
      std::size_t n = bytes.size() - pos < chunk ? bytes.size() - pos : chunk;
      while (n > 0) {
        std::size_t used = 0;
        const auto ev = parser.feed(bytes.data() + pos, n, &used);
        pos += used;
        n -= used;
        if (ev == scip2::Parser::Event::kReply) replies.push_back(parser.reply());
        if (ev == scip2::Parser::Event::kError) ++errors;
      }
    }
  }
};

std::uint32_t count_below_20(const scip2::Reply& r) {
  std::uint32_t n = 0;
  for (std::uint32_t i = 0; i < r.value_count; ++i) n += r.values[i] < 20U ? 1U : 0U;
  return n;
}

// Trailing tokens of a line that are exactly two hex digits.
std::vector<std::uint8_t> trailing_hex(const std::string& line) {
  std::istringstream is(line);
  std::vector<std::string> tokens;
  std::string t;
  while (is >> t) tokens.push_back(t);
  std::vector<std::uint8_t> out;
  std::size_t first = tokens.size();
  while (first > 0) {
    const std::string& s = tokens[first - 1];
    if (s.size() != 2 || !std::isxdigit(static_cast<unsigned char>(s[0])) ||
        !std::isxdigit(static_cast<unsigned char>(s[1]))) {
      break;
    }
    --first;
  }
  for (std::size_t i = first; i < tokens.size(); ++i) {
    out.push_back(static_cast<std::uint8_t>(std::stoul(tokens[i], nullptr, 16)));
  }
  return out;
}

}  // namespace

TEST_GROUP(ScipCaptures) {};

TEST(ScipCaptures, capA_decodes_682_values_with_timestamp_and_step_384) {
  ScipRun run;
  run.feed(read_bytes("testdata/sensors/scip-urg04lx-ug01-GD-capA.bin"), 1 << 20);
  LONGS_EQUAL(0, run.errors);
  LONGS_EQUAL(1, run.replies.size());
  const scip2::Reply& r = run.replies[0];
  STRCMP_EQUAL("GD0044072501", r.command);
  CHECK(r.status_is("00"));
  CHECK(r.is_scan);
  LONGS_EQUAL(682, r.value_count);
  LONGS_EQUAL(11149560, r.timestamp_ms);
  LONGS_EQUAL(293, r.values[384 - 44]);
  LONGS_EQUAL(85, count_below_20(r));
}

TEST(ScipCaptures, capA_decodes_identically_when_fed_one_byte_at_a_time) {
  ScipRun whole;
  ScipRun bytewise;
  const auto bytes = read_bytes("testdata/sensors/scip-urg04lx-ug01-GD-capA.bin");
  whole.feed(bytes, 1 << 20);
  bytewise.feed(bytes, 1);
  LONGS_EQUAL(1, bytewise.replies.size());
  LONGS_EQUAL(0, bytewise.errors);
  MEMCMP_EQUAL(whole.replies[0].values, bytewise.replies[0].values, 682 * sizeof(std::uint32_t));
}

TEST(ScipCaptures, capB_decodes_682_values_with_timestamp_513) {
  ScipRun run;
  run.feed(read_bytes("testdata/sensors/scip-urg04lx-GD-capB.bin"), 7);
  LONGS_EQUAL(0, run.errors);
  LONGS_EQUAL(1, run.replies.size());
  LONGS_EQUAL(682, run.replies[0].value_count);
  LONGS_EQUAL(513, run.replies[0].timestamp_ms);
}

TEST(ScipCaptures, capA_with_one_flipped_data_byte_is_rejected_by_its_line_checksum) {
  auto bytes = read_bytes("testdata/sensors/scip-urg04lx-ug01-GD-capA.bin");
  bytes[200] = static_cast<std::uint8_t>(bytes[200] ^ 0x01U);  // inside a data block
  ScipRun run;
  run.feed(bytes, 64);
  LONGS_EQUAL(0, run.replies.size());
  LONGS_EQUAL(1, run.parser.stats().checksum_error_count);
  CHECK(run.parser.last_error() == scip2::Error::kChecksum);
}

TEST(ScipCaptures, vv_reply_yields_product_and_protocol) {
  std::string text;
  bool in_reply = false;
  for (const std::string& line : read_lines("testdata/sensors/scip-urg04lx-ug01-VV.txt")) {
    if (!in_reply && line == "VV") in_reply = true;
    if (!in_reply || (!line.empty() && line[0] == '#')) continue;
    text += line + "\n";
    if (line.empty()) break;
  }
  ScipRun run;
  run.feed(std::vector<std::uint8_t>(text.begin(), text.end()), 5);
  LONGS_EQUAL(0, run.errors);
  LONGS_EQUAL(1, run.replies.size());
  scip2::VersionInfo v;
  CHECK(scip2::parse_vv(run.replies[0], &v));
  STRCMP_EQUAL("Hokuyo Automatic Co.,Ltd.", v.vendor);
  STRCMP_EQUAL("SOKUIKI Sensor URG-04LX-UG01(Simple-URG)", v.product);
  STRCMP_EQUAL("3.4.03(17/Dec./2012)", v.firmware);
  STRCMP_EQUAL("SCIP 2.0", v.protocol);
  STRCMP_EQUAL("H1510998", v.serial);
}

TEST(ScipCaptures, every_checksum_and_decode_vector_holds) {
  int checked = 0;
  for (const std::string& line : read_lines("testdata/sensors/scip-vectors.txt")) {
    if (line.rfind("checksum", 0) == 0) {
      // Pairs like "00" = 'P' (spaces optional).
      std::size_t pos = 0;
      while ((pos = line.find('"', pos)) != std::string::npos) {
        const std::size_t end = line.find('"', pos + 1);
        const std::size_t q = line.find('\'', end);
        if (end == std::string::npos || q == std::string::npos) break;
        const std::string s = line.substr(pos + 1, end - pos - 1);
        const char expected = line[q + 1];
        CHECK_EQUAL(expected, scip2::checksum(s.data(), s.size()));
        ++checked;
        pos = q + 3;
      }
    } else if (line.rfind("decode", 0) == 0) {
      const std::size_t a = line.find('"');
      const std::size_t b = line.find('"', a + 1);
      const std::string s = line.substr(a + 1, b - a - 1);
      const std::uint32_t expected = static_cast<std::uint32_t>(std::stoul(line.substr(line.find('=', b) + 1)));
      std::uint32_t v = 0;
      CHECK(scip2::decode(s.data(), s.size(), &v));
      LONGS_EQUAL(expected, v);
      ++checked;
    }
  }
  LONGS_EQUAL(14, checked);  // 4 status + Hokuyo + 6 PP + 3 decode lines
}

TEST_GROUP(SickCaptures) {};

TEST(SickCaptures, b0_telegram_passes_crc_and_yields_361_mm_values) {
  const auto bytes = read_bytes("testdata/sensors/sick-lms2xx-B0-361mm.bin");
  LONGS_EQUAL(732, bytes.size());
  lms2xx::Parser parser;
  std::size_t used = 0;
  CHECK(parser.feed(bytes.data(), bytes.size(), &used) == lms2xx::Parser::Event::kTelegram);
  LONGS_EQUAL(732, used);
  lms2xx::MeasuredValues mv;
  CHECK(lms2xx::decode_b0(parser.telegram(), &mv) == lms2xx::B0Error::kNone);
  LONGS_EQUAL(361, mv.count);
  CHECK(mv.units == lms2xx::Units::kMillimetre);
  LONGS_EQUAL(0x10, mv.status);
  LONGS_EQUAL(0x08CB, mv.distance[0]);           // bytes CB 08
  LONGS_EQUAL(0x22D7 & 0x1FFF, mv.distance[359]);  // bytes D7 22: flag bits masked off
  LONGS_EQUAL(1, mv.flags[359]);
  LONGS_EQUAL(0x0518, mv.distance[360]);
  for (std::uint16_t i = 0; i < mv.count; ++i) CHECK(mv.distance[i] < lms2xx::kFirstErrorCode);
}

TEST(SickCaptures, b0_telegram_is_found_after_garbage_containing_false_stx) {
  const auto bytes = read_bytes("testdata/sensors/sick-lms2xx-B0-361mm.bin");
  std::vector<std::uint8_t> stream = {0x02, 0x80, 0x10, 0x00, 0x33, 0x02, 0x81};  // false starts
  stream.insert(stream.end(), bytes.begin(), bytes.end());
  lms2xx::Parser parser;
  int telegrams = 0;
  std::size_t pos = 0;
  while (pos < stream.size()) {
    std::size_t used = 0;
    if (parser.feed(stream.data() + pos, stream.size() - pos, &used) == lms2xx::Parser::Event::kTelegram) {
      ++telegrams;
      LONGS_EQUAL(0xB0, parser.telegram().command());
    }
    pos += used;
  }
  LONGS_EQUAL(1, telegrams);
  CHECK(parser.stats().resync_count >= 1);
}

TEST(SickCaptures, every_listed_telegram_verifies_and_parses) {
  int checked = 0;
  for (const std::string& line : read_lines("testdata/sensors/sick-lms2xx-telegrams.txt")) {
    if (line.empty() || line[0] == '#') continue;
    const auto t = trailing_hex(line);
    CHECK(t.size() >= 7);
    const std::uint16_t crc = lms2xx::crc16(t.data(), t.size() - 2);
    LONGS_EQUAL(t[t.size() - 2] | (t[t.size() - 1] << 8), crc);
    lms2xx::Parser parser(t[1] & 0x80U ? lms2xx::Parser::Source::kScanner : lms2xx::Parser::Source::kHost);
    std::size_t used = 0;
    CHECK(parser.feed(t.data(), t.size(), &used) == lms2xx::Parser::Event::kTelegram);
    LONGS_EQUAL(t.size(), used);
    ++checked;
  }
  LONGS_EQUAL(18, checked);  // 16 host commands + 2 scanner replies
}

TEST(SickCaptures, builders_reproduce_the_listed_command_telegrams) {
  struct Case {
    const char* name;
    std::size_t (*build)(std::uint8_t*, std::size_t);
  };
  std::vector<std::pair<std::string, std::vector<std::uint8_t>>> listed;
  for (const std::string& line : read_lines("testdata/sensors/sick-lms2xx-telegrams.txt")) {
    if (!line.empty() && line[0] != '#') listed.emplace_back(line, trailing_hex(line));
  }
  auto find = [&](const char* prefix) {
    for (const auto& e : listed) {
      if (e.first.rfind(prefix, 0) == 0) return e.second;
    }
    FAIL("listed telegram missing");
    return std::vector<std::uint8_t>{};
  };
  std::uint8_t out[32];
  std::size_t n = lms2xx::build_baud_switch(9600, out, sizeof out);
  CHECK(std::vector<std::uint8_t>(out, out + n) == find("baud_9600"));
  n = lms2xx::build_baud_switch(19200, out, sizeof out);
  CHECK(std::vector<std::uint8_t>(out, out + n) == find("baud_19200"));
  n = lms2xx::build_baud_switch(38400, out, sizeof out);
  CHECK(std::vector<std::uint8_t>(out, out + n) == find("baud_38400"));
  n = lms2xx::build_baud_switch(500000, out, sizeof out);
  CHECK(std::vector<std::uint8_t>(out, out + n) == find("baud_500k"));
  n = lms2xx::build_start_streaming(out, sizeof out);
  CHECK(std::vector<std::uint8_t>(out, out + n) == find("start_continuous"));
  n = lms2xx::build_stop_streaming(out, sizeof out);
  CHECK(std::vector<std::uint8_t>(out, out + n) == find("stop_continuous"));
  n = lms2xx::build_status_request(out, sizeof out);
  CHECK(std::vector<std::uint8_t>(out, out + n) == find("status_request_31"));
  n = lms2xx::build_variant(180, 50, out, sizeof out);
  CHECK(std::vector<std::uint8_t>(out, out + n) == find("variant 180deg/0.5"));
  n = lms2xx::build_variant(100, 25, out, sizeof out);
  CHECK(std::vector<std::uint8_t>(out, out + n) == find("variant 100deg/0.25"));
}
