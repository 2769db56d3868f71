// Serves a robot log to sdpslamd for the end-to-end tests: the log's scans as a SCIP 2.0
// laser on a pseudo-terminal (replay::ScipEngine + LaserPty) and its encoder frames
// either on a SocketCAN interface (replay::Player, one clock for both: the virtual-CAN
// machine) or, on a host without CAN, through sdpslamd's own --can-candump replay started
// on the same monotonic instant as the laser.
//
//   sdpslamd_replay --log LOG --link PATH [--lines N] [--speed S] [--delay-s D]
//       [--can-iface IF --candump FILE]                      frames on SocketCAN
//       [--daemon SDPSLAMD --config INI --out DIR --candump FILE [--tail-s T]
//        [--kill-at-s T1,T2,... [--down-s D]]]                host: runs sdpslamd, SIGTERM at the end
// With --kill-at-s, a supervisor process runs sdpslamd and kills it with SIGKILL at each
// of those times (seconds after the replay's start instant), starting it again D seconds
// later (default 0.5) with the same arguments, as a power cut and a restart would; the
// laser and the encoder frames go on meanwhile (the restarted sdpslamd's --can-candump
// replay keeps the first start instant). SIGTERM at the end goes to the sdpslamd of the
// moment.
// Prints the emulator's counters and the timeline (to map sdpslamd's monotonic stamps back
// to log time); exit 0 iff every CAN frame was sent and (host mode) sdpslamd exited 0.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "sdpslam/drivers/candump_log.h"
#include "sdpslam/drivers/linux_clock.h"
#include "sdpslam/drivers/socketcan_bus.h"
#include "sdpslam/replay/player.h"
#include "sdpslam/replay/replay_log.h"

namespace {

volatile sig_atomic_t g_stop = 0;
void on_term(int) { g_stop = 1; }

int exit_code(int status) { return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status); }

// Runs `argv` (sdpslamd), killing it at kill_at_us (monotonic) and starting it again
// down_us later; on SIGTERM, stops the running one with SIGTERM and exits with its status.
[[noreturn]] void supervise(const std::vector<std::string>& args, const std::vector<std::int64_t>& kill_at_us,
                            std::int64_t down_us, const sdpslam::hal::MonotonicClock& clock) {
  struct sigaction sa {};
  sa.sa_handler = on_term;
  sigaction(SIGTERM, &sa, nullptr);
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  auto spawn = [&argv]() {
    const pid_t pid = fork();
    if (pid == 0) {
      execv(argv[0], argv.data());
      std::perror("exec sdpslamd");
      _exit(127);
    }
    return pid;
  };
  pid_t d = spawn();
  std::size_t next = 0;
  for (;;) {
    int status = 0;
    if (g_stop != 0) {
      kill(d, SIGTERM);
      waitpid(d, &status, 0);
      std::fprintf(stderr, "supervisor: %zu kills\n", next);
      _exit(exit_code(status));
    }
    if (waitpid(d, &status, WNOHANG) == d) {
      std::fprintf(stderr, "supervisor: sdpslamd ended by itself (exit %d)\n", exit_code(status));
      _exit(exit_code(status) == 0 ? 1 : exit_code(status));
    }
    if (next < kill_at_us.size() && clock.now_us() >= kill_at_us[next]) {
      kill(d, SIGKILL);
      waitpid(d, &status, 0);
      ++next;
      std::fprintf(stderr, "supervisor: killed sdpslamd with SIGKILL (%zu)\n", next);
      usleep(static_cast<useconds_t>(down_us));
      d = spawn();
    }
    usleep(10000);
  }
}

}  // namespace

int main(int argc, char** argv) {
  using namespace sdpslam;
  std::string log_path, link, can_iface, candump, daemon, config, out, kill_at;
  double down_s = 0.5;
  std::size_t lines = 0;
  double speed = 1.0, delay_s = 2.0, tail_s = 1.0;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    const char* v = argv[i + 1];
    if (a == "--log") log_path = v;
    else if (a == "--link") link = v;
    else if (a == "--lines") lines = std::strtoul(v, nullptr, 10);
    else if (a == "--speed") speed = std::atof(v);
    else if (a == "--delay-s") delay_s = std::atof(v);
    else if (a == "--tail-s") tail_s = std::atof(v);
    else if (a == "--can-iface") can_iface = v;
    else if (a == "--candump") candump = v;
    else if (a == "--daemon") daemon = v;
    else if (a == "--config") config = v;
    else if (a == "--out") out = v;
    else if (a == "--kill-at-s") kill_at = v;
    else if (a == "--down-s") down_s = std::atof(v);
    else {
      std::fprintf(stderr, "sdpslamd_replay: unknown argument %s\n", a.c_str());
      return 2;
    }
  }
  if (log_path.empty() || link.empty() || !(speed > 0.0)) {
    std::fprintf(stderr, "usage: see the header of sdpslamd_replay.cpp\n");
    return 2;
  }
  replay::ReplayLog log;
  std::string error;
  if (!replay::load_replay_log(log_path, &log, &error) || log.scans.empty()) {
    std::fprintf(stderr, "sdpslamd_replay: %s\n", error.empty() ? "no scans" : error.c_str());
    return 3;
  }
  if (lines > 0 && log.scans.size() > lines) log.scans.resize(lines);
  replay::ScipGeometry geo;
  if (!replay::scip_geometry_for(log.scans.front().scan.geometry, log.scans.front().scan.beam_count, &geo, &error)) {
    std::fprintf(stderr, "sdpslamd_replay: %s\n", error.c_str());
    return 3;
  }
  replay::ScipEngine engine(log.scans, replay::ReplayTimeline{}, geo);
  replay::LaserPty pty;
  if (!pty.open(link, &error)) {
    std::fprintf(stderr, "sdpslamd_replay: %s\n", error.c_str());
    return 4;
  }
  drivers::LinuxMonotonicClock clock;
  std::vector<drivers::CandumpRecord> frames;
  std::int64_t log_start = log.scans.front().stamp_us;
  if (!can_iface.empty()) {
    drivers::CandumpReader reader;
    if (!reader.open(candump.c_str())) {
      std::perror(candump.c_str());
      return 3;
    }
    drivers::CandumpRecord rec;
    for (int r; (r = reader.next(rec)) != 0;) {
      if (r == 1) frames.push_back(rec);
    }
    if (!frames.empty() && frames.front().stamp_us < log_start) log_start = frames.front().stamp_us;
  }
  drivers::SocketCanOptions so;
  std::snprintf(so.interface_name, sizeof so.interface_name, "%s", can_iface.empty() ? "none" : can_iface.c_str());
  std::unique_ptr<drivers::SocketCanBus> bus;
  if (!can_iface.empty()) {
    bus = std::make_unique<drivers::SocketCanBus>(so, clock);
    if (bus->state() == hal::CanBusState::kDown) {
      std::fprintf(stderr, "sdpslamd_replay: cannot open %s\n", can_iface.c_str());
      return 4;
    }
  }
  const std::int64_t delay_us = static_cast<std::int64_t>(delay_s * 1e6);
  pid_t child = -1;
  if (!daemon.empty()) {
    const std::int64_t start_us = clock.now_us() + delay_us;
    const std::string start = std::to_string(start_us);
    char speed_text[32];
    std::snprintf(speed_text, sizeof speed_text, "%g", speed);
    const std::vector<std::string> args = {daemon, "--config", config, "--out", out, "--can-candump", candump,
                                           "--can-candump-start-us", start, "--can-candump-speed", speed_text};
    std::vector<std::int64_t> kill_at_us;
    for (const char* p = kill_at.c_str(); *p != '\0';) {
      char* end = nullptr;
      const double t = std::strtod(p, &end);
      if (end == p) break;
      kill_at_us.push_back(start_us + static_cast<std::int64_t>(t * 1e6));
      p = *end == ',' ? end + 1 : end;
    }
    child = fork();
    if (child == 0) {
      supervise(args, kill_at_us, static_cast<std::int64_t>(down_s * 1e6), clock);
    }
  }
  replay::PlayerOptions po;
  po.tail_us = 200000;
  replay::Player player(clock, po);
  if (bus) player.set_can(bus.get(), &frames);
  player.set_laser(&engine, &pty);
  // Host mode: the laser's timeline starts on the instant given to sdpslamd (to a few µs).
  player.run(log_start, speed, delay_us - (child > 0 ? 0 : 0));
  const replay::LaserReplayStats& l = engine.stats();
  const replay::PlayerStats& ps = player.stats();
  std::printf("replay: speed %g scans %zu served %llu late %llu dropped %llu not_requested %llu max_late_ms %.3f",
              speed, log.scans.size(), static_cast<unsigned long long>(l.scans_served),
              static_cast<unsigned long long>(l.scans_late), static_cast<unsigned long long>(l.scans_dropped),
              static_cast<unsigned long long>(l.scans_not_requested), static_cast<double>(l.max_lateness_us) / 1000.0);
  if (bus) {
    std::printf(" frames %zu sent %llu dropped %llu", frames.size(), static_cast<unsigned long long>(ps.frames_sent),
                static_cast<unsigned long long>(ps.frames_dropped));
  }
  std::printf(" wall_s %.2f\ntimeline: play_start_us %lld log_start_us %lld speed %g\n",
              static_cast<double>(ps.wall_us) * 1e-6, static_cast<long long>(player.timeline().play_start_us),
              static_cast<long long>(player.timeline().log_start_us), speed);
  std::fflush(stdout);
  // Scans the emulator itself dropped (its process woken late on a loaded machine) are
  // reported, not failed: the tests judge sdpslamd's own counters.
  bool ok = ps.frames_dropped == 0;
  if (child > 0) {
    // Keep the pty open while sdpslamd places the last scans, then stop it.
    const std::int64_t tail_end = clock.now_us() + static_cast<std::int64_t>(tail_s * 1e6);
    while (clock.now_us() < tail_end) {
      pty.pump(engine, clock.now_us());
      usleep(5000);
    }
    kill(child, SIGTERM);
    int status = 0;
    waitpid(child, &status, 0);
    const int rc = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    std::printf("sdpslamd exit %d\n", rc);
    ok = ok && rc == 0;
  }
  return ok ? 0 : 1;
}
