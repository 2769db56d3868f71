// The real-time player: timing over socketpair(AF_UNIX, SOCK_SEQPACKET) (16-byte
// datagrams like CAN_RAW) through SocketCanBus::AdoptFd at speed ×20, and "try later"
// from the bus retried, never dropped silently.
#include <sys/socket.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <thread>
#include <vector>

#include "CppUTest/TestHarness.h"
#include "sdpslam/drivers/canopen_codec.h"
#include "sdpslam/drivers/linux_clock.h"
#include "sdpslam/drivers/socketcan_bus.h"
#include "sdpslam/replay/player.h"

using namespace sdpslam;
using namespace sdpslam::replay;

namespace {

// 2 s of log: SYNC + two TPDO1 every 10 ms (the layout replay-can writes).
std::vector<drivers::CandumpRecord> synthetic_frames(std::size_t periods) {
  std::vector<drivers::CandumpRecord> v;
  for (std::size_t k = 0; k < periods; ++k) {
    drivers::CandumpRecord r;
    r.stamp_us = 1700000000000000LL + static_cast<std::int64_t>(k) * 10000;
    r.has_stamp = true;
    r.frame = drivers::canopen::make_sync();
    v.push_back(r);
    drivers::canopen::make_tpdo1_position(1, static_cast<std::uint32_t>(k), 4, r.frame);
    v.push_back(r);
    drivers::canopen::make_tpdo1_position(2, static_cast<std::uint32_t>(3 * k), 4, r.frame);
    v.push_back(r);
  }
  return v;
}

// A bus that says "try later" for the first `refusals` sends, then takes everything.
class BusyBus final : public hal::CanBus {
 public:
  explicit BusyBus(int refusals, bool error = false) : refusals_(refusals), error_(error) {}
  int send(const hal::CanFrame& f) override {
    if (refusals_ < 0) return error_ ? -1 : 0;  // refuses for ever
    if (refusals_ > 0) {
      --refusals_;
      return error_ ? -1 : 0;
    }
    sent.push_back(f);
    return 1;
  }
  int receive(hal::CanFrame&) override { return 0; }
  int wait_readable(std::int64_t) override { return 0; }
  hal::CanBusState state() const override { return hal::CanBusState::kActive; }
  const hal::CanBusStats& stats() const override { return stats_; }
  std::vector<hal::CanFrame> sent;

 private:
  int refusals_;
  bool error_;
  hal::CanBusStats stats_;
};

}  // namespace

TEST_GROUP(ReplayPlayer){};

TEST(ReplayPlayer, frames_arrive_at_their_recorded_times_over_a_socketpair_at_speed_20) {
  int sv[2];
  LONGS_EQUAL(0, ::socketpair(AF_UNIX, SOCK_SEQPACKET, 0, sv));
  drivers::LinuxMonotonicClock clock;
  drivers::SocketCanOptions opt;
  opt.kernel_timestamps = false;
  drivers::SocketCanBus tx(drivers::SocketCanBus::AdoptFd{sv[0]}, opt, clock);
  drivers::SocketCanBus rx(drivers::SocketCanBus::AdoptFd{sv[1]}, opt, clock);
  const std::vector<drivers::CandumpRecord> frames = synthetic_frames(200);
  const double speed = 20.0;
  Player player(clock, PlayerOptions{});
  player.set_can(&tx, &frames);
  std::vector<std::int64_t> rx_us;
  std::vector<hal::CanFrame> got;
  std::thread t([&] { player.run(frames.front().stamp_us, speed, 20000); });
  const std::int64_t end = clock.now_us() + 3000000;
  while (got.size() < frames.size() && clock.now_us() < end) {
    hal::CanFrame f;
    if (rx.receive(f) == 1) {
      rx_us.push_back(clock.now_us());
      got.push_back(f);
    } else {
      rx.wait_readable(2000);
    }
  }
  t.join();
  LONGS_EQUAL(frames.size(), got.size());
  LONGS_EQUAL(frames.size(), player.stats().frames_sent);
  LONGS_EQUAL(0, player.stats().frames_dropped);
  double worst_us = 0.0, sum_us = 0.0;
  std::size_t early = 0;
  for (std::size_t i = 0; i < got.size(); ++i) {
    LONGS_EQUAL(frames[i].frame.id, got[i].id);  // order kept
    const std::int64_t due = player.timeline().due_us(frames[i].stamp_us);
    if (rx_us[i] < due) ++early;  // never before its time
    const double err = std::fabs(static_cast<double>(rx_us[i] - due));
    worst_us = std::fmax(worst_us, err);
    sum_us += err;
  }
  const double mean_us = sum_us / static_cast<double>(got.size());
  // 2 s of log in 100 ms: no frame before its scaled time, on average within a few
  // milliseconds after it (arrival includes the receiving thread's wake-up); the worst case
  // is bounded by what a shared, loaded machine's scheduler allows.
  std::printf("\nplayer x20: %zu frames, |arrival - due| mean %.0f us, worst %.0f us, wall %.1f ms\n", got.size(),
              mean_us, worst_us, static_cast<double>(player.stats().wall_us) / 1000.0);
  LONGS_EQUAL(0, early);
  CHECK_TRUE(mean_us < 3000.0);
  CHECK_TRUE(worst_us < 30000.0);
  CHECK_TRUE(player.stats().wall_us < 400000);
}

TEST(ReplayPlayer, try_later_from_the_bus_is_retried_and_counted_not_dropped) {
  drivers::LinuxMonotonicClock clock;
  BusyBus bus(5);
  const std::vector<drivers::CandumpRecord> frames = synthetic_frames(3);
  Player player(clock, PlayerOptions{});
  player.set_can(&bus, &frames);
  player.run(frames.front().stamp_us, 10.0);
  LONGS_EQUAL(frames.size(), bus.sent.size());
  LONGS_EQUAL(frames.size(), player.stats().frames_sent);
  LONGS_EQUAL(5, player.stats().send_try_later);
  LONGS_EQUAL(0, player.stats().frames_dropped);
}

TEST(ReplayPlayer, a_bus_that_keeps_failing_makes_frames_dropped_and_counted) {
  drivers::LinuxMonotonicClock clock;
  BusyBus bus(-1, true);
  const std::vector<drivers::CandumpRecord> frames = synthetic_frames(2);
  PlayerOptions o;
  o.give_up_us = 5000;
  Player player(clock, o);
  player.set_can(&bus, &frames);
  player.run(frames.front().stamp_us, 10.0);
  LONGS_EQUAL(0, player.stats().frames_sent);
  LONGS_EQUAL(frames.size(), player.stats().frames_dropped);
  CHECK_TRUE(player.stats().send_errors > 0);
}
