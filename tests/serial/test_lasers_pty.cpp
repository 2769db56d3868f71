// UrgScip2Laser and SickLms2xxLaser end to end: SerialPort on a pseudo-terminal, a sensor
// emulator on the master side, injected faults. Every scan that comes out is checked
// value by value against the emulator's pattern, so a corrupted scan cannot pass.
#include <CppUTest/TestHarness.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include "sdpslam/drivers/linux_clock.h"
#include "sdpslam/drivers/serial_port.h"
#include "sdpslam/drivers/sick_lms2xx_laser.h"
#include "sdpslam/drivers/urg_scip2_laser.h"
#include "sensor_emulators.h"
#include "shared_data.h"

using sdpslam::RangeScan;
using sdpslam::drivers::LinuxMonotonicClock;
using sdpslam::drivers::SerialOptions;
using sdpslam::drivers::SerialPort;
using sdpslam::test::SickEmulator;
using sdpslam::test::UrgEmulator;

namespace {

// Missing scans in a sequence of ids taken modulo 1000.
int missing(const std::vector<int>& ids) {
  int m = 0;
  for (std::size_t i = 1; i < ids.size(); ++i) m += (ids[i] - ids[i - 1] + 1000) % 1000 - 1;
  return m;
}

int urg_scan_id(const RangeScan& s) {
  if (s.beam_count != 682U) return -1;
  const int id = static_cast<int>(std::lround(s.ranges_m[0] * 1000.0F)) - 1000;
  if (id < 0 || id >= 1000) return -1;
  for (std::uint32_t i = 0; i < s.beam_count; ++i) {
    const std::uint32_t v = UrgEmulator::value(static_cast<std::uint32_t>(id), i);
    const float expected = v < 20U ? 0.0F : static_cast<float>(v) * 0.001F;
    if (s.ranges_m[i] != expected) return -1;
  }
  return id;
}

int sick_scan_id(const RangeScan& s) {
  if (s.beam_count != 361U) return -1;
  const int id = static_cast<int>(std::lround(s.ranges_m[0] * 1000.0F)) - 1000;
  if (id < 0 || id >= 1000) return -1;
  for (std::uint32_t i = 0; i < s.beam_count; ++i) {
    const std::uint16_t d = SickEmulator::value(static_cast<std::uint32_t>(id), i) & 0x1FFFU;
    const float expected = (d == 0U || d >= 0x1FF7U) ? 0.0F : static_cast<float>(d) * 0.001F;
    if (s.ranges_m[i] != expected) return -1;
  }
  return id;
}

template <typename Emulator, typename Laser, typename Options>
struct Rig {
  LinuxMonotonicClock clock;
  std::string link;
  Emulator emu;
  SerialOptions serial_options;
  SerialPort port;
  Laser laser;
  RangeScan scan;
  std::vector<int> ids;
  std::vector<std::int64_t> stamps;
  int bad = 0;

  Rig(const std::string& tag, std::uint32_t baud, const Options& options)
      : link(sdpslam::test::make_temp_dir(tag) + "/tty" + tag),
        emu(link),
        serial_options(make_serial(link, baud)),
        port(serial_options, clock),
        laser(port, clock, options) {
    CHECK(port.open());
    emu.start();
  }
  static SerialOptions make_serial(const std::string& path, std::uint32_t baud) {
    SerialOptions o;
    o.path = path.c_str();
    o.baud = baud;
    o.reopen_interval_us = 50000;
    return o;
  }
  // Polls until `count` more scans arrived (true) or `timeout_us` passed (false).
  bool collect(int count, std::int64_t timeout_us, int (*id_of)(const RangeScan&)) {
    const std::int64_t end = clock.now_us() + timeout_us;
    int got = 0;
    while (got < count && clock.now_us() < end) {
      if (laser.poll(scan, 20000) == 1) {
        const int id = id_of(scan);
        if (id < 0) {
          ++bad;
        } else {
          ids.push_back(id);
          stamps.push_back(scan.stamp_us);
        }
        ++got;
      }
    }
    return got == count;
  }
  // Polls until scans up to `after` past the one the injected fault hit have arrived
  // (true), or `timeout_us` passed (false). On a loaded machine the driver falls behind
  // the emulator, and "the next few scans" read after inject() may all predate the fault.
  bool collect_past_fault(int after, std::int64_t timeout_us, int (*id_of)(const RangeScan&)) {
    const std::int64_t end = clock.now_us() + timeout_us;
    for (;;) {
      const int f = emu.faulted_scan();
      if (f >= 0 && !ids.empty() && ids.back() >= f + after) return true;
      const std::int64_t left = end - clock.now_us();
      if (left <= 0) return false;
      collect(1, left, id_of);
    }
  }
};

sdpslam::drivers::UrgOptions urg_options() {
  sdpslam::drivers::UrgOptions o;
  o.reply_timeout_us = 300000;
  o.stall_timeout_us = 400000;
  return o;
}
sdpslam::drivers::SickOptions sick_options(std::uint32_t baud) {
  sdpslam::drivers::SickOptions o;
  o.target_baud = baud;
  o.reply_timeout_us = 200000;
  o.stall_timeout_us = 400000;
  return o;
}

using UrgRig = Rig<UrgEmulator, sdpslam::drivers::UrgScip2Laser, sdpslam::drivers::UrgOptions>;
using SickRig = Rig<SickEmulator, sdpslam::drivers::SickLms2xxLaser, sdpslam::drivers::SickOptions>;

// A poll held off longer than the stall timeout (a loaded machine, a long SLAM step)
// finds scans waiting in the tty: it reads them, it does not call the sensor stalled.
template <typename R>
void check_held_off_poll_reads_backlog(R& rig, int (*id_of)(const RangeScan&)) {
  CHECK(rig.collect(3, 3000000, id_of));
  std::this_thread::sleep_for(std::chrono::milliseconds(600));  // stall_timeout_us is 400 ms
  CHECK(rig.collect(10, 3000000, id_of));
  LONGS_EQUAL(0, rig.bad);
  LONGS_EQUAL(0, rig.emu.sends_cut());
  LONGS_EQUAL(0, rig.laser.stats().stall_count);
  LONGS_EQUAL(0, rig.laser.stats().restart_count);
  LONGS_EQUAL(0, missing(rig.ids));
}

}  // namespace

TEST_GROUP(UrgLaserPty) {};

TEST(UrgLaserPty, streams_exact_scans_with_geometry_from_pp_at_750000_baud) {
  UrgRig rig("urg", 750000U, urg_options());
  CHECK(rig.collect(5, 3000000, urg_scan_id));
  LONGS_EQUAL(0, rig.bad);
  LONGS_EQUAL(0, rig.emu.sends_cut());  // every loss below is the injected fault's
  LONGS_EQUAL(0, missing(rig.ids));
  LONGS_EQUAL(750000, sdpslam::drivers::tty_baud_rate(rig.port.fd()));
  DOUBLES_EQUAL(-2.0862, rig.scan.geometry.angle_min_rad, 1e-4);
  DOUBLES_EQUAL(2.0 * M_PI / 1024.0, rig.scan.geometry.angle_increment_rad, 1e-6);
  DOUBLES_EQUAL(5.6, rig.scan.geometry.range_max_m, 1e-6);
  CHECK(rig.scan.classify(50) == RangeScan::Beam::kInvalid);  // error code 1 -> invalid
  STRCMP_EQUAL("SOKUIKI Sensor URG-04LX-UG01(Simple-URG)", rig.laser.product());
  CHECK(rig.laser.health() == sdpslam::hal::RangeSourceHealth::kStreaming);
  LONGS_EQUAL(0, rig.laser.stats().checksum_error_count + rig.laser.stats().framing_error_count);
}

TEST(UrgLaserPty, stamps_increase_steadily_across_the_24_bit_timestamp_wrap) {
  UrgRig rig("urgwrap", 115200U, urg_options());
  CHECK(rig.collect(45, 5000000, urg_scan_id));  // the emulator's counter wraps at scan 30
  LONGS_EQUAL(0, rig.bad);
  LONGS_EQUAL(0, rig.emu.sends_cut());  // every loss below is the injected fault's
  for (std::size_t i = 1; i < rig.stamps.size(); ++i) {
    const std::int64_t d = rig.stamps[i] - rig.stamps[i - 1];
    CHECK(d > 0);
    CHECK(d < 100000);  // 10 ms period; a botched unwrap jumps by 4.66 h
  }
  CHECK(rig.stamps.back() <= rig.clock.now_us());
}

TEST(UrgLaserPty, corrupted_data_byte_drops_exactly_that_scan_as_checksum_error) {
  UrgRig rig("urgcs", 115200U, urg_options());
  CHECK(rig.collect(3, 3000000, urg_scan_id));
  rig.emu.inject(UrgEmulator::kCorruptData);
  CHECK(rig.collect_past_fault(3, 6000000, urg_scan_id));
  LONGS_EQUAL(0, rig.bad);
  LONGS_EQUAL(0, rig.emu.sends_cut());  // every loss below is the injected fault's
  LONGS_EQUAL(1, missing(rig.ids));
  LONGS_EQUAL(1, rig.laser.stats().checksum_error_count);
  LONGS_EQUAL(1, rig.laser.stats().dropped_scan_count);
}

TEST(UrgLaserPty, truncated_line_drops_exactly_that_scan) {
  UrgRig rig("urgtr", 115200U, urg_options());
  CHECK(rig.collect(3, 3000000, urg_scan_id));
  rig.emu.inject(UrgEmulator::kTruncateLine);
  CHECK(rig.collect_past_fault(3, 6000000, urg_scan_id));
  LONGS_EQUAL(0, rig.bad);
  LONGS_EQUAL(0, rig.emu.sends_cut());  // every loss below is the injected fault's
  LONGS_EQUAL(1, missing(rig.ids));
  LONGS_EQUAL(1, rig.laser.stats().dropped_scan_count);
  LONGS_EQUAL(1, rig.laser.stats().checksum_error_count + rig.laser.stats().framing_error_count);
}

TEST(UrgLaserPty, lost_data_line_is_a_value_count_framing_error) {
  UrgRig rig("urglost", 115200U, urg_options());
  CHECK(rig.collect(3, 3000000, urg_scan_id));
  rig.emu.inject(UrgEmulator::kDropLine);
  CHECK(rig.collect_past_fault(3, 6000000, urg_scan_id));
  LONGS_EQUAL(0, rig.bad);
  LONGS_EQUAL(0, rig.emu.sends_cut());  // every loss below is the injected fault's
  LONGS_EQUAL(1, missing(rig.ids));
  LONGS_EQUAL(1, rig.laser.stats().framing_error_count);
  LONGS_EQUAL(0, rig.laser.stats().checksum_error_count);
  CHECK(rig.laser.parser_stats().framing_error_count == 1);
}

TEST(UrgLaserPty, random_garbage_is_skipped_and_streaming_resumes_at_the_next_reply) {
  UrgRig rig("urggb", 115200U, urg_options());
  CHECK(rig.collect(3, 3000000, urg_scan_id));
  rig.emu.inject(UrgEmulator::kGarbage);
  CHECK(rig.collect_past_fault(3, 6000000, urg_scan_id));
  LONGS_EQUAL(0, rig.bad);
  LONGS_EQUAL(0, rig.emu.sends_cut());  // every loss below is the injected fault's
  CHECK(missing(rig.ids) <= 1);  // garbage glued to the next echo costs that scan
  CHECK(rig.laser.stats().garbage_byte_count > 0);
  CHECK(rig.laser.stats().resync_count >= 1);
  LONGS_EQUAL(static_cast<long>(missing(rig.ids)), static_cast<long>(rig.laser.stats().dropped_scan_count));
}

TEST(UrgLaserPty, a_poll_held_off_past_the_stall_timeout_reads_the_backlog_without_a_restart) {
  UrgRig rig("urghold", 115200U, urg_options());
  check_held_off_poll_reads_backlog(rig, urg_scan_id);
}

TEST(UrgLaserPty, unplug_is_seen_as_hangup_and_replug_restarts_streaming) {
  UrgRig rig("urgplug", 750000U, urg_options());
  CHECK(rig.collect(3, 3000000, urg_scan_id));
  rig.emu.unplug();
  int r = 0;
  for (int i = 0; i < 100 && r >= 0; ++i) r = rig.laser.poll(rig.scan, 20000);
  CHECK(r < 0);
  CHECK(rig.laser.health() == sdpslam::hal::RangeSourceHealth::kDisconnected);
  LONGS_EQUAL(1, rig.port.stats().hangup_count);
  LONGS_EQUAL(1, rig.laser.stats().disconnect_count);
  rig.emu.replug();
  CHECK(rig.collect(3, 3000000, urg_scan_id));
  LONGS_EQUAL(0, rig.bad);
  LONGS_EQUAL(0, rig.emu.sends_cut());  // every loss below is the injected fault's
  LONGS_EQUAL(2, rig.port.stats().open_count);
  LONGS_EQUAL(750000, sdpslam::drivers::tty_baud_rate(rig.port.fd()));
  LONGS_EQUAL(1, rig.laser.stats().restart_count);
  LONGS_EQUAL(2, rig.emu.md_commands());
}

TEST_GROUP(SickLaserPty) {};

TEST(SickLaserPty, switches_scanner_and_host_to_500000_baud_and_streams_exact_scans) {
  SickRig rig("sick", 9600U, sick_options(500000U));
  CHECK(rig.collect(5, 3000000, sick_scan_id));
  LONGS_EQUAL(0, rig.bad);
  LONGS_EQUAL(0, rig.emu.sends_cut());  // every loss below is the injected fault's
  LONGS_EQUAL(0, missing(rig.ids));
  LONGS_EQUAL(500000, rig.emu.baud());
  LONGS_EQUAL(500000, rig.port.baud_rate());
  LONGS_EQUAL(500000, sdpslam::drivers::tty_baud_rate(rig.port.fd()));
  DOUBLES_EQUAL(-M_PI / 2.0, rig.scan.geometry.angle_min_rad, 1e-6);
  DOUBLES_EQUAL(M_PI / 360.0, rig.scan.geometry.angle_increment_rad, 1e-7);
  CHECK(rig.scan.classify(40) == RangeScan::Beam::kInvalid);  // distance 0
  CHECK(rig.scan.classify(97) == RangeScan::Beam::kInvalid);  // error code 0x1FFF
  CHECK(rig.scan.classify(3) == RangeScan::Beam::kReturn);    // flag bit masked off
  LONGS_EQUAL(0, rig.laser.stats().checksum_error_count);
}

TEST(SickLaserPty, corrupted_telegram_fails_crc_and_only_that_scan_is_lost) {
  SickRig rig("sickcrc", 9600U, sick_options(38400U));
  CHECK(rig.collect(3, 3000000, sick_scan_id));
  rig.emu.inject(SickEmulator::kCorruptCrc);
  CHECK(rig.collect_past_fault(3, 6000000, sick_scan_id));
  LONGS_EQUAL(0, rig.bad);
  LONGS_EQUAL(0, rig.emu.sends_cut());  // every loss below is the injected fault's
  LONGS_EQUAL(1, missing(rig.ids));
  CHECK(rig.laser.stats().checksum_error_count >= 1);
  CHECK(rig.laser.stats().dropped_scan_count >= 1);
}

TEST(SickLaserPty, truncated_telegram_is_lost_and_the_next_one_is_recovered_by_rescan) {
  SickRig rig("sicktr", 9600U, sick_options(38400U));
  CHECK(rig.collect(3, 3000000, sick_scan_id));
  rig.emu.inject(SickEmulator::kTruncateTelegram);
  CHECK(rig.collect_past_fault(3, 6000000, sick_scan_id));
  LONGS_EQUAL(0, rig.bad);
  LONGS_EQUAL(0, rig.emu.sends_cut());  // every loss below is the injected fault's
  LONGS_EQUAL(1, missing(rig.ids));
  CHECK(rig.laser.stats().checksum_error_count >= 1);
  CHECK(rig.laser.stats().resync_count >= 1);
}

TEST(SickLaserPty, garbage_with_false_stx_bytes_costs_no_scan) {
  SickRig rig("sickgb", 9600U, sick_options(38400U));
  CHECK(rig.collect(3, 3000000, sick_scan_id));
  rig.emu.inject(SickEmulator::kGarbage);
  CHECK(rig.collect_past_fault(3, 6000000, sick_scan_id));
  LONGS_EQUAL(0, rig.bad);
  LONGS_EQUAL(0, rig.emu.sends_cut());  // every loss below is the injected fault's
  LONGS_EQUAL(0, missing(rig.ids));
  CHECK(rig.laser.stats().garbage_byte_count >= 40);
  CHECK(rig.laser.stats().resync_count >= 1);
}

TEST(SickLaserPty, a_poll_held_off_past_the_stall_timeout_reads_the_backlog_without_a_restart) {
  SickRig rig("sickhold", 9600U, sick_options(38400U));
  check_held_off_poll_reads_backlog(rig, sick_scan_id);
}

TEST(SickLaserPty, nak_is_counted_and_the_request_is_resent) {
  SickRig rig("sicknak", 9600U, sick_options(38400U));
  rig.emu.inject(SickEmulator::kNakNextRequest);
  CHECK(rig.collect(3, 3000000, sick_scan_id));
  LONGS_EQUAL(0, rig.bad);
  LONGS_EQUAL(0, rig.emu.sends_cut());  // every loss below is the injected fault's
  LONGS_EQUAL(1, rig.emu.naks_sent());
  LONGS_EQUAL(1, rig.laser.stats().nak_count);
}

TEST(SickLaserPty, unplug_and_replug_of_a_power_cycled_scanner_restarts_at_9600) {
  SickRig rig("sickplug", 9600U, sick_options(500000U));
  CHECK(rig.collect(3, 3000000, sick_scan_id));
  rig.emu.unplug();
  int r = 0;
  for (int i = 0; i < 100 && r >= 0; ++i) r = rig.laser.poll(rig.scan, 20000);
  CHECK(r < 0);
  LONGS_EQUAL(1, rig.port.stats().hangup_count);
  rig.emu.replug();
  CHECK(rig.collect(3, 3000000, sick_scan_id));
  LONGS_EQUAL(0, rig.bad);
  LONGS_EQUAL(0, rig.emu.sends_cut());  // every loss below is the injected fault's
  LONGS_EQUAL(2, rig.port.stats().open_count);
  LONGS_EQUAL(500000, rig.emu.baud());
  LONGS_EQUAL(1, rig.laser.stats().restart_count);
}
