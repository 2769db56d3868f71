// sdpslamd: the onboard SLAM program (see firmware-host/README.md and sdpslamd.ini).
//
//   sdpslamd --config FILE [--out DIR] [--can-candump LOG [--can-candump-start-us T]
//            [--can-candump-speed S]] [--check-config]
//   sdpslamd --help | --version     (on stdout, exit 0)
//
// Exit codes (as the sdpslam command): 0 stopped by SIGINT/SIGTERM with final outputs
// written, 1 internal failure, 2 bad command line, 3 bad configuration or input,
// 4 an output could not be written (output directory at start, final outputs at exit).
#include <signal.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <memory>
#include <new>
#include <string>

#include "sdpslam/core/version.h"
#include "sdpslam/daemon/candump_replay_bus.h"
#include "sdpslam/daemon/daemon.h"
#include "sdpslam/drivers/can_wheel_encoders.h"
#include "sdpslam/drivers/linux_clock.h"
#include "sdpslam/drivers/serial_port.h"
#include "sdpslam/drivers/sick_lms2xx_laser.h"
#include "sdpslam/drivers/socketcan_bus.h"
#include "sdpslam/drivers/systemd_notifier.h"
#include "sdpslam/drivers/urg_scip2_laser.h"

namespace {

volatile std::sig_atomic_t g_stop = 0;
volatile std::sig_atomic_t g_localize = 0;
void on_signal(int) { g_stop = 1; }
void on_localize_signal(int) { g_localize = 1; }

enum ExitCode : int { kExitOk = 0, kExitInternal = 1, kExitUsage = 2, kExitBadInput = 3, kExitIo = 4 };

// Help asked for goes to stdout (exit 0); after a usage error, to stderr (exit 2).
int usage(const char* why) {
  std::FILE* out = why != nullptr ? stderr : stdout;
  if (why != nullptr) std::fprintf(stderr, "sdpslamd: %s\n", why);
  std::fprintf(out,
               "usage: sdpslamd --config FILE [--out DIR] [--check-config]\n"
               "                [--can-candump LOG [--can-candump-start-us T] [--can-candump-speed S]]\n"
               "  --config FILE           INI configuration (every key: sdpslamd.ini)\n"
               "  --out DIR               output directory (overrides [output] directory)\n"
               "  --check-config          load and validate the configuration, then exit\n"
               "  --can-candump LOG       replay a candump -l log as the CAN bus instead of SocketCAN\n"
               "  --can-candump-start-us  CLOCK_MONOTONIC time (us) the log's first frame is due\n"
               "  --can-candump-speed     replay speed factor (default 1)\n"
               "  --version               print the version and exit\n"
               "  --help                  print this help and exit\n");
  return why != nullptr ? kExitUsage : kExitOk;
}

int start_can_encoders(void* ctx) { return static_cast<sdpslam::drivers::CanWheelEncoders*>(ctx)->start(); }

int run_daemon(int argc, char** argv);

}  // namespace

// No exception leaves main: out of memory (the state is sized and checked against
// [daemon] memory_budget_mib before any work, so this is the rest of the process) and any
// other failure become a message and exit 1, which systemd's Restart=on-failure retries.
int main(int argc, char** argv) {
  try {
    return run_daemon(argc, argv);
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "sdpslamd: out of memory\n");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sdpslamd: internal error: %s\n", e.what());
  }
  return kExitInternal;
}

namespace {

int run_daemon(int argc, char** argv) {
  using namespace sdpslam;
  std::string config_path;
  std::string out_dir;
  std::string candump;
  daemon::CandumpReplayOptions replay;
  bool check_only = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&](const char* name) -> const char* {
      if (i + 1 >= argc) return nullptr;
      (void)name;
      return argv[++i];
    };
    const char* v = nullptr;
    if (a == "--config") {
      if ((v = value("--config")) == nullptr) return usage("--config needs a file");
      config_path = v;
    } else if (a == "--out") {
      if ((v = value("--out")) == nullptr) return usage("--out needs a directory");
      out_dir = v;
    } else if (a == "--can-candump") {
      if ((v = value("--can-candump")) == nullptr) return usage("--can-candump needs a file");
      candump = v;
    } else if (a == "--can-candump-start-us") {
      if ((v = value(a.c_str())) == nullptr) return usage("--can-candump-start-us needs a value");
      char* end = nullptr;
      replay.start_us = std::strtoll(v, &end, 10);
      if (*end != '\0' || replay.start_us <= 0) return usage("--can-candump-start-us: not a positive integer");
    } else if (a == "--can-candump-speed") {
      if ((v = value(a.c_str())) == nullptr) return usage("--can-candump-speed needs a value");
      char* end = nullptr;
      replay.speed = std::strtod(v, &end);
      if (*end != '\0' || !(replay.speed > 0.0)) return usage("--can-candump-speed: not a positive number");
    } else if (a == "--check-config") {
      check_only = true;
    } else if (a == "--help" || a == "-h") {
      return usage(nullptr);
    } else if (a == "--version") {
      std::printf("sdpslamd %s\n", version_string());
      return kExitOk;
    } else {
      return usage(("unknown argument " + a).c_str());
    }
  }
  if (config_path.empty()) return usage("--config is required");

  daemon::DaemonConfig config;
  std::string error;
  if (!daemon::load_daemon_config(config_path, &config, &error)) {
    std::fprintf(stderr, "sdpslamd: %s\n", error.c_str());
    return kExitBadInput;
  }
  for (const std::string& w : config.warnings) std::fprintf(stderr, "sdpslamd: warning: %s\n", w.c_str());
  if (!out_dir.empty()) config.output_directory = out_dir;
  if (check_only) {
    // The same initialisation as a start (the state allocated and every part set up), so
    // that what is approved here starts.
    if (!daemon::make_engine(config, &error)) {
      std::fprintf(stderr, "sdpslamd: %s: %s\n", config_path.c_str(), error.c_str());
      return kExitBadInput;
    }
    std::printf("%s: ok (mode %s, %u particles, %.1f MiB SLAM state of %u MiB allowed, laser %s on %s, encoders %s on "
                "%s, outputs in %s)\n",
                config_path.c_str(), daemon::to_string(config.mode), config.slam.filter.particle_count,
                static_cast<double>(daemon::engine_arena_bytes(config)) / (1024.0 * 1024.0), config.memory_budget_mib,
                daemon::to_string(config.laser_protocol), config.laser_device.c_str(),
                drivers::to_string(config.encoders.protocol), config.can_interface.c_str(),
                config.output_directory.c_str());
    // The options in effect (profile and file applied), as INI: nothing hidden.
    std::printf("; the configuration in effect\n%s", daemon::effective_config_ini(config).c_str());
    return kExitOk;
  }

  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;  // no SA_RESTART: a blocking wait returns at once
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  // SIGUSR1: from mapping to localization on the map just built (Daemon::switch_to_localization).
  struct sigaction su = sa;
  su.sa_handler = on_localize_signal;
  sigaction(SIGUSR1, &su, nullptr);
  signal(SIGPIPE, SIG_IGN);

  drivers::LinuxMonotonicClock clock;
  daemon::EventLog log(clock, config.log_interval_us);
  // Under a Type=notify unit: READY=1 once the loop can start, WATCHDOG=1 from the loop.
  drivers::SystemdNotifier notifier(drivers::NotifyEnvironment::from_process(), clock, static_cast<long>(::getpid()));
  if (!notifier.setup_error().empty()) {
    std::fprintf(stderr, "sdpslamd: warning: service notification: %s\n", notifier.setup_error().c_str());
  }
  std::unique_ptr<daemon::SlamEngine> engine = daemon::make_engine(config, &error);
  if (!engine) {
    std::fprintf(stderr, "sdpslamd: %s: %s\n", config_path.c_str(), error.c_str());
    return kExitBadInput;
  }
  // The session a snapshot holds goes on; a refused one is kept aside and the map starts
  // anew, on an engine that holds nothing of it.
  if (daemon::resume_from_snapshot(config, *engine, log) == daemon::ResumeOutcome::kRefused) {
    engine = daemon::make_engine(config, &error);
    if (!engine) {
      std::fprintf(stderr, "sdpslamd: %s: %s\n", config_path.c_str(), error.c_str());
      return kExitInternal;
    }
  }

  // CAN: SocketCAN with the protocol's receive filters, or a candump replay.
  std::unique_ptr<hal::CanBus> bus;
  if (!candump.empty()) {
    auto rb = std::make_unique<daemon::CandumpReplayBus>(clock, replay);
    if (!rb->open(candump, &error)) {
      std::fprintf(stderr, "sdpslamd: %s\n", error.c_str());
      return kExitBadInput;
    }
    bus = std::move(rb);
  } else {
    drivers::SocketCanOptions so;
    std::snprintf(so.interface_name, sizeof so.interface_name, "%s", config.can_interface.c_str());
    so.reopen_interval_us = config.can_reopen_interval_us;
    if (!drivers::add_receive_filters(config.encoders, so)) {
      std::fprintf(stderr, "sdpslamd: CAN receive filters do not fit\n");
      return kExitInternal;
    }
    auto sb = std::make_unique<drivers::SocketCanBus>(so, clock);
    if (sb->state() == hal::CanBusState::kDown) {
      char cause[160];
      log.log(daemon::Event::kCan, "CAN %s cannot be opened now: %s; retrying every %.1f s",
              config.can_interface.c_str(), sb->describe_last_failure(cause, sizeof cause),
              static_cast<double>(config.can_reopen_interval_us) * 1e-6);
    }
    bus = std::move(sb);
  }
  // One frame per update: the loop drains the bus frame by frame so that every encoder
  // sample enters the odometry ring with its own receive stamp (Daemon::update_odometry).
  drivers::CanWheelEncoderConfig encoder_config = config.encoders;
  encoder_config.canopen.max_frames_per_update = 1;
  encoder_config.odrive.max_frames_per_update = 1;
  drivers::CanWheelEncoders encoders(*bus, clock, encoder_config);

  // Laser on its serial device; a device that is absent now is re-opened when it appears.
  drivers::SerialOptions po;
  po.path = config.laser_device.c_str();
  po.baud = config.laser_protocol == daemon::LaserProtocol::kSick ? 9600U : config.laser_baud;
  po.reopen_interval_us = config.laser_reopen_interval_us;
  po.reopen = true;
  drivers::SerialPort port(po, clock);
  if (!port.open()) {
    log.log(daemon::Event::kLaser, "%s cannot be opened now (%s: %s): retrying every %.1f s",
            config.laser_device.c_str(), port.last_error_step(), std::strerror(port.last_errno()),
            static_cast<double>(config.laser_reopen_interval_us) * 1e-6);
  }
  std::unique_ptr<hal::RangeScanSource> laser;
  if (config.laser_protocol == daemon::LaserProtocol::kScip) {
    drivers::UrgOptions uo = config.urg;
    uo.laser_in_base = config.laser_in_base;
    laser = std::make_unique<drivers::UrgScip2Laser>(port, clock, uo);
  } else {
    drivers::SickOptions so = config.sick;
    so.laser_in_base = config.laser_in_base;
    laser = std::make_unique<drivers::SickLms2xxLaser>(port, clock, so);
  }

  daemon::DaemonIo io;
  io.clock = &clock;
  io.bus = bus.get();
  io.encoders = &encoders;
  io.start_encoders = start_can_encoders;
  io.start_ctx = &encoders;
  io.laser = laser.get();
  io.laser_stream = &port;
  io.engine = engine.get();
  io.watchdog = &notifier;
  io.fork_snapshots = true;  // the loop does not pause while the state is written
  auto d = std::make_unique<daemon::Daemon>(config, io, log);
  d->adopt_engine(std::move(engine));
  if (!d->start(&error)) {
    std::fprintf(stderr, "sdpslamd: %s\n", error.c_str());
    return kExitIo;
  }
  if (notifier.enabled()) {
    char status[200];
    std::snprintf(status, sizeof status, "running: %s, outputs in %s%s", daemon::to_string(config.mode),
                  config.output_directory.c_str(),
                  notifier.watchdog_timeout_us() > 0 ? ", watchdog on" : "");
    if (!notifier.ready(status)) {
      log.log(daemon::Event::kStartup, "the service manager was not told that sdpslamd is ready: %s",
              notifier.last_error().c_str());
    } else if (notifier.watchdog_timeout_us() > 0) {
      log.log(daemon::Event::kStartup, "service watchdog: the loop reports at least every %.1f s",
              static_cast<double>(notifier.watchdog_timeout_us()) * 0.5e-6);
    }
  }
  const bool ok = d->run(&g_stop, &g_localize);
  notifier.stopping();
  if (notifier.failures() > 0U) {
    std::fprintf(stderr, "sdpslamd: %llu service notifications not sent (last: %s)\n",
                 static_cast<unsigned long long>(notifier.failures()), notifier.last_error().c_str());
  }
  const daemon::DaemonCounters& c = d->counters();
  const daemon::LatencyFigures lf = d->latency_from_stamp();
  std::fprintf(stderr,
               "sdpslamd: stopped: %llu scans received, %llu placed, %llu processed, %llu dropped; latency p50 %.1f "
               "p99 %.1f max %.1f ms; outputs %s in %s\n",
               static_cast<unsigned long long>(c.scans_received), static_cast<unsigned long long>(c.scans_placed),
               static_cast<unsigned long long>(c.scans_processed), static_cast<unsigned long long>(c.scans_dropped()),
               lf.p50_ms, lf.p99_ms, lf.max_ms, ok ? "written" : "NOT written", config.output_directory.c_str());
  return ok ? kExitOk : kExitIo;
}

}  // namespace
