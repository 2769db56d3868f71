// Laser emulators on real pseudo-terminals, driven by the project's own drivers
// (UrgScip2Laser, SickLms2xxLaser): the scans the drivers produce are the log's scans
// (count, order, ranges within 1 mm, timing), plus the protocol engines' answers.
#include <cmath>
#include <string>
#include <thread>
#include <vector>

#include "CppUTest/TestHarness.h"
#include "sdpslam/drivers/linux_clock.h"
#include "sdpslam/drivers/serial_port.h"
#include "sdpslam/drivers/sick_lms2xx_laser.h"
#include "sdpslam/drivers/urg_scip2_laser.h"
#include "sdpslam/replay/player.h"
#include "shared_data.h"

using namespace sdpslam;
using namespace sdpslam::replay;

namespace {

constexpr double kPi = 3.14159265358979323846;

// n scans of `beams` beams over 180° (CARMEN FLASER geometry when beams = 180), 100 ms
// apart. Beam 0 carries the scan number (1000 + k mm) so order can be checked; a few
// beams are max-range or invalid.
std::vector<ReplayScan> synthetic_scans(std::size_t n, std::uint32_t beams, float increment_rad) {
  std::vector<ReplayScan> v(n);
  for (std::size_t k = 0; k < n; ++k) {
    ReplayScan& s = v[k];
    s.stamp_us = 1700000000000000LL + static_cast<std::int64_t>(k) * 100000 + (k % 3) * 7000;
    s.scan.stamp_us = s.stamp_us;
    s.scan.geometry.angle_min_rad = static_cast<float>(-kPi / 2.0);
    s.scan.geometry.angle_increment_rad = increment_rad;
    s.scan.geometry.range_max_m = 50.0F;
    s.scan.beam_count = beams;
    for (std::uint32_t i = 0; i < beams; ++i) {
      s.scan.ranges_m[i] = 0.5F + 0.01F * static_cast<float>((i * 37 + k * 11) % 700);
    }
    s.scan.ranges_m[0] = 1.0F + 0.001F * static_cast<float>(k);
    s.scan.ranges_m[5] = 81.91F;  // no return
    s.scan.ranges_m[9] = 0.0F;    // invalid
  }
  return v;
}

// Which log scan a received scan is: beam 0 carries 1000 + k mm.
std::size_t scan_number(const RangeScan& s) {
  return static_cast<std::size_t>(std::lround((static_cast<double>(s.ranges_m[0]) - 1.0) * 1000.0));
}

// Accounting that holds on a loaded machine too. The emulator, like a real sensor, drops
// a scan it could not send before the next one was due (its thread woke too late); every
// scan is served or dropped, every served scan reaches the driver, and the driver
// delivers them in the log's order. Returns the log index of each received scan.
std::vector<std::size_t> check_delivery(const std::vector<ReplayScan>& scans, const std::vector<RangeScan>& got,
                                        const LaserReplayStats& st) {
  LONGS_EQUAL(scans.size(), st.scans_served + st.scans_dropped);
  LONGS_EQUAL(st.scans_served, got.size());
  CHECK_TRUE_TEXT(2 * got.size() >= scans.size(), "fewer than half the scans were served");
  std::vector<std::size_t> index;
  for (const RangeScan& g : got) {
    const std::size_t k = scan_number(g);
    CHECK_TRUE(k < scans.size());
    if (!index.empty()) CHECK_TRUE(k > index.back());  // in order, never twice
    index.push_back(k);
  }
  return index;
}

struct PlayerThread {
  drivers::LinuxMonotonicClock clock;
  Player player{clock, PlayerOptions{}};
  std::thread thread;
  void start(LaserEngine& e, LaserPty& pty, std::int64_t log_start, double speed, std::int64_t delay_us) {
    player.set_laser(&e, &pty);
    thread = std::thread([this, log_start, speed, delay_us] { player.run(log_start, speed, delay_us); });
  }
  ~PlayerThread() {
    if (thread.joinable()) thread.join();
  }
};

}  // namespace

TEST_GROUP(ReplayScipGeometry){};

TEST(ReplayScipGeometry, carmen_180_beams_get_two_steps_per_beam) {
  const std::vector<ReplayScan> s = synthetic_scans(1, 180, static_cast<float>(kPi / 179.0));
  ScipGeometry g;
  std::string error;
  CHECK_TRUE(scip_geometry_for(s[0].scan.geometry, 180, &g, &error));
  LONGS_EQUAL(716, g.ares);
  LONGS_EQUAL(179, g.afrt);
  LONGS_EQUAL(0, g.amin);
  LONGS_EQUAL(359, g.amax);
  LONGS_EQUAL(2, g.steps_per_beam);
  LONGS_EQUAL(50000, g.dmax_mm);
}

TEST(ReplayScipGeometry, urg_grid_gets_the_urg_04lx_numbers) {
  ScanGeometry geo;
  geo.angle_increment_rad = static_cast<float>(2.0 * kPi / 1024.0);
  geo.angle_min_rad = static_cast<float>((44.0 - 384.0) * 2.0 * kPi / 1024.0);
  geo.range_max_m = 5.6F;
  ScipGeometry g;
  std::string error;
  CHECK_TRUE(scip_geometry_for(geo, 682, &g, &error));
  LONGS_EQUAL(1024, g.ares);
  LONGS_EQUAL(384, g.afrt);
  LONGS_EQUAL(44, g.amin);
  LONGS_EQUAL(725, g.amax);
  LONGS_EQUAL(5600, g.dmax_mm);
}

TEST(ReplayScipGeometry, a_grid_off_every_step_lattice_is_refused) {
  ScanGeometry geo;
  geo.angle_increment_rad = 0.0123F;
  geo.angle_min_rad = -1.0F;
  ScipGeometry g;
  std::string error;
  CHECK_FALSE(scip_geometry_for(geo, 100, &g, &error));
  CHECK_TRUE(error.find("integer SCIP steps") != std::string::npos);
}

TEST_GROUP(ReplayScipEngine) {
  std::vector<ReplayScan> scans = synthetic_scans(3, 180, static_cast<float>(kPi / 179.0));
  ScipGeometry geo;
  void setup() override {
    std::string error;
    scip_geometry_for(scans[0].scan.geometry, 180, &geo, &error);
  }
  std::string ask(ScipEngine& e, const std::string& cmd) {
    const std::string line = cmd + "\n";
    e.on_host_bytes(reinterpret_cast<const std::uint8_t*>(line.data()), line.size(), 0, 0);
    std::string out(e.output().begin(), e.output().end());
    e.output().clear();
    return out;
  }
};

TEST(ReplayScipEngine, unknown_command_is_answered_0E) {
  ScipEngine e(scans, ReplayTimeline{}, geo);
  STRCMP_EQUAL("XX\n0Ee\n\n", ask(e, "XX").c_str());
  LONGS_EQUAL(1, e.stats().unknown_commands);
}

TEST(ReplayScipEngine, second_bm_says_laser_already_on) {
  ScipEngine e(scans, ReplayTimeline{}, geo);
  STRCMP_EQUAL("BM\n00P\n\n", ask(e, "BM").c_str());
  STRCMP_EQUAL("BM\n02R\n\n", ask(e, "BM").c_str());
}

TEST(ReplayScipEngine, md_beyond_amax_is_refused) {
  ScipEngine e(scans, ReplayTimeline{}, geo);
  const std::string r = ask(e, "MD0000036002000");
  CHECK_TRUE(r.rfind("MD0000036002000\n05", 0) == 0);
}

TEST(ReplayScipEngine, scans_due_while_not_streaming_are_counted_not_requested) {
  ScipEngine e(scans, ReplayTimeline{scans[0].stamp_us, 0, 1.0}, geo);
  e.advance(1000000, 0);
  CHECK_TRUE(e.done());
  LONGS_EQUAL(3, e.stats().scans_not_requested);
  LONGS_EQUAL(0, e.stats().scans_served);
  CHECK_TRUE(e.output().empty());
}

TEST(ReplayScipEngine, an_overtaken_scan_is_dropped_not_sent_late) {
  ScipEngine e(scans, ReplayTimeline{scans[0].stamp_us, 0, 1.0}, geo);
  ask(e, "MD0000035902000");
  e.advance(250000, 0);  // scans 0, 1 and 2 are all due: only the newest goes out
  LONGS_EQUAL(1, e.stats().scans_served);
  LONGS_EQUAL(2, e.stats().scans_dropped);
}

TEST_GROUP(ReplayLaserPty){};

// The sensor stamps are exact to the ms. The driver maps them onto the host clock with a
// minimum-delay filter (scip2::SensorClock): its offset starts at the first scan's
// delivery delay and can only shrink, so an interval between two delivered scans is
// never longer than the log's (scaled by 1/speed) beyond the 1 ms of the stamps' grain,
// whatever the machine's load. A driver that stamped arrival times would stretch the
// interval after any scan delivered late. How far the intervals are off in all (the
// first scan's excess delay, 10 ms on an idle machine) depends on the load: printed.
TEST(ReplayLaserPty, urg_driver_reproduces_the_log_scans_in_order_within_a_millimetre) {
  const std::vector<ReplayScan> scans = synthetic_scans(25, 180, static_cast<float>(kPi / 179.0));
  ScipGeometry geo;
  std::string error;
  CHECK_TRUE(scip_geometry_for(scans[0].scan.geometry, 180, &geo, &error));
  ScipEngine engine(scans, ReplayTimeline{}, geo);
  LaserPty pty;
  const std::string link = test::make_temp_dir("replay_urg") + "/urg";
  CHECK_TRUE_TEXT(pty.open(link, &error), error.c_str());
  // Scans 36..57 ms apart at this speed: a real sensor (and the emulator) drops a scan
  // only when the next one is due before it could go out.
  const double speed = 2.0;
  PlayerThread player;
  player.start(engine, pty, scans[0].stamp_us, speed, 500000);  // 0.5 s for the handshake

  drivers::LinuxMonotonicClock clock;
  drivers::SerialOptions so;
  so.path = link.c_str();
  drivers::SerialPort port(so, clock);
  CHECK_TRUE(port.open());
  drivers::UrgOptions uo;
  uo.cluster = geo.steps_per_beam;
  uo.stall_timeout_us = 2000000;  // the emulator is silent until the log's first scan
  drivers::UrgScip2Laser laser(port, clock, uo);
  std::vector<RangeScan> got;
  const std::int64_t end = clock.now_us() + 5000000;
  RangeScan out;
  while (got.size() < scans.size() && clock.now_us() < end) {
    if (laser.poll(out, 50000) == 1) got.push_back(out);
  }
  player.thread.join();
  std::printf("\nURG emulator: served %llu dropped %llu late %llu max lateness %lld us\n",
              static_cast<unsigned long long>(engine.stats().scans_served),
              static_cast<unsigned long long>(engine.stats().scans_dropped),
              static_cast<unsigned long long>(engine.stats().scans_late),
              static_cast<long long>(engine.stats().max_lateness_us));
  const std::vector<std::size_t> idx = check_delivery(scans, got, engine.stats());
  double worst_mm = 0.0, worst_timing_us = 0.0, worst_stretch_us = -1e9;
  for (std::size_t j = 0; j < got.size(); ++j) {
    const std::size_t k = idx[j];
    const RangeScan& g = got[j];
    LONGS_EQUAL(180, g.beam_count);
    DOUBLES_EQUAL(scans[k].scan.geometry.angle_min_rad, g.geometry.angle_min_rad, 1e-6);
    DOUBLES_EQUAL(scans[k].scan.geometry.angle_increment_rad, g.geometry.angle_increment_rad, 1e-7);
    for (std::uint32_t i = 0; i < 180; ++i) {
      const RangeScan::Beam want = scans[k].scan.classify(i);
      if (i == 9) {
        CHECK_TRUE(g.classify(i) == RangeScan::Beam::kInvalid);
        continue;
      }
      CHECK_TRUE(g.classify(i) == want);
      worst_mm = std::fmax(worst_mm, 1000.0 * std::fabs(static_cast<double>(g.ranges_m[i] - scans[k].scan.ranges_m[i])));
    }
    // Timing: driver stamps are the emulator's sensor stamps mapped onto this clock;
    // intervals match the log's scaled by 1/speed.
    const double want_us = static_cast<double>(scans[k].stamp_us - scans[idx[0]].stamp_us) / speed;
    const double have_us = static_cast<double>(g.stamp_us - got[0].stamp_us);
    worst_timing_us = std::fmax(worst_timing_us, std::fabs(have_us - want_us));
    if (j > 0) {
      const double want_step_us = static_cast<double>(scans[k].stamp_us - scans[idx[j - 1]].stamp_us) / speed;
      const double have_step_us = static_cast<double>(g.stamp_us - got[j - 1].stamp_us);
      worst_stretch_us = std::fmax(worst_stretch_us, have_step_us - want_step_us);
    }
  }
  std::printf("\nURG replay: %zu scans, worst range error %.3f mm, worst interval error %.0f us, "
              "longest stretch of one interval %.0f us\n",
              got.size(), worst_mm, worst_timing_us, worst_stretch_us);
  CHECK_TRUE(worst_mm <= 1.0);
  CHECK_TRUE_TEXT(worst_stretch_us <= 2000.0, "an interval between driver stamps is longer than the log's");
}

TEST(ReplayLaserPty, sick_driver_reproduces_the_log_scans_in_order_within_a_millimetre) {
  const std::vector<ReplayScan> scans = synthetic_scans(15, 181, static_cast<float>(kPi / 180.0));
  SickEngine engine(scans, ReplayTimeline{});
  LaserPty pty;
  std::string error;
  const std::string link = test::make_temp_dir("replay_sick") + "/sick";
  CHECK_TRUE_TEXT(pty.open(link, &error), error.c_str());
  const double speed = 2.0;
  PlayerThread player;
  player.start(engine, pty, scans[0].stamp_us, speed, 1500000);  // 9600-baud handshake first

  drivers::LinuxMonotonicClock clock;
  drivers::SerialOptions so;
  so.path = link.c_str();
  so.baud = 9600;
  drivers::SerialPort port(so, clock);
  CHECK_TRUE(port.open());
  drivers::SickOptions sk;
  sk.target_baud = 500000;
  sk.stall_timeout_us = 2000000;  // the emulator is silent until the log's first scan
  drivers::SickLms2xxLaser laser(port, clock, sk);
  std::vector<RangeScan> got;
  std::vector<std::int64_t> got_at_us;  // when poll() handed the scan over
  const std::int64_t end = clock.now_us() + 8000000;
  RangeScan out;
  while (got.size() < scans.size() && clock.now_us() < end) {
    if (laser.poll(out, 50000) == 1) {
      got.push_back(out);
      got_at_us.push_back(clock.now_us());
    }
  }
  player.thread.join();
  {
    std::printf("\nSICK: engine dropped %llu commands %llu unknown %llu served %llu not requested %llu lost %llu baud %u; driver "
                "timeouts %llu naks %llu framing %llu crc %llu health %d\n",
                (unsigned long long)engine.stats().scans_dropped, (unsigned long long)engine.stats().commands, (unsigned long long)engine.stats().unknown_commands,
                (unsigned long long)engine.stats().scans_served, (unsigned long long)engine.stats().scans_not_requested,
                (unsigned long long)engine.stats().bytes_lost_line_speed, engine.baud(),
                (unsigned long long)laser.stats().timeout_count, (unsigned long long)laser.stats().nak_count,
                (unsigned long long)laser.stats().framing_error_count, (unsigned long long)laser.stats().checksum_error_count,
                static_cast<int>(laser.health()));
  }
  LONGS_EQUAL(500000, engine.baud());
  LONGS_EQUAL(0, engine.stats().bytes_lost_line_speed);
  const std::vector<std::size_t> idx = check_delivery(scans, got, engine.stats());
  double worst_mm = 0.0, worst_timing_us = 0.0, sum_timing_us = 0.0;
  for (std::size_t j = 0; j < got.size(); ++j) {
    const std::size_t k = idx[j];
    const RangeScan& g = got[j];
    LONGS_EQUAL(361, g.beam_count);
    // 0.5° values: even ones sit on the log's 1° beams, odd ones take the nearest.
    DOUBLES_EQUAL(scans[k].scan.ranges_m[0], g.ranges_m[0], 0.0011);  // scan number
    for (std::uint32_t i = 0; i < 361; i += 2) {
      const std::uint32_t b = i / 2;
      if (b == 5 || b == 9) {  // beyond 8.183 m (overflow code) and invalid: both no data
        CHECK_TRUE(g.classify(i) == RangeScan::Beam::kInvalid);
        continue;
      }
      worst_mm = std::fmax(worst_mm, 1000.0 * std::fabs(static_cast<double>(g.ranges_m[i] - scans[k].scan.ranges_m[b])));
    }
    const double want_us = static_cast<double>(scans[k].stamp_us - scans[idx[0]].stamp_us) / speed;
    const double have_us = static_cast<double>(g.stamp_us - got[0].stamp_us);
    worst_timing_us = std::fmax(worst_timing_us, std::fabs(have_us - want_us));
    sum_timing_us += std::fabs(have_us - want_us);
    // The stamp is the arrival of the telegram's last byte: not before the emulator was
    // due to send it, not after the driver handed the scan over (one clock for both).
    CHECK_TRUE(g.stamp_us >= player.player.timeline().due_us(scans[k].stamp_us));
    CHECK_TRUE(g.stamp_us <= got_at_us[j]);
  }
  const double mean_timing_us = sum_timing_us / static_cast<double>(got.size());
  std::printf("\nSICK replay: %zu scans, worst range error %.3f mm, interval error mean %.0f us, worst %.0f us\n",
              got.size(), worst_mm, mean_timing_us, worst_timing_us);
  CHECK_TRUE(worst_mm <= 1.0);
  // The LMS2xx driver stamps a scan on the arrival of its last byte (there is no sensor
  // clock in the telegram), so host scheduling delay goes straight into the stamp and
  // the interval errors printed above depend on the machine's load (on an idle machine
  // under 5 ms mean and 40 ms worst); the bounds checked are the load-free ones above.
}
