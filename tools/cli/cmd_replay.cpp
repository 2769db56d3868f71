// Hardware-in-the-loop replay commands (tools/replay):
//   sdpslam replay-can LOG OUT.candump   encoder CAN frames from a log's odometry
//   sdpslam replay-laser LOG --link PATH a SCIP 2.0 / SICK laser on a pseudo-terminal
//   sdpslam replay --can-log F --can-iface IF [--laser LOG --laser-link PATH]
//                                        both at recorded time × speed on one clock
#include <climits>
#include <cstdio>
#include <memory>
#include <string>

#include "cli_common.h"
#include "sdpslam/drivers/linux_clock.h"
#include "sdpslam/drivers/socketcan_bus.h"
#include "sdpslam/replay/encoder_frames.h"
#include "sdpslam/replay/player.h"
#include "sdpslam/replay/replay_log.h"
#include "sdpslam/replay/tinyslam_ticks.h"

namespace sdpslam::cli {
namespace {

constexpr std::size_t kErrorsPrinted = 20;

void print_errors(const char* cmd, const std::vector<std::string>& errors) {
  for (std::size_t i = 0; i < errors.size() && i < kErrorsPrinted; ++i) {
    std::fprintf(stderr, "sdpslam %s: skipped %s\n", cmd, errors[i].c_str());
  }
  if (errors.size() > kErrorsPrinted) {
    std::fprintf(stderr, "sdpslam %s: ... %zu skipped lines in all\n", cmd, errors.size());
  }
}

// ------------------------------------------------------------------ replay-can
struct CanArgs {
  std::string log;
  std::string out;
  std::string protocol = "canopen";
  double ticks_per_rev = 2000.0;
  double wheel_radius_m = 0.077;
  double wheel_separation_m = 0.330;
  int left_node = 1;
  int right_node = 2;
  std::string iface = "can0";
  double period_ms = 10.0;
  bool no_sync = false;
  std::string source = "auto";
};

bool is_tinyslam(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "r");
  if (f == nullptr) return false;
  int c = std::fgetc(f);
  while (c == ' ' || c == '\t') c = std::fgetc(f);
  std::fclose(f);
  return c >= '0' && c <= '9';  // tinySLAM lines are numbers only
}

int run_replay_can(const CanArgs& a) {
  replay::EncoderFrameOptions o;
  if (!drivers::parse_encoder_protocol(a.protocol, o.protocol)) {
    std::fprintf(stderr, "sdpslam replay-can: unknown protocol '%s' (canopen, odrive)\n", a.protocol.c_str());
    return kExitUsage;
  }
  o.params.ticks_per_rev = a.ticks_per_rev;
  o.params.left_radius_m = o.params.right_radius_m = a.wheel_radius_m;
  o.params.wheel_separation_m = a.wheel_separation_m;
  o.left_node = static_cast<std::uint8_t>(a.left_node);
  o.right_node = static_cast<std::uint8_t>(a.right_node);
  o.with_sync = !a.no_sync;
  std::snprintf(o.interface_name, sizeof o.interface_name, "%s", a.iface.c_str());
  std::string error;
  std::vector<replay::TickSample> track;
  const bool ticks = a.source == "ticks" || (a.source == "auto" && is_tinyslam(a.log));
  if (ticks) {
    replay::TinySlamTicks t;
    if (!replay::read_tinyslam_ticks(a.log, &t, &error)) {
      std::fprintf(stderr, "sdpslam replay-can: %s\n", error.c_str());
      return kExitBadInput;
    }
    print_errors("replay-can", t.errors);
    track = std::move(t.samples);
    std::printf("source: real wheel ticks of %zu tinySLAM lines\n", track.size());
  } else {
    replay::ReplayLog log;
    if (!replay::load_replay_log(a.log, &log, &error)) {
      std::fprintf(stderr, "sdpslam replay-can: %s\n", error.c_str());
      return kExitBadInput;
    }
    print_errors("replay-can", log.errors);
    std::size_t dropped = 0;
    const auto period_us = static_cast<std::int64_t>(a.period_ms * 1000.0 + 0.5);
    if (!replay::poses_to_tick_track(log.odometry, o.params, period_us, &track, &dropped, &error)) {
      std::fprintf(stderr, "sdpslam replay-can: %s: %s\n", a.log.c_str(), error.c_str());
      return kExitBadInput;
    }
    std::printf("source: %zu odometry poses (%s), %zu with non-increasing stamps dropped; %zu samples every %.3f ms\n",
                log.odometry.size(), log.odometry_from_laser_records ? "from laser records" : "ODOM lines", dropped,
                track.size(), a.period_ms);
  }
  std::vector<drivers::CandumpRecord> frames;
  if (!replay::tick_track_to_frames(track, o, &frames, &error)) {
    std::fprintf(stderr, "sdpslam replay-can: %s\n", error.c_str());
    return kExitUsage;
  }
  if (!replay::write_candump_file(a.out, frames, &error)) {
    std::fprintf(stderr, "sdpslam replay-can: %s\n", error.c_str());
    return kExitIo;
  }
  std::printf("wrote %zu frames (%s) to %s\n", frames.size(), drivers::to_string(o.protocol), a.out.c_str());
  return kExitOk;
}

std::function<int()> setup_replay_can(CLI::App& app) {
  auto a = std::make_shared<CanArgs>();
  app.add_option("LOG", a->log, "robot log (CARMEN, tinySLAM, DP-SLAM)")->required();
  app.add_option("OUT", a->out, "output candump -l log")->required();
  app.add_option("--protocol", a->protocol, "canopen (TPDO1 u32) or odrive (Get_Encoder_Estimates)");
  app.add_option("--source", a->source, "auto: real ticks for tinySLAM logs, else odometry poses; ticks; poses")
      ->check(CLI::IsMember({"auto", "ticks", "poses"}));
  app.add_option("--ticks-per-rev", a->ticks_per_rev, "encoder ticks per wheel revolution")->check(CLI::PositiveNumber);
  app.add_option("--wheel-radius", a->wheel_radius_m, "wheel radius, m")->check(CLI::PositiveNumber);
  app.add_option("--wheel-separation", a->wheel_separation_m, "distance between the wheels, m")->check(CLI::PositiveNumber);
  app.add_option("--left-node", a->left_node, "left encoder node id")->check(CLI::Range(1, 127));
  app.add_option("--right-node", a->right_node, "right encoder node id")->check(CLI::Range(1, 127));
  app.add_option("--iface", a->iface, "interface name written in the log");
  app.add_option("--period-ms", a->period_ms, "sampling period for pose logs, ms")->check(CLI::PositiveNumber);
  app.add_flag("--no-sync", a->no_sync, "CANopen: no SYNC frame before each pair (the receiver produces SYNC)");
  return [a] { return run_replay_can(*a); };
}

// ------------------------------------------------------------------ players
struct PlayArgs {
  std::string can_log;
  std::string can_iface;
  std::string laser_log;
  std::string link;
  std::string protocol = "scip";
  double speed = 1.0;
  double start_delay_s = 0.0;
};

int run_play(const PlayArgs& a, const char* cmd) {
  std::string error;
  drivers::LinuxMonotonicClock clock;
  std::vector<drivers::CandumpRecord> frames;
  std::unique_ptr<drivers::SocketCanBus> bus;
  std::int64_t log_start = INT64_MAX;
  if (!a.can_log.empty()) {
    drivers::CandumpReader reader;
    if (!reader.open(a.can_log.c_str())) {
      std::fprintf(stderr, "sdpslam %s: %s: cannot open\n", cmd, a.can_log.c_str());
      return kExitBadInput;
    }
    drivers::CandumpRecord rec;
    for (int r; (r = reader.next(rec)) != 0;) {
      if (r == 1) {
        frames.push_back(rec);
      } else {
        std::fprintf(stderr, "sdpslam %s: skipped %s:%zu: %s (column %zu)\n", cmd, a.can_log.c_str(),
                     reader.line_number(), drivers::to_string(reader.error()), reader.column());
      }
    }
    if (!frames.empty()) log_start = frames.front().stamp_us;
    drivers::SocketCanOptions opt;
    std::snprintf(opt.interface_name, sizeof opt.interface_name, "%s", a.can_iface.c_str());
    bus = std::make_unique<drivers::SocketCanBus>(opt, clock);
    if (bus->state() == hal::CanBusState::kDown) {
      std::fprintf(stderr, "sdpslam %s: cannot open CAN interface %s: %s (errno %d)\n", cmd, a.can_iface.c_str(),
                   drivers::to_string(bus->last_error()), bus->last_errno());
      return kExitIo;
    }
  }
  replay::ReplayLog log;
  std::unique_ptr<replay::LaserEngine> engine;
  replay::LaserPty pty;
  if (!a.laser_log.empty()) {
    if (!replay::load_replay_log(a.laser_log, &log, &error)) {
      std::fprintf(stderr, "sdpslam %s: %s\n", cmd, error.c_str());
      return kExitBadInput;
    }
    print_errors(cmd, log.errors);
    if (log.scans.empty()) {
      std::fprintf(stderr, "sdpslam %s: %s: no laser scans\n", cmd, a.laser_log.c_str());
      return kExitBadInput;
    }
    if (log.scans.front().stamp_us < log_start) log_start = log.scans.front().stamp_us;
    if (a.protocol == "scip") {
      replay::ScipGeometry geo;
      if (!replay::scip_geometry_for(log.scans.front().scan.geometry, log.scans.front().scan.beam_count, &geo, &error)) {
        std::fprintf(stderr, "sdpslam %s: %s\n", cmd, error.c_str());
        return kExitBadInput;
      }
      std::printf("SCIP geometry: ARES %u AFRT %u AMIN %u AMAX %u DMIN %u DMAX %u; ask MD with cluster %u for the log's %u beams\n",
                  geo.ares, geo.afrt, geo.amin, geo.amax, geo.dmin_mm, geo.dmax_mm, geo.steps_per_beam, geo.beam_count);
      engine = std::make_unique<replay::ScipEngine>(log.scans, replay::ReplayTimeline{}, geo);
    } else {
      engine = std::make_unique<replay::SickEngine>(log.scans, replay::ReplayTimeline{});
    }
    if (!pty.open(a.link, &error)) {
      std::fprintf(stderr, "sdpslam %s: %s\n", cmd, error.c_str());
      return kExitIo;
    }
    std::printf("laser (%s) on %s -> %s\n", a.protocol.c_str(), a.link.c_str(), pty.slave_name().c_str());
  }
  std::fflush(stdout);
  replay::Player player(clock, replay::PlayerOptions{});
  if (bus) player.set_can(bus.get(), &frames);
  if (engine) player.set_laser(engine.get(), &pty);
  player.run(log_start, a.speed, static_cast<std::int64_t>(a.start_delay_s * 1e6));
  const replay::PlayerStats& s = player.stats();
  if (bus) {
    std::printf("CAN: frames %zu sent %llu late %llu dropped %llu (try-later retries %llu, send errors %llu, max lateness %.3f ms)\n",
                frames.size(), static_cast<unsigned long long>(s.frames_sent), static_cast<unsigned long long>(s.frames_late),
                static_cast<unsigned long long>(s.frames_dropped), static_cast<unsigned long long>(s.send_try_later),
                static_cast<unsigned long long>(s.send_errors), static_cast<double>(s.max_frame_lateness_us) / 1000.0);
  }
  if (engine) {
    const replay::LaserReplayStats& l = engine->stats();
    std::printf("laser: scans %zu served %llu late %llu dropped %llu not requested %llu (max lateness %.3f ms, bytes dropped %llu)\n",
                log.scans.size(), static_cast<unsigned long long>(l.scans_served), static_cast<unsigned long long>(l.scans_late),
                static_cast<unsigned long long>(l.scans_dropped), static_cast<unsigned long long>(l.scans_not_requested),
                static_cast<double>(l.max_lateness_us) / 1000.0, static_cast<unsigned long long>(pty.bytes_dropped()));
  }
  std::printf("played in %.3f s at speed %.3g\n", static_cast<double>(s.wall_us) * 1e-6, a.speed);
  return s.frames_dropped == 0 ? kExitOk : kExitIo;
}

void add_laser_options(CLI::App& app, PlayArgs& a, bool required) {
  auto* link = app.add_option(required ? "--link" : "--laser-link", a.link, "symlink to create to the pty's slave");
  if (required) link->required();
  app.add_option(required ? "--protocol" : "--laser-protocol", a.protocol, "scip (Hokuyo SCIP 2.0) or sick (LMS2xx)")
      ->check(CLI::IsMember({"scip", "sick"}));
  app.add_option("--speed", a.speed, "playback speed factor")->check(CLI::PositiveNumber);
  app.add_option("--start-delay", a.start_delay_s, "seconds before the first event (time to start a driver)")
      ->check(CLI::NonNegativeNumber);
}

std::function<int()> setup_replay_laser(CLI::App& app) {
  auto a = std::make_shared<PlayArgs>();
  app.add_option("LOG", a->laser_log, "robot log with laser scans")->required();
  add_laser_options(app, *a, true);
  return [a] { return run_play(*a, "replay-laser"); };
}

std::function<int()> setup_replay(CLI::App& app) {
  auto a = std::make_shared<PlayArgs>();
  app.add_option("--can-log", a->can_log, "candump -l log to send (e.g. from replay-can)");
  app.add_option("--can-iface", a->can_iface, "SocketCAN interface to send on")->default_val("vcan0");
  app.add_option("--laser", a->laser_log, "robot log whose scans the laser serves");
  add_laser_options(app, *a, false);
  return [a] {
    if (a->can_log.empty() && a->laser_log.empty()) {
      std::fprintf(stderr, "sdpslam replay: nothing to play (give --can-log and/or --laser)\n");
      return static_cast<int>(kExitUsage);
    }
    if (!a->laser_log.empty() && a->link.empty()) {
      std::fprintf(stderr, "sdpslam replay: --laser needs --laser-link\n");
      return static_cast<int>(kExitUsage);
    }
    return run_play(*a, "replay");
  };
}

}  // namespace

SDPSLAM_REGISTER_COMMAND(replay_can, "replay-can", "encoder CAN frames (candump -l) from a log's odometry or wheel ticks",
                         60, setup_replay_can);
SDPSLAM_REGISTER_COMMAND(replay_laser, "replay-laser", "serve a log's scans as a SCIP 2.0 or SICK laser on a pty", 61,
                         setup_replay_laser);
SDPSLAM_REGISTER_COMMAND(replay, "replay", "play a candump onto SocketCAN and a log's laser on a pty, on one clock", 62,
                         setup_replay);

}  // namespace sdpslam::cli
