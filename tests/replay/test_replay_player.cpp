// The real-time player: its schedule on a clock the test moves (exact, whatever the
// machine's load), a real play over socketpair(AF_UNIX, SOCK_SEQPACKET) (16-byte
// datagrams like CAN_RAW) through SocketCanBus::AdoptFd at speed x20, and "try later"
// from the bus retried, never dropped silently. Arrival-time figures over many plays:
// bench_replay_player.
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
#include "synthetic_can.h"

using namespace sdpslam;
using namespace sdpslam::replay;
using sdpslam::replay::test::synthetic_frames;

namespace {

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

// A clock that moves only when read: every now_us() advances it by step_us, plus a
// one-off jump of jump_us at the read numbered jump_at_read. The player still sleeps in
// real time between reads, but what it decides depends only on this clock, so the
// timing of its decisions can be checked exactly whatever the machine's load.
class SteppingClock final : public hal::MonotonicClock {
 public:
  SteppingClock(std::int64_t step_us, long jump_at_read = -1, std::int64_t jump_us = 0)
      : step_us_(step_us), jump_at_read_(jump_at_read), jump_us_(jump_us) {}
  std::int64_t now_us() const override {
    t_us_ += step_us_;
    if (reads_++ == jump_at_read_) t_us_ += jump_us_;
    return t_us_;
  }
  std::int64_t peek_us() const { return t_us_; }

 private:
  std::int64_t step_us_;
  long jump_at_read_;
  std::int64_t jump_us_;
  mutable std::int64_t t_us_ = 1000000;
  mutable long reads_ = 0;
};

// Takes every frame and notes the clock (without moving it) when it was handed over.
class StampingBus final : public hal::CanBus {
 public:
  explicit StampingBus(const SteppingClock& clock) : clock_(clock) {}
  int send(const hal::CanFrame& f) override {
    sent.push_back(f);
    sent_at_us.push_back(clock_.peek_us());
    return 1;
  }
  int receive(hal::CanFrame&) override { return 0; }
  int wait_readable(std::int64_t) override { return 0; }
  hal::CanBusState state() const override { return hal::CanBusState::kActive; }
  const hal::CanBusStats& stats() const override { return stats_; }
  std::vector<hal::CanFrame> sent;
  std::vector<std::int64_t> sent_at_us;

 private:
  const SteppingClock& clock_;
  hal::CanBusStats stats_;
};

}  // namespace

TEST_GROUP(ReplayPlayer){};

// Over a real socket at speed x20 (2 s of log in 100 ms), whatever the machine's load:
// every frame arrives, in order, none before its scaled time, none dropped, and the play
// takes its scaled duration but not the unscaled one. How close to its time a frame
// arrives depends on how soon the scheduler wakes the player and the receiver; that
// figure is printed here and measured over many plays by bench_replay_player.
TEST(ReplayPlayer, frames_cross_a_socketpair_at_speed_20_in_order_none_early_none_dropped) {
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
  const std::int64_t end = clock.now_us() + 10000000;
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
  double sum_us = 0.0;
  double worst_us = 0.0;
  std::size_t early = 0;
  for (std::size_t i = 0; i < got.size(); ++i) {
    LONGS_EQUAL(frames[i].frame.id, got[i].id);  // order kept
    const std::int64_t due = player.timeline().due_us(frames[i].stamp_us);
    if (rx_us[i] < due) ++early;  // never before its time
    const double err = std::fabs(static_cast<double>(rx_us[i] - due));
    worst_us = std::fmax(worst_us, err);
    sum_us += err;
  }
  LONGS_EQUAL(0, early);
  const std::int64_t scaled_us = static_cast<std::int64_t>(
      static_cast<double>(frames.back().stamp_us - frames.front().stamp_us) / speed);
  CHECK_TRUE(player.stats().wall_us >= scaled_us);
  CHECK_TRUE(player.stats().wall_us < scaled_us * 10);  // speed applied (unscaled: 2 s)
  std::printf("\nplayer x20: %zu frames, |arrival - due| mean %.0f us, worst %.0f us, wall %.1f ms\n", got.size(),
              sum_us / static_cast<double>(got.size()), worst_us,
              static_cast<double>(player.stats().wall_us) / 1000.0);
}

// The schedule itself, on a clock that moves 300 us per read: a frame is handed to the
// bus at the first read of the clock at or after its due time, so never early and never
// more than two reads (one pass of the player's loop) late; nothing is counted late.
TEST(ReplayPlayer, on_its_own_clock_each_frame_goes_out_within_one_loop_pass_of_its_time) {
  const std::int64_t step_us = 300;
  SteppingClock clock(step_us);
  StampingBus bus(clock);
  const std::vector<drivers::CandumpRecord> frames = synthetic_frames(50);
  Player player(clock, PlayerOptions{});
  player.set_can(&bus, &frames);
  player.run(frames.front().stamp_us, 20.0, 1000);
  LONGS_EQUAL(frames.size(), bus.sent.size());
  LONGS_EQUAL(frames.size(), player.stats().frames_sent);
  LONGS_EQUAL(0, player.stats().frames_late);
  LONGS_EQUAL(0, player.stats().frames_dropped);
  std::int64_t worst_late_us = 0;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    LONGS_EQUAL(frames[i].frame.id, bus.sent[i].id);
    const std::int64_t late_us = bus.sent_at_us[i] - player.timeline().due_us(frames[i].stamp_us);
    CHECK_TRUE(late_us >= 0);
    CHECK_TRUE(late_us < 2 * step_us);
    if (late_us > worst_late_us) worst_late_us = late_us;
  }
  LONGS_EQUAL(worst_late_us, player.stats().max_frame_lateness_us);
  // The frames of one period share a stamp: all three go out on the same read.
  for (std::size_t i = 0; i + 2 < frames.size(); i += 3) {
    LONGS_EQUAL(bus.sent_at_us[i], bus.sent_at_us[i + 1]);
    LONGS_EQUAL(bus.sent_at_us[i], bus.sent_at_us[i + 2]);
  }
}

// A stall (the clock jumps 40 ms, as when the player's thread is descheduled) makes the
// frames due during it go out at once, in order, late by what the clock says, and those
// beyond late_threshold_us are counted in frames_late; none is dropped or skipped.
TEST(ReplayPlayer, a_stall_sends_the_frames_due_during_it_in_order_and_counts_them_late) {
  const std::int64_t step_us = 100;
  const std::int64_t stall_us = 40000;
  SteppingClock clock(step_us, 20, stall_us);
  StampingBus bus(clock);
  const std::vector<drivers::CandumpRecord> frames = synthetic_frames(60);  // 500 us apart at x20
  PlayerOptions o;
  o.late_threshold_us = 5000;
  Player player(clock, o);
  player.set_can(&bus, &frames);
  player.run(frames.front().stamp_us, 20.0, 0);
  LONGS_EQUAL(frames.size(), bus.sent.size());
  LONGS_EQUAL(0, player.stats().frames_dropped);
  std::uint64_t late = 0;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    LONGS_EQUAL(frames[i].frame.id, bus.sent[i].id);
    const std::int64_t late_us = bus.sent_at_us[i] - player.timeline().due_us(frames[i].stamp_us);
    CHECK_TRUE(late_us >= 0);
    if (late_us > o.late_threshold_us) ++late;
  }
  CHECK_TRUE(late > 0);
  LONGS_EQUAL(late, player.stats().frames_late);
  CHECK_TRUE(player.stats().max_frame_lateness_us > stall_us - 2000);
  CHECK_TRUE(player.stats().max_frame_lateness_us <= stall_us + 2 * step_us);
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
