// Receives CANopen encoder frames on a SocketCAN interface through the onboard stack
// (CanWheelEncoders + EncoderOdometrySource) and prints the final odometry pose, then
// integrates the same candump offline (replay::integrate_canopen_frames) and compares.
// Usage: hil_odom_receiver IFACE LOG.candump EXPECTED_PAIRS IDLE_TIMEOUT_MS
// A pair is handed to the odometry only when both wheels have a new sample (the TPDO1s
// answering one SYNC), which is what a host sampling on SYNC does. Exit 0 iff the poses
// are bit-identical and every pair arrived.
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "sdpslam/drivers/can_wheel_encoders.h"
#include "sdpslam/drivers/candump_log.h"
#include "sdpslam/drivers/diff_drive_odometry.h"
#include "sdpslam/drivers/linux_clock.h"
#include "sdpslam/drivers/socketcan_bus.h"
#include "sdpslam/replay/encoder_frames.h"

namespace {
using namespace sdpslam;

// Hands on a wheel sample only once both wheels moved on (a complete SYNC answer).
class CompletePairs final : public hal::WheelEncoderSource {
 public:
  explicit CompletePairs(hal::WheelEncoderSource& inner) : inner_(inner) {}
  int update() override {
    const int r = inner_.update();
    const hal::WheelEncoderSample s = inner_.latest();
    if (s.left.sequence != held_.left.sequence && s.right.sequence != held_.right.sequence) held_ = s;
    held_.left.stale = s.left.stale;
    held_.right.stale = s.right.stale;
    return r;
  }
  hal::WheelEncoderSample latest() const override { return held_; }

 private:
  hal::WheelEncoderSource& inner_;
  hal::WheelEncoderSample held_;
};

void print_pose(const char* what, const Pose2& p) {
  std::printf("%s x=%a y=%a th=%a (%.9f %.9f %.9f)\n", what, p.x_m, p.y_m, p.heading_rad, p.x_m, p.y_m, p.heading_rad);
}
}  // namespace

int main(int argc, char** argv) {
  if (argc < 5) {
    std::fprintf(stderr, "usage: %s IFACE LOG.candump EXPECTED_PAIRS IDLE_TIMEOUT_MS\n", argv[0]);
    return 2;
  }
  const std::uint64_t expected = std::strtoull(argv[3], nullptr, 10);
  const std::int64_t idle_us = std::atoll(argv[4]) * 1000;
  drivers::DiffDriveParams params;  // MinesRover: 2000 ticks/rev, r 77 mm, axle 330 mm
  drivers::CanWheelEncoderConfig cfg;
  cfg.protocol = drivers::EncoderProtocol::kCanOpen;
  cfg.canopen.left_node = 1;
  cfg.canopen.right_node = 2;
  cfg.canopen.send_nmt_start = false;
  cfg.canopen.sync_period_us = 0;  // the replayed log carries the SYNCs
  cfg.canopen.max_frames_per_update = 1;
  cfg.canopen.position_timeout_us = 2000000;
  drivers::LinuxMonotonicClock clock;
  drivers::SocketCanOptions opt;
  std::snprintf(opt.interface_name, sizeof opt.interface_name, "%s", argv[1]);
  if (!drivers::add_receive_filters(cfg, opt)) return 2;
  drivers::SocketCanBus bus(opt, clock);
  if (bus.state() != hal::CanBusState::kActive) {
    std::fprintf(stderr, "cannot open %s: %s\n", argv[1], drivers::to_string(bus.last_error()));
    return 3;
  }
  drivers::CanWheelEncoders enc(bus, clock, cfg);
  CompletePairs pairs(enc);
  drivers::EncoderOdometrySource odom(pairs, params);
  std::printf("receiver: ready\n");
  std::fflush(stdout);
  std::uint64_t integrated = 0;
  std::int64_t last_rx = clock.now_us();
  bool any = false;
  for (;;) {
    const std::uint64_t before = bus.stats().rx_frames;
    const int r = odom.update();
    if (r == 1) ++integrated;
    if (bus.stats().rx_frames != before) {
      last_rx = clock.now_us();
      any = true;
      continue;
    }
    if (clock.now_us() - last_rx > (any ? idle_us : 30000000)) break;
    bus.wait_readable(20000);
  }
  const Pose2 live = odom.odometry().pose();
  std::printf("receiver: frames %llu integrated %llu relatch %u overflows %llu\n",
              static_cast<unsigned long long>(bus.stats().rx_frames), static_cast<unsigned long long>(integrated),
              odom.relatch_count(), static_cast<unsigned long long>(bus.stats().rx_overflows));
  print_pose("live   ", live);

  drivers::CandumpReader reader;
  std::vector<drivers::CandumpRecord> recs;
  drivers::CandumpRecord rec;
  if (!reader.open(argv[2])) return 3;
  for (int rr; (rr = reader.next(rec)) != 0;) {
    if (rr == 1) recs.push_back(rec);
  }
  Pose2 offline;
  const std::size_t n = replay::integrate_canopen_frames(recs, params, 1, 2, &offline);
  print_pose("offline", offline);
  const bool identical = std::memcmp(&live, &offline, sizeof live) == 0;
  const double dx = live.x_m - offline.x_m, dy = live.y_m - offline.y_m;
  std::printf("receiver: pairs offline %zu live %llu expected %llu; %s (|dxy| %.3g m, dth %.3g rad)\n", n,
              static_cast<unsigned long long>(integrated + 1), static_cast<unsigned long long>(expected),
              identical ? "BIT-IDENTICAL" : "DIFFERENT", std::sqrt(dx * dx + dy * dy), live.heading_rad - offline.heading_rad);
  return identical && integrated + 1 == expected && n == expected ? 0 : 1;
}
