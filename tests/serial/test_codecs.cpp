// SCIP 2.0 and LMS2xx codecs on crafted bytes: boundaries, misuse, resynchronisation.
#include <CppUTest/TestHarness.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "sdpslam/drivers/lms2xx.h"
#include "sdpslam/drivers/scip2.h"

namespace scip2 = sdpslam::drivers::scip2;
namespace lms2xx = sdpslam::drivers::lms2xx;

namespace {

std::string line(const std::string& d) { return d + scip2::checksum(d.data(), d.size()) + "\n"; }

// A GD reply for steps [0, count) of 3-char values v[i] = i * 3 + 20, in 64-char blocks.
std::string gd_reply(std::uint32_t count) {
  char echo[16];
  std::snprintf(echo, sizeof echo, "GD%04u%04u01", 0U, count - 1U);
  std::string data;
  for (std::uint32_t i = 0; i < count; ++i) {
    char e[3];
    scip2::encode(i * 3U + 20U, 3, e);
    data.append(e, 3);
  }
  std::string out = std::string(echo) + "\n00P\n" + line("0000");
  for (std::size_t p = 0; p < data.size(); p += 64) out += line(data.substr(p, 64));
  return out + "\n";
}

struct Fed {
  int replies = 0;
  int errors = 0;
  scip2::Reply last;
};
Fed feed_all(scip2::Parser& p, const std::string& s) {
  Fed f;
  std::size_t pos = 0;
  while (pos < s.size()) {
    std::size_t used = 0;
    const auto ev = p.feed(reinterpret_cast<const std::uint8_t*>(s.data()) + pos, s.size() - pos, &used);
    pos += used;
    if (ev == scip2::Parser::Event::kReply) {
      ++f.replies;
      f.last = p.reply();
    }
    if (ev == scip2::Parser::Event::kError) ++f.errors;
  }
  return f;
}

}  // namespace

TEST_GROUP(Scip2Codec) {};

TEST(Scip2Codec, decode_rejects_chars_outside_the_6_bit_alphabet_and_bad_lengths) {
  std::uint32_t v = 77;
  CHECK_FALSE(scip2::decode("0/", 2, &v));
  CHECK_FALSE(scip2::decode("0p", 2, &v));
  CHECK_FALSE(scip2::decode("00000", 5, &v));
  CHECK_FALSE(scip2::decode("", 0, &v));
  LONGS_EQUAL(77, v);
}

TEST(Scip2Codec, encode_round_trips_and_refuses_values_that_do_not_fit) {
  char e[4];
  CHECK(scip2::encode(5432, 3, e));
  std::uint32_t v = 0;
  CHECK(scip2::decode(e, 3, &v));
  LONGS_EQUAL(5432, v);
  CHECK_FALSE(scip2::encode(1U << 18U, 3, e));
  CHECK_FALSE(scip2::encode(1U << 24U, 4, e));
}

TEST(Scip2Codec, value_straddling_two_blocks_is_joined) {
  scip2::Parser p;
  const Fed f = feed_all(p, gd_reply(30));  // 90 chars: value 21 spans chars 63..65
  LONGS_EQUAL(1, f.replies);
  LONGS_EQUAL(30, f.last.value_count);
  LONGS_EQUAL(21 * 3 + 20, f.last.values[21]);
}

TEST(Scip2Codec, bad_status_checksum_is_rejected_and_next_reply_is_delivered) {
  scip2::Parser p;
  const Fed f = feed_all(p, "BM\n00Q\n\n" + gd_reply(5));
  LONGS_EQUAL(1, f.errors);
  LONGS_EQUAL(1, f.replies);
  LONGS_EQUAL(1, p.stats().checksum_error_count);
  STRCMP_EQUAL("GD0000000401", f.last.command);
}

TEST(Scip2Codec, error_offset_names_the_first_byte_of_the_bad_line) {
  scip2::Parser p;
  std::string s = gd_reply(5);
  const std::size_t ts_line = s.find("00P\n") + 4;
  s[ts_line + 4] = static_cast<char>(s[ts_line + 4] ^ 1);  // timestamp checksum char
  feed_all(p, s);
  CHECK(p.last_error() == scip2::Error::kChecksum);
  LONGS_EQUAL(ts_line, p.last_error_offset());
}

TEST(Scip2Codec, overlong_line_is_an_error_and_parser_recovers) {
  scip2::Parser p;
  const Fed f = feed_all(p, std::string(200, 'A') + "\n\n" + gd_reply(3));
  LONGS_EQUAL(1, f.errors);
  LONGS_EQUAL(1, f.replies);
  CHECK(p.last_error() == scip2::Error::kLineTooLong);
}

TEST(Scip2Codec, unknown_first_line_is_not_an_echo) {
  scip2::Parser p;
  const Fed f = feed_all(p, "ZZ\n00P\n\n");
  LONGS_EQUAL(1, f.errors);
  CHECK(p.last_error() == scip2::Error::kNotAnEcho);
}

TEST(Scip2Codec, md_acknowledgement_carries_no_scan) {
  scip2::Parser p;
  const Fed f = feed_all(p, "MD0000000401000\n00P\n\n");
  LONGS_EQUAL(1, f.replies);
  CHECK_FALSE(f.last.is_scan);
  LONGS_EQUAL(0, f.last.value_count);
}

TEST(Scip2Codec, scip11_answer_to_scip20_is_accepted_as_ok) {
  scip2::Parser p;
  const Fed f = feed_all(p, "SCIP2.0\n0\n\n");
  LONGS_EQUAL(1, f.replies);
  CHECK(f.last.status_ok());
}

TEST(Scip2Codec, request_larger_than_capacity_is_refused) {
  scip2::Parser p;
  const Fed f = feed_all(p, "GD0000999901\n00P\n\n");
  LONGS_EQUAL(1, f.errors);
  CHECK(p.last_error() == scip2::Error::kTooManyValues);
}

TEST(Scip2Codec, pp_missing_field_is_refused) {
  scip2::Parser p;
  const Fed f = feed_all(p, "PP\n00P\n" + line("DMIN:20;").substr(0, 0) + "DMIN:20;4\n\n");
  LONGS_EQUAL(1, f.replies);
  scip2::SensorParams sp;
  CHECK_FALSE(scip2::parse_pp(f.last, &sp));
}

TEST(Scip2Codec, builders_produce_exact_commands_and_refuse_out_of_range) {
  char out[32];
  std::size_t n = scip2::build_scan(true, 3, 44, 725, 1, 0, 0, out, sizeof out);
  STRCMP_EQUAL("MD0044072501000\n", std::string(out, n).c_str());
  n = scip2::build_scan(false, 2, 0, 10, 2, 0, 0, out, sizeof out);
  STRCMP_EQUAL("GS0000001002\n", std::string(out, n).c_str());
  n = scip2::build_ss(750000, out, sizeof out);
  STRCMP_EQUAL("SS750000\n", std::string(out, n).c_str());
  LONGS_EQUAL(0, scip2::build_scan(true, 3, 10, 5, 1, 0, 0, out, sizeof out));
  LONGS_EQUAL(0, scip2::build_simple("QT", out, 2));
}

TEST(Scip2Codec, sensor_clock_unwraps_the_24_bit_counter) {
  scip2::SensorClock c;
  const std::int64_t a = c.map_us(0xFFFFFFU - 50U, 1000000);
  const std::int64_t b = c.map_us(49U, 1100000);  // 100 ms later, after the wrap
  LONGS_EQUAL(1, c.wrap_count());
  LONGS_EQUAL(100000, b - a);
}

TEST(Scip2Codec, sensor_clock_keeps_the_least_delayed_offset) {
  scip2::SensorClock c;
  c.map_us(1000, 5000000 + 3000);   // 3 ms transport delay
  c.map_us(1100, 5100000 + 500);    // 0.5 ms: the best
  const std::int64_t t = c.map_us(1200, 5200000 + 4000);
  LONGS_EQUAL(5200000 + 500, t);
}

TEST_GROUP(Lms2xxCodec) {};

TEST(Lms2xxCodec, ack_and_nak_outside_telegrams_are_events) {
  lms2xx::Parser p;
  const std::uint8_t b[] = {0x06, 0x15};
  std::size_t used = 0;
  CHECK(p.feed(b, 2, &used) == lms2xx::Parser::Event::kAck);
  LONGS_EQUAL(1, used);
  CHECK(p.feed(b + 1, 1, &used) == lms2xx::Parser::Event::kNak);
}

TEST(Lms2xxCodec, oversized_len_is_rejected_at_the_header) {
  lms2xx::Parser p;
  const std::uint8_t b[] = {0x02, 0x80, 0xFF, 0x7F};
  std::size_t used = 0;
  CHECK(p.feed(b, 4, &used) == lms2xx::Parser::Event::kError);
  CHECK(p.last_error() == lms2xx::Error::kBadLength);
}

TEST(Lms2xxCodec, host_telegram_is_refused_by_a_scanner_side_parser) {
  std::uint8_t t[16];
  const std::size_t n = lms2xx::build_status_request(t, sizeof t);
  lms2xx::Parser p;
  std::size_t used = 0;
  CHECK(p.feed(t, n, &used) == lms2xx::Parser::Event::kError);
  CHECK(p.last_error() == lms2xx::Error::kBadAddress);
}

TEST(Lms2xxCodec, b0_with_count_not_matching_len_is_refused) {
  lms2xx::Telegram t;
  t.length = 8;
  const std::uint8_t body[] = {0xB0, 0x03, 0x40, 1, 0, 2, 0, 0x10};  // says 3 values, has 2
  std::memcpy(t.body, body, sizeof body);
  lms2xx::MeasuredValues mv;
  CHECK(lms2xx::decode_b0(t, &mv) == lms2xx::B0Error::kLengthMismatch);
}

TEST(Lms2xxCodec, b0_units_bits_select_cm_or_mm_and_unknown_is_refused) {
  lms2xx::Telegram t;
  t.length = 6;
  std::uint8_t body[] = {0xB0, 0x01, 0x00, 0x34, 0x12, 0x10};
  std::memcpy(t.body, body, sizeof body);
  lms2xx::MeasuredValues mv;
  CHECK(lms2xx::decode_b0(t, &mv) == lms2xx::B0Error::kNone);
  CHECK(mv.units == lms2xx::Units::kCentimetre);
  LONGS_EQUAL(0x1234, mv.distance[0]);
  t.body[2] = 0x80;
  CHECK(lms2xx::decode_b0(t, &mv) == lms2xx::B0Error::kBadUnits);
}

TEST(Lms2xxCodec, builders_refuse_rates_and_variants_the_scanner_lacks) {
  std::uint8_t t[32];
  LONGS_EQUAL(0, lms2xx::build_baud_switch(115200, t, sizeof t));
  LONGS_EQUAL(0, lms2xx::build_variant(180, 25, t, sizeof t));
  LONGS_EQUAL(0, lms2xx::build_variant(90, 50, t, sizeof t));
  LONGS_EQUAL(0, lms2xx::build_start_streaming(t, 7));
}
