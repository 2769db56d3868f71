// Plays a candump -l log onto a SocketCAN interface at its recorded rate × speed
// (replay::Player). Usage: hil_can_player LOG.candump IFACE [SPEED] [START_DELAY_MS]
// Prints the player's counters; exit 0 iff every frame was sent.
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "sdpslam/drivers/candump_log.h"
#include "sdpslam/drivers/linux_clock.h"
#include "sdpslam/drivers/socketcan_bus.h"
#include "sdpslam/replay/player.h"

int main(int argc, char** argv) {
  using namespace sdpslam;
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s LOG.candump IFACE [SPEED] [START_DELAY_MS]\n", argv[0]);
    return 2;
  }
  const double speed = argc > 3 ? std::atof(argv[3]) : 1.0;
  const std::int64_t delay_us = argc > 4 ? std::atoll(argv[4]) * 1000 : 0;
  drivers::CandumpReader reader;
  if (!reader.open(argv[1])) {
    std::perror(argv[1]);
    return 3;
  }
  std::vector<drivers::CandumpRecord> frames;
  drivers::CandumpRecord rec;
  for (int r; (r = reader.next(rec)) != 0;) {
    if (r == 1) frames.push_back(rec);
    else std::fprintf(stderr, "%s:%zu: %s\n", argv[1], reader.line_number(), drivers::to_string(reader.error()));
  }
  if (frames.empty() || !(speed > 0.0)) {
    std::fprintf(stderr, "no frames or bad speed\n");
    return 3;
  }
  drivers::LinuxMonotonicClock clock;
  drivers::SocketCanOptions opt;
  std::snprintf(opt.interface_name, sizeof opt.interface_name, "%s", argv[2]);
  drivers::SocketCanBus bus(opt, clock);
  replay::Player player(clock, replay::PlayerOptions{});
  player.set_can(&bus, &frames);
  player.run(frames.front().stamp_us, speed, delay_us);
  const replay::PlayerStats& s = player.stats();
  std::printf("player: frames %zu sent %llu late %llu dropped %llu try_later %llu errors %llu max_late_us %lld wall_ms %lld\n",
              frames.size(), static_cast<unsigned long long>(s.frames_sent), static_cast<unsigned long long>(s.frames_late),
              static_cast<unsigned long long>(s.frames_dropped), static_cast<unsigned long long>(s.send_try_later),
              static_cast<unsigned long long>(s.send_errors), static_cast<long long>(s.max_frame_lateness_us),
              static_cast<long long>(s.wall_us / 1000));
  return s.frames_sent == frames.size() ? 0 : 1;
}
