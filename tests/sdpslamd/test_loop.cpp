// The sdpslamd loop with fake sensors and a fake engine: odometry placed at scan stamps,
// waiting and skipping, stale encoders, laser hang-up and reconnection, bus-off, queue
// exhaustion, outputs written atomically, a failed write keeping the previous files.
#include <CppUTest/TestHarness.h>
#include <sys/socket.h>
#include <sys/un.h>

#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sdpslam/daemon/daemon.h"
#include "sdpslam/io/atomic_file.h"
#include "sdpslam/io/trajectory_io.h"
#include "shared_data.h"
#include "yaml_statics.h"  // localize mode reads a map YAML

using namespace sdpslam;
using namespace sdpslam::daemon;

namespace {

class FakeClock final : public hal::MonotonicClock {
 public:
  std::int64_t now_us() const override { return t; }
  std::int64_t t = 1000000;
};

class FakeEncoders final : public hal::WheelEncoderSource {
 public:
  void sample(std::uint32_t left, std::uint32_t right, std::int64_t stamp_us) {
    for (hal::WheelTicks* w : {&s.left, &s.right}) {
      w->raw_count = w == &s.left ? left : right;
      w->stamp_us = stamp_us;
      ++w->sequence;
      w->has_sample = true;
      w->stale = false;
    }
  }
  void go_stale() { s.left.stale = s.right.stale = true; }
  int update() override { return 0; }
  hal::WheelEncoderSample latest() const override { return s; }
  hal::WheelEncoderSample s;
};

class FakeLaser final : public hal::RangeScanSource {
 public:
  void deliver(std::int64_t stamp_us) {
    RangeScan sc;
    sc.stamp_us = stamp_us;
    sc.beam_count = 2;
    ready.push_back(sc);
  }
  int poll(RangeScan& out, std::int64_t) override {
    if (unplugged) return -1;
    if (ready.empty()) return 0;
    out = ready.front();
    ready.erase(ready.begin());
    ++st.scan_count;
    h = hal::RangeSourceHealth::kStreaming;
    return 1;
  }
  void unplug() {
    unplugged = true;
    ++st.disconnect_count;
    h = hal::RangeSourceHealth::kDisconnected;
  }
  void replug() {
    unplugged = false;
    ++st.restart_count;
    h = hal::RangeSourceHealth::kStarting;
  }
  hal::RangeSourceHealth health() const override { return h; }
  const hal::RangeSourceStats& stats() const override { return st; }
  std::vector<RangeScan> ready;
  bool unplugged = false;
  hal::RangeSourceHealth h = hal::RangeSourceHealth::kStarting;
  hal::RangeSourceStats st;
};

class FakeBus final : public hal::CanBus {
 public:
  int send(const hal::CanFrame&) override { return 1; }
  int receive(hal::CanFrame&) override { return 0; }
  int wait_readable(std::int64_t) override { return 0; }
  hal::CanBusState state() const override { return s; }
  const hal::CanBusStats& stats() const override { return st; }
  hal::CanBusState s = hal::CanBusState::kActive;
  hal::CanBusStats st;
};

class FakeEngine final : public SlamEngine {
 public:
  const char* name() const override { return "fake"; }
  EngineStep process(const OdometrySample& odom, const RangeScan&) override {
    got.push_back(odom);
    return EngineStep{true, odom.pose};
  }
  std::vector<io::StampedPose> trajectory() const override {
    std::vector<io::StampedPose> t;
    for (const OdometrySample& o : got) t.push_back({o.stamp_us, o.pose});
    return t;
  }
  std::uint32_t map_image(io::OccupancyImage* image) const override {
    *image = map;
    return static_cast<std::uint32_t>(map.occupancy.size());
  }
  sdpslam::io::Json status_json() const override { return {{"fake", true}}; }
  std::uint64_t unrecorded_scans() const override { return 0U; }
  bool has_snapshots() const override { return snapshots; }
  bool save_snapshot(const std::string& path, std::uint64_t, std::uint64_t* bytes, std::string* error) override {
    saved_at.push_back(got.size());
    *bytes = 1U;
    return io::write_file_atomic(path, std::to_string(got.size()), error);
  }
  bool snapshots = false;
  std::vector<std::size_t> saved_at;  // scans the engine had at each snapshot
  std::vector<OdometrySample> got;
  io::OccupancyImage map;  // what the engine "mapped" (empty by default)
};

class CountingWatchdog final : public hal::Watchdog {
 public:
  void pat() override { ++pats; }
  int pats = 0;
};

// 2000 ticks per revolution, radius 0.077 m: 1000 ticks on both wheels = 0.2419 m ahead.
constexpr double kMetresPer1000Ticks = 0.077 * 3.14159265358979323846;

struct Rig {
  FakeClock clock;
  FakeEncoders enc;
  FakeLaser laser;
  FakeBus bus;
  FakeEngine engine;
  CountingWatchdog watchdog;
  std::FILE* log_file = std::tmpfile();
  EventLog log{clock, 0, log_file};
  DaemonConfig config;
  std::unique_ptr<Daemon> d;

  Rig() {
    config.output_directory = test::make_temp_dir("sdpslamd_loop");
    config.odometry_wait_us = 200000;
    config.output_period_us = 3600000000LL;
    config.write_map = false;
    config.loop_slice_us = 100;
  }
  ~Rig() { std::fclose(log_file); }
  Daemon& make(bool fork_snapshots = false) {
    DaemonIo io;
    io.clock = &clock;
    io.bus = &bus;
    io.encoders = &enc;
    io.laser = &laser;
    io.engine = &engine;
    io.watchdog = &watchdog;
    io.fork_snapshots = fork_snapshots;
    d = std::make_unique<Daemon>(config, io, log);
    std::string error;
    CHECK_TRUE_TEXT(d->start(&error), error.c_str());
    return *d;
  }
  // Odometry sample of `ticks` on both wheels at t, then one loop step at t.
  void odom(std::uint32_t ticks, std::int64_t t) {
    clock.t = t;
    enc.sample(ticks, ticks, t);
    d->step();
  }
  // One scan at t + 50 ms between odometry at t (`ticks`) and t + 100 ms (`ticks` + 100):
  // placed with an interpolated pose.
  void scan_between_odometry(std::uint32_t ticks, std::int64_t t) {
    odom(ticks, t);
    laser.deliver(t + 50000);
    odom(ticks + 100U, t + 100000);
  }
};

bool file_exists(const std::string& p) {
  struct stat st{};
  return ::stat(p.c_str(), &st) == 0;
}

std::size_t lines_of(const std::string& path) {
  std::size_t n = 0U;
  if (std::FILE* f = std::fopen(path.c_str(), "r")) {
    for (int ch = std::fgetc(f); ch != EOF; ch = std::fgetc(f)) n += ch == '\n' ? 1U : 0U;
    std::fclose(f);
  }
  return n;
}

int temp_files_in(const std::string& dir) {
  int n = 0;
  DIR* d = opendir(dir.c_str());
  while (dirent* e = readdir(d)) n += std::string(e->d_name).find(".tmp") != std::string::npos ? 1 : 0;
  closedir(d);
  return n;
}

}  // namespace

TEST_GROUP(SdpslamdLoop){};

TEST(SdpslamdLoop, scan_between_two_odometry_samples_gets_the_interpolated_pose) {
  Rig r;
  r.make();
  r.odom(0, 1000000);
  r.odom(1000, 1100000);
  r.laser.deliver(1050000);
  r.d->step();
  LONGS_EQUAL(1, r.engine.got.size());
  LONGS_EQUAL(1050000, r.engine.got[0].stamp_us);
  DOUBLES_EQUAL(kMetresPer1000Ticks / 2.0, r.engine.got[0].pose.x_m, 1e-9);
}

TEST(SdpslamdLoop, scan_newer_than_odometry_waits_for_it_then_is_placed) {
  Rig r;
  r.make();
  r.odom(0, 1000000);
  r.laser.deliver(1050000);
  r.clock.t = 1060000;
  r.d->step();
  LONGS_EQUAL(0, r.engine.got.size());
  LONGS_EQUAL(1, r.d->queued_scans());
  r.odom(1000, 1100000);
  LONGS_EQUAL(1, r.engine.got.size());
  LONGS_EQUAL(0, r.d->counters().scans_dropped());
}

TEST(SdpslamdLoop, stale_encoders_make_scans_wait_then_skip_and_count) {
  Rig r;
  r.make();
  r.odom(0, 1000000);
  r.odom(100, 1100000);
  r.enc.go_stale();
  r.laser.deliver(1150000);
  r.clock.t = 1160000;
  r.d->step();
  LONGS_EQUAL(0, r.engine.got.size());
  r.clock.t = 1160000 + r.config.odometry_wait_us;
  r.d->step();
  LONGS_EQUAL(0, r.engine.got.size());
  LONGS_EQUAL(1, r.d->counters().scans_skipped_no_odometry);
  LONGS_EQUAL(1, r.d->counters().odometry_stale_events);
  CHECK(r.log.count(Event::kOdometry) >= 1U);
}

TEST(SdpslamdLoop, no_motion_is_invented_across_a_stale_outage) {
  Rig r;
  r.make();
  r.odom(0, 1000000);
  r.odom(100, 1100000);
  r.clock.t = 1150000;
  r.enc.go_stale();
  r.d->step();
  r.odom(5000, 1300000);  // re-latch after the outage
  r.odom(5100, 1400000);
  r.laser.deliver(1200000);  // measured during the outage
  r.laser.deliver(1350000);  // after it
  r.d->step();
  r.d->step();
  LONGS_EQUAL(1, r.d->counters().scans_skipped_gap);
  LONGS_EQUAL(1, r.engine.got.size());
  LONGS_EQUAL(1350000, r.engine.got[0].stamp_us);
  // The pose continues from the last known one: the 4900 ticks of the outage are not used.
  DOUBLES_EQUAL((100.0 + 50.0) / 1000.0 * kMetresPer1000Ticks, r.engine.got[0].pose.x_m, 1e-9);
}

TEST(SdpslamdLoop, laser_hangup_is_logged_and_scans_resume_after_reconnection) {
  Rig r;
  r.make();
  r.odom(0, 1000000);
  r.laser.deliver(1010000);
  r.odom(10, 1020000);
  LONGS_EQUAL(1, r.engine.got.size());
  r.laser.unplug();
  r.clock.t = 1030000;
  r.d->step();
  r.laser.replug();
  r.laser.deliver(1040000);
  r.odom(20, 1050000);
  LONGS_EQUAL(2, r.engine.got.size());
  CHECK(r.log.count(Event::kLaser) >= 2U);  // disconnected, restarted (health changes too)
  CHECK(r.d->status_json().find("\"disconnects\": 1") != std::string::npos);
}

TEST(SdpslamdLoop, bus_off_and_recovery_are_logged_and_the_loop_keeps_running) {
  Rig r;
  r.make();
  r.odom(0, 1000000);
  r.bus.s = hal::CanBusState::kBusOff;
  r.bus.st.errors.bus_off = 1;
  r.clock.t = 1010000;
  r.d->step();
  CHECK(r.d->status_json().find("\"can\": \"bus-off\"") != std::string::npos);
  r.bus.s = hal::CanBusState::kActive;
  r.bus.st.reopen_count = 1;
  r.odom(10, 1020000);
  r.laser.deliver(1015000);
  r.d->step();
  LONGS_EQUAL(1, r.engine.got.size());
  CHECK(r.log.count(Event::kCan) >= 3U);  // bus-off state, bus-off counter, back to active
}

TEST(SdpslamdLoop, full_scan_queue_drops_the_oldest_and_counts_it) {
  Rig r;
  r.config.scan_queue = 2;
  r.make();
  r.odom(0, 1000000);
  for (int i = 1; i <= 3; ++i) {
    r.laser.deliver(1000000 + i * 1000);
    r.clock.t = 1000000 + i * 1000 + 10;
    r.d->step();
  }
  LONGS_EQUAL(1, r.d->counters().scans_dropped_queue_full);
  r.odom(10, 1100000);
  LONGS_EQUAL(2, r.engine.got.size());
  LONGS_EQUAL(1002000, r.engine.got[0].stamp_us);
}

TEST(SdpslamdLoop, finish_places_what_it_can_and_writes_outputs_atomically) {
  Rig r;
  r.make();
  r.odom(0, 1000000);
  r.laser.deliver(1050000);
  r.odom(100, 1100000);
  r.laser.deliver(1200000);  // no odometry will come: skipped at the final pass
  r.clock.t = 1210000;
  r.d->step();
  CHECK_TRUE(r.d->finish());
  std::vector<io::StampedPose> t;
  std::string error;
  CHECK_TRUE_TEXT(io::read_trajectory(r.config.output_directory + "/trajectory.txt", &t, &error), error.c_str());
  LONGS_EQUAL(1, t.size());
  std::vector<io::StampedPose> tum;
  CHECK_TRUE_TEXT(io::read_trajectory(r.config.output_directory + "/trajectory.tum", &tum, &error), error.c_str());
  LONGS_EQUAL(1, tum.size());
  LONGS_EQUAL(t[0].stamp_us, tum[0].stamp_us);
  LONGS_EQUAL(1, r.d->counters().scans_skipped_no_odometry);
  CHECK_TRUE(file_exists(r.config.output_directory + "/status.json"));
  LONGS_EQUAL(0, temp_files_in(r.config.output_directory));
  // status.json is JSON, with the engine's members in its "engine" object.
  std::ifstream in(r.config.output_directory + "/status.json");
  const nlohmann::json status = nlohmann::json::parse(in, nullptr, false);
  CHECK_FALSE(status.is_discarded());
  STRCMP_EQUAL("sdpslamd", status["program"].get<std::string>().c_str());
  CHECK_TRUE(status["engine"]["fake"].get<bool>());
  LONGS_EQUAL(1, status["scans"]["skipped_no_odometry"].get<int>());
  CHECK_TRUE(status["cpu"]["user_s"].is_number());
}

// Mode sdp writes the whole state every [output] snapshot_interval_s while scans come,
// none while the robot is idle, and one more at the stop before the engine finishes.
TEST(SdpslamdLoop, snapshots_follow_the_interval_while_scans_come_and_one_is_written_at_the_stop) {
  Rig r;
  r.engine.snapshots = true;
  r.config.snapshot_interval_us = 1000000;
  r.make();
  for (int k = 0; k < 25; ++k) r.scan_between_odometry(100U * static_cast<std::uint32_t>(2 * k), 2000000 + 200000LL * k);
  // 5 s of scans from t = 2 s: the interval ends at t = 2, 3, 4, 5 and 6 s (the first
  // before any scan: nothing to write then).
  const std::size_t while_mapping = r.engine.saved_at.size();
  CHECK(while_mapping >= 3U && while_mapping <= 5U);
  CHECK_TRUE(file_exists(snapshot_path(r.config)));
  // Idle: the scans placed since the last one are saved at the next interval, then
  // nothing more while no scan comes.
  for (int k = 0; k < 30; ++k) r.odom(5000U, 8000000 + 200000LL * k);
  const std::size_t after_idle = r.engine.saved_at.size();
  LONGS_EQUAL(r.engine.got.size(), r.engine.saved_at.back());
  CHECK(after_idle <= while_mapping + 1U);
  for (int k = 0; k < 30; ++k) r.odom(5000U, 14000000 + 200000LL * k);
  LONGS_EQUAL(after_idle, r.engine.saved_at.size());
  // A last scan, then the stop: saved before the engine finishes.
  r.scan_between_odometry(5000U, 21000000);
  CHECK_TRUE(r.d->finish());
  LONGS_EQUAL(after_idle + 1U, r.engine.saved_at.size());
  LONGS_EQUAL(r.engine.got.size(), r.engine.saved_at.back());
  LONGS_EQUAL(after_idle + 1U, r.d->counters().snapshots_written);
  STRCMP_CONTAINS("\"snapshots\": {", r.d->status_json().c_str());
  LONGS_EQUAL(0, temp_files_in(r.config.output_directory));
}

#ifndef SDPSLAM_TEST_UNDER_EMULATOR  // see tests/sdpslamd/CMakeLists.txt
// On the robot a forked copy writes it while the loop goes on: the file holds the state
// of the moment of the fork, and the outcome is collected later.
TEST(SdpslamdLoop, a_forked_child_writes_the_snapshot_while_the_loop_goes_on) {
  Rig r;
  r.engine.snapshots = true;
  r.config.snapshot_interval_us = 1000000;
  r.make(true);
  for (int k = 0; k < 6; ++k) r.scan_between_odometry(100U * static_cast<std::uint32_t>(2 * k), 2000000 + 200000LL * k);
  // The child saves; the parent's fake engine records nothing (the child's memory is
  // its own). Its outcome is collected by a later step.
  LONGS_EQUAL(0, r.engine.saved_at.size());
  for (int i = 0; i < 500 && r.d->counters().snapshots_written == 0U; ++i) {
    ::usleep(10000);
    r.d->step();
  }
  LONGS_EQUAL(1, r.d->counters().snapshots_written);
  LONGS_EQUAL(0, r.d->counters().snapshot_failures);
  auto saved_scans = [&] {
    std::ifstream in(snapshot_path(r.config));
    std::size_t n = 0U;
    in >> n;
    return n;
  };
  const std::size_t forked = saved_scans();
  CHECK(forked >= 1U && forked <= r.engine.got.size());
  // Finishing waits for any child, then writes the last one in the loop.
  r.scan_between_odometry(2000U, 4000000);
  CHECK_TRUE(r.d->finish());
  LONGS_EQUAL(1, r.engine.saved_at.size());
  LONGS_EQUAL(r.engine.got.size(), saved_scans());
  LONGS_EQUAL(0, temp_files_in(r.config.output_directory));
}
#endif

// Off ([output] snapshot_interval_s = 0), or a mode without snapshots: none.
TEST(SdpslamdLoop, no_snapshot_when_they_are_off) {
  Rig r;
  r.engine.snapshots = true;
  r.config.snapshot_interval_us = 0;
  r.make();
  for (int k = 0; k < 10; ++k) r.scan_between_odometry(100U * static_cast<std::uint32_t>(2 * k), 2000000 + 500000LL * k);
  CHECK_TRUE(r.d->finish());
  LONGS_EQUAL(0, r.engine.saved_at.size());
  CHECK_FALSE(file_exists(snapshot_path(r.config)));
}

TEST(SdpslamdLoop, failed_write_keeps_the_previous_file_and_is_counted) {
  Rig r;
  r.make();
  r.scan_between_odometry(0, 1000000);
  CHECK_TRUE(r.d->write_outputs());
  // status.json cannot be replaced while a directory stands in its place.
  const std::string status = r.config.output_directory + "/status.json";
  CHECK_EQUAL(0, std::remove(status.c_str()));
  CHECK_EQUAL(0, ::mkdir(status.c_str(), 0755));
  r.scan_between_odometry(100, 1100000);
  CHECK_FALSE(r.d->write_outputs());
  LONGS_EQUAL(1, r.d->counters().output_failures);
  CHECK(r.log.count(Event::kOutput) == 1U);
  std::vector<io::StampedPose> t;
  std::string error;
  CHECK_TRUE(io::read_trajectory(r.config.output_directory + "/trajectory.txt", &t, &error));
  LONGS_EQUAL(2, t.size());
  ::rmdir(status.c_str());
}

// Trajectory and map are delivered as one set (manifest.txt) and only when a scan was
// placed since the last delivery: an idle robot rewrites (and fsyncs) nothing but its
// status.
TEST(SdpslamdLoop, idle_periods_rewrite_nothing_and_the_set_has_a_manifest) {
  Rig r;
  r.make();
  r.scan_between_odometry(0, 1000000);
  CHECK_TRUE(r.d->write_outputs());
  LONGS_EQUAL(1, r.d->counters().output_writes);
  CHECK_TRUE(file_exists(r.config.output_directory + "/manifest.txt"));
  const std::uint64_t fsyncs = io::fsync_count();
  CHECK_TRUE(r.d->write_outputs());
  CHECK_TRUE(r.d->write_outputs());
  LONGS_EQUAL(1, r.d->counters().output_writes);
  LONGS_EQUAL(2, r.d->counters().output_writes_unchanged);
  UNSIGNED_LONGLONGS_EQUAL(fsyncs, io::fsync_count());  // idle: nothing flushed to storage
  CHECK_TRUE(file_exists(r.config.output_directory + "/status.json"));  // the heartbeat still is written
  r.scan_between_odometry(100, 1100000);
  CHECK_TRUE(r.d->write_outputs());
  LONGS_EQUAL(2, r.d->counters().output_writes);
  CHECK(io::fsync_count() > fsyncs);  // a new set is made durable
  std::vector<io::StampedPose> t;
  std::string error;
  CHECK_TRUE(io::read_trajectory(r.config.output_directory + "/trajectory.txt", &t, &error));
  LONGS_EQUAL(2, t.size());
}

// Lifelong use (SIGUSR1): from mapping to localization on the map just built. The session's
// map and path are kept, the next scans go to a localize engine that starts at the last
// mapped pose, and a second switch, or one before anything was mapped, is refused.
TEST(SdpslamdLoop, a_switch_to_localization_keeps_the_session_map_and_localizes_on_it) {
  Rig r;
  Daemon& d = r.make();
  std::string error;
  CHECK_FALSE(d.switch_to_localization(&error));
  STRCMP_CONTAINS("nothing mapped yet", error.c_str());
  // A 6 m x 4 m walled room at 0.1 m, as the mapping engine's map.
  r.engine.map.width = 60U;
  r.engine.map.height = 40U;
  r.engine.map.resolution_m = 0.1;
  r.engine.map.origin_x_m = -1.0;
  r.engine.map.origin_y_m = -2.0;
  for (std::uint32_t row = 0; row < 40U; ++row) {
    for (std::uint32_t c = 0; c < 60U; ++c) {
      r.engine.map.occupancy.push_back(row == 0U || c == 0U || row == 39U || c == 59U ? 1.0F : 0.0F);
    }
  }
  for (int k = 0; k < 5; ++k) r.scan_between_odometry(100U * static_cast<std::uint32_t>(2 * k), 2000000 + 200000LL * k);
  const std::uint64_t mapped = d.counters().scans_processed;
  CHECK(mapped >= 4U);
  CHECK_TRUE_TEXT(d.switch_to_localization(&error), error.c_str());
  const std::string session = r.config.output_directory + "/session";
  CHECK_TRUE(file_exists(session + "/map.yaml"));
  CHECK_TRUE(file_exists(session + "/map.pgm"));
  LONGS_EQUAL(lines_of(r.config.output_directory + "/trajectory.txt"), lines_of(session + "/trajectory.txt"));
  STRCMP_CONTAINS("\"mode\": \"localize\"", d.status_json().c_str());
  const std::size_t fed_to_mapping = r.engine.got.size();
  for (int k = 5; k < 8; ++k) r.scan_between_odometry(100U * static_cast<std::uint32_t>(2 * k), 2000000 + 200000LL * k);
  CHECK(d.counters().scans_placed > mapped);
  LONGS_EQUAL(fed_to_mapping, r.engine.got.size());  // the mapping engine gets no more scans
  CHECK_FALSE(d.switch_to_localization(&error));
  STRCMP_CONTAINS("already localizing", error.c_str());
}

// Every pass of the loop reports to the watchdog, with or without sensors: a supervisor
// hears from a running loop whatever the robot's hardware does, and only from it.
TEST(SdpslamdLoop, each_placed_scan_s_pose_goes_to_the_pose_socket_s_subscribers) {
  Rig r;
  r.config.pose_socket = r.config.output_directory + "/pose.sock";
  r.make();
  // A client: its own bound datagram socket, subscribed with one datagram.
  const std::string me = r.config.output_directory + "/client.sock";
  const int fd = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_NONBLOCK, 0);
  sockaddr_un a{};
  a.sun_family = AF_UNIX;
  std::strcpy(a.sun_path, me.c_str());
  CHECK(::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0);
  sockaddr_un server{};
  server.sun_family = AF_UNIX;
  std::strcpy(server.sun_path, r.config.pose_socket.c_str());
  CHECK(::sendto(fd, "SUBSCRIBE", 9, 0, reinterpret_cast<sockaddr*>(&server), sizeof server) == 9);
  r.scan_between_odometry(0, 1000000);
  r.scan_between_odometry(1000, 2000000);
  LONGS_EQUAL(2, r.engine.got.size());
  for (std::size_t k = 0; k < 2; ++k) {
    unsigned char buf[128];
    const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
    PoseRecord rec;
    CHECK_TRUE(sdpslam::daemon::decode_pose_record(buf, static_cast<std::size_t>(n > 0 ? n : 0), &rec));
    LONGS_EQUAL(k + 1U, rec.sequence);
    LONGS_EQUAL(r.engine.got[k].stamp_us, rec.stamp_us);
    DOUBLES_EQUAL(r.engine.got[k].pose.x_m, rec.pose.x_m, 0.0);  // the fake engine returns the odometry
    LONGS_EQUAL(PoseRecord::kFlagProcessed, rec.flags);
  }
  LONGS_EQUAL(1, r.d->pose_publisher().subscribers());
  LONGS_EQUAL(2, r.d->pose_publisher().stats().datagrams_sent);
  ::close(fd);
  ::unlink(me.c_str());
}

TEST(SdpslamdLoop, every_step_pats_the_watchdog_whether_or_not_the_sensors_answer) {
  Rig r;
  r.make();
  LONGS_EQUAL(0, r.watchdog.pats);
  r.scan_between_odometry(0, 1000000);
  LONGS_EQUAL(2, r.watchdog.pats);
  r.laser.unplug();
  r.bus.s = hal::CanBusState::kBusOff;
  for (int i = 0; i < 5; ++i) r.d->step();
  LONGS_EQUAL(7, r.watchdog.pats);
}
