#include <CppUTest/TestHarness.h>

#include <cstdio>
#include <cstring>
#include <string>

#include "sdpslam/drivers/candump_log.h"
#include "shared_data.h"

using namespace sdpslam;
using namespace sdpslam::drivers;

TEST_GROUP(CandumpLogLine){};

TEST(CandumpLogLine, standard_frame_with_stamp_and_interface) {
  CandumpRecord r;
  const auto res = parse_candump_log_line("(1700000000.010300) can0 185#45230100\n", r);
  CHECK(res.kind == CandumpLineKind::kFrame);
  LONGS_EQUAL(1700000000010300LL, r.stamp_us);
  STRCMP_EQUAL("can0", r.interface_name);
  LONGS_EQUAL(0x185, r.frame.id);
  LONGS_EQUAL(4, r.frame.dlc);
  LONGS_EQUAL(0x45, r.frame.data[0]);
  LONGS_EQUAL(0x00, r.frame.data[3]);
}

TEST(CandumpLogLine, empty_data_is_dlc_zero) {
  CandumpRecord r;
  CHECK(parse_candump_log_line("(1.000000) can0 080#", r).kind == CandumpLineKind::kFrame);
  LONGS_EQUAL(0x080, r.frame.id);
  LONGS_EQUAL(0, r.frame.dlc);
}

TEST(CandumpLogLine, eight_digit_id_is_extended) {
  CandumpRecord r;
  CHECK(parse_candump_log_line("(1.000000) can0 00000901#000003E8003200FA", r).kind == CandumpLineKind::kFrame);
  CHECK_TRUE(r.frame.is_extended());
  LONGS_EQUAL(0x901, r.frame.arbitration_id());
  LONGS_EQUAL(8, r.frame.dlc);
}

TEST(CandumpLogLine, rtr_with_and_without_length) {
  CandumpRecord r;
  CHECK(parse_candump_log_line("(1.000000) can0 029#R", r).kind == CandumpLineKind::kFrame);
  CHECK_TRUE(r.frame.is_rtr());
  LONGS_EQUAL(0, r.frame.dlc);
  CHECK(parse_candump_log_line("(1.000000) can0 029#R8", r).kind == CandumpLineKind::kFrame);
  LONGS_EQUAL(8, r.frame.dlc);
  const auto bad = parse_candump_log_line("(1.000000) can0 029#R9", r);
  CHECK(bad.error == CandumpError::kBadDlc);
  LONGS_EQUAL(22, bad.column);
}

TEST(CandumpLogLine, error_frame_keeps_error_flag_not_extended) {
  CandumpRecord r;
  CHECK(parse_candump_log_line("(1.000000) can0 20000080#0000000000000000", r).kind == CandumpLineKind::kFrame);
  CHECK_TRUE(r.frame.is_error());
  CHECK_FALSE(r.frame.is_extended());
  UNSIGNED_LONGS_EQUAL(0x20000080u, r.frame.id);
}

TEST(CandumpLogLine, dot_separated_bytes_are_accepted) {
  CandumpRecord r;
  CHECK(parse_candump_log_line("(1.000000) can0 123#11.22.33", r).kind == CandumpLineKind::kFrame);
  LONGS_EQUAL(3, r.frame.dlc);
  LONGS_EQUAL(0x33, r.frame.data[2]);
}

TEST(CandumpLogLine, line_not_starting_with_paren_is_comment) {
  CandumpRecord r;
  r.frame.id = 0x55;
  CHECK(parse_candump_log_line("# (1.000000) can0 123#11", r).kind == CandumpLineKind::kComment);
  CHECK(parse_candump_log_line("", r).kind == CandumpLineKind::kComment);
  CHECK(parse_candump_log_line(" (1.000000) can0 123#11", r).kind == CandumpLineKind::kComment);
  LONGS_EQUAL(0x55, r.frame.id);
}

TEST(CandumpLogLine, text_after_the_frame_is_ignored_like_canplayer) {
  CandumpRecord r;
  CHECK(parse_candump_log_line("(1.000000) can0 705#05            # heartbeat", r).kind == CandumpLineKind::kFrame);
  LONGS_EQUAL(1, r.frame.dlc);
}

TEST(CandumpLogLine, malformed_lines_name_reason_and_column) {
  CandumpRecord r;
  struct Case {
    const char* line;
    CandumpError error;
    std::size_t column;
  };
  const Case cases[] = {
      {"(1.0003) can0 123#11", CandumpError::kBadTimestamp, 8},
      {"(1.000000 can0 123#11", CandumpError::kBadTimestamp, 10},
      {"(x.000000) can0 123#11", CandumpError::kBadTimestamp, 2},
      {"(1.000000)", CandumpError::kMissingInterface, 11},
      {"(1.000000) can0", CandumpError::kMissingFrame, 16},
      {"(1.000000) averyveryverylongname 123#11", CandumpError::kInterfaceTooLong, 12},
      {"(1.000000) can0 12#11", CandumpError::kBadId, 17},
      {"(1.000000) c\x01n0 123#11", CandumpError::kBadInterfaceChar, 13},
      {"(1.000000) can0 800#11", CandumpError::kIdOutOfRange, 17},
      {"(1.000000) can0 1G3#11", CandumpError::kBadHexDigit, 18},
      {"(1.000000) can0 123", CandumpError::kMissingSeparator, 20},
      {"(1.000000) can0 123##1112", CandumpError::kCanFdUnsupported, 21},
      {"(1.000000) can0 123#112", CandumpError::kOddHexDigits, 23},
      {"(1.000000) can0 123#11Z2", CandumpError::kBadHexDigit, 23},
      {"(1.000000) can0 123#112233445566778899", CandumpError::kTooManyBytes, 37},
  };
  for (const Case& c : cases) {
    const auto res = parse_candump_log_line(c.line, r);
    CHECK_TEXT(res.kind == CandumpLineKind::kError, c.line);
    CHECK_TEXT(res.error == c.error, c.line);
    LONGS_EQUAL_TEXT(c.column, res.column, c.line);
  }
}

TEST(CandumpLogLine, format_then_parse_round_trips_every_kind) {
  hal::CanFrame frames[4];
  frames[0] = hal::CanFrame::standard(0x185, reinterpret_cast<const std::uint8_t*>("\x45\x23\x01\x00"), 4);
  frames[1].id = 0x1B01 | hal::CanFrame::kExtendedFlag;
  frames[1].dlc = 8;
  frames[1].data[7] = 0xFA;
  frames[2].id = 0x029 | hal::CanFrame::kRtrFlag;
  frames[2].dlc = 8;
  frames[3].id = 0x20000080u;
  frames[3].dlc = 8;
  for (const auto& f : frames) {
    CandumpRecord rec;
    rec.stamp_us = 1700000000000100LL;
    std::strcpy(rec.interface_name, "vcan0");
    rec.frame = f;
    char buf[kMaxCandumpLogLine];
    const std::size_t n = format_candump_log_line(rec, buf, sizeof buf);
    CHECK_TRUE(n > 0);
    CandumpRecord back;
    CHECK_TEXT(parse_candump_log_line(std::string_view(buf, n), back).kind == CandumpLineKind::kFrame, buf);
    UNSIGNED_LONGS_EQUAL(f.id, back.frame.id);
    LONGS_EQUAL(f.dlc, back.frame.dlc);
    if (!f.is_rtr()) MEMCMP_EQUAL(f.data, back.frame.data, f.dlc);
    LONGS_EQUAL(rec.stamp_us, back.stamp_us);
  }
}

TEST(CandumpLogLine, format_writes_candump_syntax) {
  CandumpRecord rec;
  rec.stamp_us = 1700000000010300LL;
  std::strcpy(rec.interface_name, "can0");
  const std::uint8_t b[4] = {0x45, 0x23, 0x01, 0x00};
  rec.frame = hal::CanFrame::standard(0x185, b, 4);
  char buf[kMaxCandumpLogLine];
  format_candump_log_line(rec, buf, sizeof buf);
  STRCMP_EQUAL("(1700000000.010300) can0 185#45230100\n", buf);
}

TEST(CandumpLogLine, format_refuses_small_buffer_and_bad_record) {
  CandumpRecord rec;
  char buf[kMaxCandumpLogLine];
  LONGS_EQUAL(0, format_candump_log_line(rec, buf, sizeof buf));  // no interface
  std::strcpy(rec.interface_name, "can0");
  LONGS_EQUAL(0, format_candump_log_line(rec, buf, 10));
  rec.frame.dlc = 9;
  LONGS_EQUAL(0, format_candump_log_line(rec, buf, sizeof buf));
}

TEST_GROUP(CandumpScreenLine){};

TEST(CandumpScreenLine, default_candump_output_parses) {
  CandumpRecord r;
  CHECK(parse_candump_screen_line("  can0  620   [8]  80 00 10 00 00 00 04 05", r).kind == CandumpLineKind::kFrame);
  LONGS_EQUAL(0x620, r.frame.id);
  LONGS_EQUAL(8, r.frame.dlc);
  LONGS_EQUAL(0x05, r.frame.data[7]);
  CHECK_FALSE(r.has_stamp);
  CHECK(parse_candump_screen_line("  can0  080   [0] ", r).kind == CandumpLineKind::kFrame);
  LONGS_EQUAL(0, r.frame.dlc);
}

TEST(CandumpScreenLine, remote_request_and_stamp_prefix) {
  CandumpRecord r;
  CHECK(parse_candump_screen_line(" (1700000000.300000)  can0  029   [8]  remote request", r).kind ==
        CandumpLineKind::kFrame);
  CHECK_TRUE(r.frame.is_rtr());
  LONGS_EQUAL(8, r.frame.dlc);
  CHECK_TRUE(r.has_stamp);
}

TEST(CandumpScreenLine, byte_count_must_match_dlc) {
  CandumpRecord r;
  CHECK(parse_candump_screen_line("  can0  720   [2]  00", r).error == CandumpError::kBadDlc);
  CHECK(parse_candump_screen_line("  can0  720   [1]  00 01", r).error == CandumpError::kBadDlc);
  CHECK(parse_candump_screen_line("  can0  720   [9]  00", r).error == CandumpError::kBadDlc);
  CHECK(parse_candump_screen_line("  can0  720   1  00", r).error == CandumpError::kMissingSeparator);
}

TEST_GROUP(CandumpFiles) {
  std::string dir;
  void setup() override { dir = test::make_temp_dir("candump"); }
};

TEST(CandumpFiles, reader_reports_line_number_and_keeps_good_lines) {
  const std::string path = dir + "/mixed.log";
  std::FILE* f = std::fopen(path.c_str(), "w");
  std::fputs("# header\n(1.000000) can0 185#01020304\n(1.000100) can0 18#01\n(1.000200) can0 186#0506\n", f);
  std::fclose(f);
  CandumpReader reader;
  CHECK_TRUE(reader.open(path.c_str()));
  CandumpRecord r;
  LONGS_EQUAL(1, reader.next(r));
  LONGS_EQUAL(2, reader.line_number());
  LONGS_EQUAL(-1, reader.next(r));
  LONGS_EQUAL(3, reader.line_number());
  CHECK(reader.error() == CandumpError::kBadId);
  LONGS_EQUAL(17, reader.column());
  LONGS_EQUAL(1, reader.next(r));
  LONGS_EQUAL(0x186, r.frame.id);
  LONGS_EQUAL(0, reader.next(r));
  LONGS_EQUAL(2, reader.frames());
  LONGS_EQUAL(1, reader.errors());
  LONGS_EQUAL(1, reader.comments());
}

TEST(CandumpFiles, over_long_line_is_one_error_and_reading_continues) {
  const std::string path = dir + "/long.log";
  std::FILE* f = std::fopen(path.c_str(), "w");
  std::fputs("(1.000000) can0 123#", f);
  for (int i = 0; i < 1000; ++i) std::fputc('A', f);
  std::fputs("\n(2.000000) can0 124#\n", f);
  std::fclose(f);
  CandumpReader reader;
  reader.open(path.c_str());
  CandumpRecord r;
  LONGS_EQUAL(-1, reader.next(r));
  CHECK(reader.error() == CandumpError::kLineTooLong);
  LONGS_EQUAL(1, reader.next(r));
  LONGS_EQUAL(0x124, r.frame.id);
  LONGS_EQUAL(2, reader.line_number());
}

TEST(CandumpFiles, missing_file_fails_open_and_next_reports_io_error) {
  CandumpReader reader;
  CHECK_FALSE(reader.open((dir + "/absent.log").c_str()));
  CandumpRecord r;
  LONGS_EQUAL(-1, reader.next(r));
  CHECK(reader.error() == CandumpError::kIoError);
}

TEST(CandumpFiles, writer_output_reads_back_identically) {
  const std::string path = dir + "/out.log";
  CandumpWriter w;
  CHECK_TRUE(w.open(path.c_str()));
  CandumpRecord rec;
  std::strcpy(rec.interface_name, "can0");
  for (int i = 0; i < 50; ++i) {
    rec.stamp_us = 1700000000000000LL + i * 10000;
    const std::uint8_t b[4] = {static_cast<std::uint8_t>(i), 0, 0, 0};
    rec.frame = hal::CanFrame::standard(0x185, b, 4);
    CHECK_TRUE(w.write(rec));
  }
  CHECK_TRUE(w.close());
  CandumpReader reader;
  reader.open(path.c_str());
  CandumpRecord r;
  int n = 0;
  while (reader.next(r) == 1) {
    LONGS_EQUAL(n, r.frame.data[0]);
    LONGS_EQUAL(1700000000000000LL + n * 10000, r.stamp_us);
    ++n;
  }
  LONGS_EQUAL(50, n);
  LONGS_EQUAL(0, reader.errors());
}

TEST(CandumpFiles, nul_byte_in_a_line_is_reported_not_truncated_away) {
  const std::string path = dir + "/nul.log";
  std::FILE* f = std::fopen(path.c_str(), "w");
  const char line[] = "(1.000000) c\0n0 123#11\n(2.000000) can0 124#\n";
  std::fwrite(line, 1, sizeof line - 1, f);
  std::fclose(f);
  CandumpReader reader;
  reader.open(path.c_str());
  CandumpRecord r;
  LONGS_EQUAL(-1, reader.next(r));
  CHECK(reader.error() == CandumpError::kBadInterfaceChar);
  LONGS_EQUAL(13, reader.column());
  LONGS_EQUAL(1, reader.next(r));
  LONGS_EQUAL(0x124, r.frame.id);
}
