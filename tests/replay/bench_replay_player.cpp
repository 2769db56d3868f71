// Benchmark of the real-time player's timing: how close to its scaled time each CAN
// frame arrives at a receiver over socketpair(AF_UNIX, SOCK_SEQPACKET) (16-byte
// datagrams like CAN_RAW), through SocketCanBus::AdoptFd. Arrival includes the
// receiving thread's wake-up, so the figures depend on the machine's load: they are
// printed, not asserted (the test suite checks what holds under any load).
// A plain program (not a test); build it in a Release directory:
//   cmake --build --preset host-release --target bench_replay_player
//   build/host-release/tests/replay/bench_replay_player [plays=20] [speed=20]
// Target on an idle machine: mean |arrival - due| under 3 ms, worst under 30 ms.
#include <sys/socket.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <thread>
#include <vector>

#include "sdpslam/drivers/linux_clock.h"
#include "sdpslam/drivers/socketcan_bus.h"
#include "sdpslam/replay/player.h"
#include "synthetic_can.h"

using namespace sdpslam;

int main(int argc, char** argv) {
  const int plays = argc > 1 ? std::atoi(argv[1]) : 20;
  const double speed = argc > 2 ? std::atof(argv[2]) : 20.0;
  if (plays < 1 || !(speed > 0.0)) {
    std::fprintf(stderr, "usage: bench_replay_player [plays>=1] [speed>0]\n");
    return 2;
  }
  const std::vector<drivers::CandumpRecord> frames = replay::test::synthetic_frames(200);
  std::vector<double> err_us;       // every frame of every play
  std::vector<double> play_mean_us;  // per play
  std::uint64_t lost = 0;
  std::uint64_t early = 0;
  drivers::LinuxMonotonicClock clock;
  for (int p = 0; p < plays; ++p) {
    int sv[2];
    if (::socketpair(AF_UNIX, SOCK_SEQPACKET, 0, sv) != 0) {
      std::perror("socketpair");
      return 1;
    }
    drivers::SocketCanOptions opt;
    opt.kernel_timestamps = false;
    drivers::SocketCanBus tx(drivers::SocketCanBus::AdoptFd{sv[0]}, opt, clock);
    drivers::SocketCanBus rx(drivers::SocketCanBus::AdoptFd{sv[1]}, opt, clock);
    replay::Player player(clock, replay::PlayerOptions{});
    player.set_can(&tx, &frames);
    std::vector<std::int64_t> rx_us;
    rx_us.reserve(frames.size());
    std::thread t([&] { player.run(frames.front().stamp_us, speed, 20000); });
    const std::int64_t end = clock.now_us() + 30000000;
    while (rx_us.size() < frames.size() && clock.now_us() < end) {
      hal::CanFrame f;
      if (rx.receive(f) == 1) {
        rx_us.push_back(clock.now_us());
      } else {
        rx.wait_readable(2000);
      }
    }
    t.join();
    lost += frames.size() - rx_us.size();
    double sum = 0.0;
    for (std::size_t i = 0; i < rx_us.size(); ++i) {
      const std::int64_t due = player.timeline().due_us(frames[i].stamp_us);
      if (rx_us[i] < due) ++early;
      const double e = std::fabs(static_cast<double>(rx_us[i] - due));
      err_us.push_back(e);
      sum += e;
    }
    play_mean_us.push_back(rx_us.empty() ? 0.0 : sum / static_cast<double>(rx_us.size()));
  }
  if (err_us.empty()) {
    std::fprintf(stderr, "bench_replay_player: no frame arrived\n");
    return 1;
  }
  std::sort(err_us.begin(), err_us.end());
  auto pct = [&](double q) {
    const std::size_t i = static_cast<std::size_t>(q * static_cast<double>(err_us.size() - 1));
    return err_us[i];
  };
  double sum = 0.0;
  for (double e : err_us) sum += e;
  std::sort(play_mean_us.begin(), play_mean_us.end());
  std::printf("player x%.0f: %d plays of %zu frames; |arrival - due| mean %.0f us, median %.0f us, p99 %.0f us, "
              "worst %.0f us; per-play mean: best %.0f us, median %.0f us, worst %.0f us; lost %llu, early %llu\n",
              speed, plays, frames.size(), sum / static_cast<double>(err_us.size()), pct(0.5), pct(0.99),
              err_us.back(), play_mean_us.front(), play_mean_us[play_mean_us.size() / 2], play_mean_us.back(),
              static_cast<unsigned long long>(lost), static_cast<unsigned long long>(early));
  return lost == 0 && early == 0 ? 0 : 1;
}
