// The text of the JSON outputs (io/json_text.h): whatever a string holds, the text parses
// back to it; numbers stay numbers and non-finite ones become null; the line layout the
// scripts grep is kept.
#include <CppUTest/TestHarness.h>

#include <cmath>
#include <limits>
#include <string>

#include "sdpslam/io/json_text.h"

using sdpslam::io::Json;
using sdpslam::io::json_fixed;
using sdpslam::io::json_text;

namespace {

Json parsed(const std::string& text) { return Json::parse(text, nullptr, false); }

}  // namespace

TEST_GROUP(JsonText){};

TEST(JsonText, strings_with_quotes_backslashes_and_control_characters_read_back) {
  const std::string nasty = "C:\\logs\\\"we\"ird\"\\n\t\x01\x1f end \xc3\xa9\xe2\x82\xac";
  Json doc;
  doc["log"] = nasty;
  doc[nasty] = {{"inner", nasty}};
  const std::string text = json_text(doc);
  const Json back = parsed(text);
  CHECK_FALSE_TEXT(back.is_discarded(), text.c_str());
  STRCMP_EQUAL(nasty.c_str(), back["log"].get<std::string>().c_str());
  STRCMP_EQUAL(nasty.c_str(), back[nasty]["inner"].get<std::string>().c_str());
  CHECK_TRUE(back == doc);
}

// Paths are bytes; JSON text is UTF-8. A byte that is not UTF-8 becomes U+FFFD rather than
// an exception or an invalid file.
TEST(JsonText, bytes_that_are_not_utf8_are_replaced_not_thrown) {
  Json doc;
  doc["log"] = std::string("/data/\xff\xfe.clf");
  const Json back = parsed(json_text(doc));
  CHECK_FALSE(back.is_discarded());
  STRCMP_EQUAL("/data/\xef\xbf\xbd\xef\xbf\xbd.clf", back["log"].get<std::string>().c_str());
}

TEST(JsonText, numbers_stay_numbers_and_non_finite_ones_become_null) {
  Json doc;
  doc["count"] = std::uint64_t{18446744073709551615U};
  doc["signed"] = std::int64_t{-1};
  doc["whole"] = 5.0;
  doc["third"] = 1.0 / 3.0;
  doc["nan"] = std::numeric_limits<double>::quiet_NaN();
  doc["inf"] = -std::numeric_limits<double>::infinity();
  const std::string text = json_text(doc);
  const Json back = parsed(text);
  CHECK_FALSE_TEXT(back.is_discarded(), text.c_str());
  CHECK_TRUE(back["count"].is_number_unsigned());
  CHECK_TRUE(back["count"].get<std::uint64_t>() == 18446744073709551615U);
  LONGS_EQUAL(-1, back["signed"].get<long>());
  CHECK_TRUE(back["whole"].is_number_float());
  DOUBLES_EQUAL(5.0, back["whole"].get<double>(), 0.0);
  CHECK_TRUE(back["third"].get<double>() == 1.0 / 3.0);  // every digit that tells the double apart
  CHECK_TRUE(back["nan"].is_null());
  CHECK_TRUE(back["inf"].is_null());
}

// An object or array of scalars is one line; anything holding one is spread over lines,
// two spaces per level, members in the order they were added.
TEST(JsonText, flat_members_stay_on_one_line_and_the_rest_is_indented) {
  Json doc;
  doc["mode"] = "sdp";
  doc["pools"] = {{"tiles", {{"capacity", 4}, {"peak", 2}}}, {"dropped", 0}};
  doc["empty"] = Json::object();
  doc["list"] = {1, 2};
  doc["timing"] = {{"wall_time_s", 1.5}, {"ok", true}};
  STRCMP_EQUAL(
      "{\n"
      "  \"mode\": \"sdp\",\n"
      "  \"pools\": {\n"
      "    \"tiles\": {\"capacity\": 4, \"peak\": 2},\n"
      "    \"dropped\": 0\n"
      "  },\n"
      "  \"empty\": {},\n"
      "  \"list\": [1, 2],\n"
      "  \"timing\": {\"wall_time_s\": 1.5, \"ok\": true}\n"
      "}\n",
      json_text(doc).c_str());
}

TEST(JsonText, fixed_rounds_to_the_decimals_asked_and_passes_non_finite_values) {
  DOUBLES_EQUAL(1.235, json_fixed(1.23456, 3), 0.0);
  DOUBLES_EQUAL(-0.5, json_fixed(-0.49999, 3), 0.0);
  DOUBLES_EQUAL(2.0, json_fixed(1.6, 0), 0.0);
  Json doc;
  doc["ms"] = json_fixed(12.3456789, 3);
  STRCMP_EQUAL("{\"ms\": 12.346}\n", json_text(doc).c_str());
  CHECK_TRUE(std::isnan(json_fixed(std::nan(""), 3)));
  DOUBLES_EQUAL(1e300, json_fixed(1e300, 9), 0.0);
}
