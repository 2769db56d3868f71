#include "sdpslam/daemon/daemon.h"

#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <time.h>

#include <algorithm>
#include <cerrno>
#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <utility>

#include "sdpslam/io/atomic_file.h"
#include "sdpslam/io/json_text.h"
#include "sdpslam/io/map_image.h"
#include "sdpslam/io/snapshot_file.h"
#include "sdpslam/slam/slam_outputs.h"

namespace sdpslam::daemon {
namespace {

void sleep_us(std::int64_t us) {
  if (us <= 0) return;
  timespec ts{static_cast<time_t>(us / 1000000), static_cast<long>((us % 1000000) * 1000)};
  nanosleep(&ts, nullptr);
}

const char* health_name(hal::RangeSourceHealth h) {
  switch (h) {
    case hal::RangeSourceHealth::kStarting: return "starting";
    case hal::RangeSourceHealth::kStreaming: return "streaming";
    case hal::RangeSourceHealth::kStalled: return "stalled";
    case hal::RangeSourceHealth::kDisconnected: return "disconnected";
  }
  return "?";
}

// Seconds and milliseconds to the microsecond, coordinates to the millimetre.
double fixed3(double v) { return io::json_fixed(v, 3); }

}  // namespace

Daemon::Daemon(const DaemonConfig& config, const DaemonIo& io, EventLog& log)
    : config_(config), io_(io), log_(log), paired_(*io.encoders, io.bus,
              config.encoders.protocol == drivers::EncoderProtocol::kCanOpen ? config.encoders.canopen.position_timeout_us
                                                                             : config.encoders.odrive.position_timeout_us),
      odom_(paired_, config.drive) {}

bool Daemon::start(std::string* error) {
  // Made, cleaned of an interrupted run's leftovers and proven writable before any
  // device is opened.
  if (!outputs_.begin(config_.output_directory, error)) return false;
  if (config_.input_log && !recorder_.open(config_.output_directory + "/input.clf", error)) return false;
  if (!config_.pose_socket.empty() && !publisher_.open(config_.pose_socket, error)) return false;
  start_us_ = io_.clock->now_us();
  next_output_us_ = start_us_ + config_.output_period_us;
  next_snapshot_us_ = start_us_ + config_.snapshot_interval_us;
  log_.log(Event::kStartup, "mode %s, laser %s on %s, encoders %s, outputs every %.1f s in %s", io_.engine->name(),
           to_string(config_.laser_protocol), config_.laser_device.c_str(),
           drivers::to_string(config_.encoders.protocol), static_cast<double>(config_.output_period_us) * 1e-6,
           config_.output_directory.c_str());
  return true;
}

void Daemon::take_odometry(const hal::OdometryReading& r) {
  if (r.status == hal::OdometryStatus::kValid && r.stamp_us > last_odom_stamp_us_) {
    if (ring_.push(r.stamp_us, r.pose)) ++counters_.odometry_samples;
    last_odom_stamp_us_ = r.stamp_us;
  } else if (r.status == hal::OdometryStatus::kLatching && r.stamp_us > last_odom_stamp_us_) {
    // First pair (or first after an outage): the pose is known at this stamp, and it
    // starts a new segment (motion since the last valid sample is unknown).
    ring_.mark_break();
    if (ring_.push(r.stamp_us, r.pose)) ++counters_.odometry_samples;
    last_odom_stamp_us_ = r.stamp_us;
  }
}

void Daemon::update_odometry() {
  if (!encoders_started_) {
    encoders_started_ = io_.start_encoders == nullptr || io_.start_encoders(io_.start_ctx) == 1;
  }
  // Drain what the bus holds, integrating after every frame: a backlog that built up
  // while a scan was being processed then yields every intermediate pose at its own
  // kernel receive stamp, instead of one jump to the newest pair (which left gaps the
  // interpolation refuses). Bounded so a flooded bus cannot starve the laser.
  hal::OdometryReading r = odom_.latest();
  for (std::uint32_t frame = 0; frame < kMaxFramesPerOdometryUpdate; ++frame) {
    odom_.update();
    r = odom_.latest();
    take_odometry(r);
    if (io_.bus == nullptr || io_.bus->wait_readable(0) <= 0) break;
  }
  if (r.status != seen_odom_) {
    if (r.status == hal::OdometryStatus::kStale) {
      ++counters_.odometry_stale_events;
      ring_.mark_break();
      log_.log(Event::kOdometry, "encoders stale since %.3f s: scans wait, then are skipped; no motion is invented",
               static_cast<double>(r.stamp_us - start_us_) * 1e-6);
    } else if (seen_odom_ == hal::OdometryStatus::kStale || r.status == hal::OdometryStatus::kValid) {
      log_.log(Event::kOdometry, "encoders %s", hal::to_string(r.status));
    }
    seen_odom_ = r.status;
  }
}

void Daemon::enqueue(std::int64_t now_us) {
  ++counters_.scans_received;
  if (queue_.size() >= config_.scan_queue) {
    queue_.pop(pending_scratch_);
    ++counters_.scans_dropped_queue_full;
    log_.log(Event::kScanDropped, "scan queue full (%u): oldest scan dropped (%" PRIu64 " in all)", config_.scan_queue,
             counters_.scans_dropped_queue_full);
  }
  pending_scratch_.scan = scratch_;
  pending_scratch_.read_us = now_us;
  queue_.push(pending_scratch_);
}

void Daemon::place_scans(std::int64_t now_us, bool final_pass) {
  while (!queue_.empty()) {
    PendingScan& p = queue_[0];
    Pose2 pose;
    const OdometryRing::Lookup l = ring_.interpolate(p.scan.stamp_us, config_.max_interpolation_gap_us, &pose);
    if (l == OdometryRing::Lookup::kNotYet) {
      const std::int64_t waited = now_us - p.read_us;
      if (!final_pass && waited < config_.odometry_wait_us) return;
      ++counters_.scans_skipped_no_odometry;
      log_.log(Event::kScanSkipped, "no odometry reached the scan's stamp within %.0f ms (newest %.1f ms older): skipped",
               static_cast<double>(config_.odometry_wait_us) / 1000.0,
               ring_.empty() ? 0.0 : static_cast<double>(p.scan.stamp_us - ring_.newest_stamp_us()) / 1000.0);
      queue_.pop(pending_scratch_);
      continue;
    }
    if (l != OdometryRing::Lookup::kOk) {
      if (l == OdometryRing::Lookup::kTooOld) ++counters_.scans_skipped_too_old;
      else ++counters_.scans_skipped_gap;
      log_.log(Event::kScanSkipped, "scan at %.3f s cannot be placed (%s): skipped",
               static_cast<double>(p.scan.stamp_us - start_us_) * 1e-6, to_string(l));
      queue_.pop(pending_scratch_);
      continue;
    }
    const std::int64_t waited = now_us - p.read_us;
    if (waited > counters_.max_odometry_wait_us) counters_.max_odometry_wait_us = waited;
    OdometrySample slam_odom;
    if (!recorder_.pass(OdometrySample{p.scan.stamp_us, pose}, p.scan, p.read_us, &slam_odom, &slam_scan_)) {
      log_.log(Event::kOutput, "%s (%" PRIu64 " failed lines in all)", recorder_.last_error().c_str(),
               recorder_.stats().write_failures);
    }
    const EngineStep s = io_.engine->process(slam_odom, slam_scan_);
    if (const std::string notice = io_.engine->take_notice(); !notice.empty()) {
      log_.log(Event::kSession, "%s", notice.c_str());
    }
    if (s.placed) ++counters_.scans_placed;
    else ++counters_.scans_held;
    if (s.processed) ++counters_.scans_processed;
    if (publisher_.is_open() && s.placed) {
      PoseRecord rec;
      rec.flags = static_cast<std::uint16_t>((s.processed ? PoseRecord::kFlagProcessed : 0U) |
                                             (std::strcmp(io_.engine->name(), "localize") == 0 ? PoseRecord::kFlagLocalize : 0U));
      rec.map_version = map_version();
      rec.stamp_us = p.scan.stamp_us;
      rec.pose = s.pose;
      const PoseSpread spread = io_.engine->spread();
      rec.var_x = static_cast<float>(spread.var_x);
      rec.cov_xy = static_cast<float>(spread.cov_xy);
      rec.var_y = static_cast<float>(spread.var_y);
      rec.var_heading = static_cast<float>(spread.var_heading);
      publisher_.poll();
      publisher_.publish(rec);
    }
    const std::int64_t done_us = io_.clock->now_us();
    const std::int64_t from_stamp = done_us - p.scan.stamp_us;
    const std::int64_t from_read = done_us - p.read_us;
    stamp_latency_.push_overwrite(static_cast<std::int32_t>(std::min<std::int64_t>(from_stamp, INT32_MAX)));
    read_latency_.push_overwrite(static_cast<std::int32_t>(std::min<std::int64_t>(from_read, INT32_MAX)));
    stamp_latency_max_us_ = std::max(stamp_latency_max_us_, from_stamp);
    read_latency_max_us_ = std::max(read_latency_max_us_, from_read);
    ++latency_count_;
    queue_.pop(pending_scratch_);
    now_us = done_us;
  }
}

void Daemon::watch_faults() {
  const hal::RangeSourceHealth h = io_.laser->health();
  const hal::RangeSourceStats& ls = io_.laser->stats();
  if (ls.disconnect_count > seen_laser_.disconnect_count) {
    log_.log(Event::kLaser, "laser %s disconnected (%" PRIu64 " in all): re-opening", config_.laser_device.c_str(),
             ls.disconnect_count);
  }
  if (ls.restart_count > seen_laser_.restart_count) {
    log_.log(Event::kLaser, "laser restarted (%" PRIu64 " restarts)", ls.restart_count);
  }
  if (ls.stall_count > seen_laser_.stall_count) {
    log_.log(Event::kLaser, "laser stalled: no scan within %.0f ms (%" PRIu64 " stalls)",
             static_cast<double>(config_.urg.stall_timeout_us) / 1000.0, ls.stall_count);
  }
  if (ls.dropped_scan_count > seen_laser_.dropped_scan_count) {
    log_.log(Event::kLaserData, "laser driver rejected %" PRIu64 " scan(s) (checksum %" PRIu64 ", framing %" PRIu64 ")",
             ls.dropped_scan_count - seen_laser_.dropped_scan_count, ls.checksum_error_count, ls.framing_error_count);
  }
  if (h != seen_health_) {
    log_.log(Event::kLaser, "laser %s -> %s", health_name(seen_health_), health_name(h));
    seen_health_ = h;
  }
  seen_laser_ = ls;
  if (io_.bus != nullptr) {
    const hal::CanBusState st = io_.bus->state();
    const hal::CanBusStats& cs = io_.bus->stats();
    if (st != seen_can_state_) {
      log_.log(Event::kCan, "CAN %s %s -> %s", config_.can_interface.c_str(), hal::to_string(seen_can_state_),
               hal::to_string(st));
      seen_can_state_ = st;
    }
    if (cs.reopen_count > seen_can_.reopen_count) {
      log_.log(Event::kCan, "CAN %s back (%u re-opens)", config_.can_interface.c_str(), cs.reopen_count);
    }
    if (cs.errors.bus_off > seen_can_.errors.bus_off) {
      log_.log(Event::kCan, "CAN bus-off reported (%u in all)", cs.errors.bus_off);
    }
    if (cs.rx_overflows > seen_can_.rx_overflows) {
      log_.log(Event::kCanData, "kernel dropped %" PRIu64 " CAN frame(s) (receive queue overflow)",
               cs.rx_overflows - seen_can_.rx_overflows);
    }
    seen_can_ = cs;
  }
}

void Daemon::step() {
  ++counters_.loop_steps;
  update_odometry();
  const std::int64_t wait = queue_.empty() ? config_.loop_slice_us : std::min<std::int64_t>(config_.loop_slice_us, 1000);
  const std::int64_t before = io_.clock->now_us();
  const int r = io_.laser->poll(scratch_, wait);
  std::int64_t now = io_.clock->now_us();
  if (r == 1) {
    enqueue(now);
  } else if (r < 0 && now - before < wait / 2) {
    sleep_us(wait - (now - before));  // disconnected: the driver returned at once
    now = io_.clock->now_us();
  }
  update_odometry();
  publisher_.poll();  // (un)subscriptions, also while no scan comes
  place_scans(now, false);
  watch_faults();
  now = io_.clock->now_us();
  if (now >= next_output_us_) {
    write_outputs();
    next_output_us_ = io_.clock->now_us() + config_.output_period_us;
  }
  if (snapshot_child_ > 0) reap_snapshot(false);
  if (snapshots_on() && now >= next_snapshot_us_) {
    if (counters_.scans_placed != snapshot_at_scans_) write_snapshot(true);
    next_snapshot_us_ = io_.clock->now_us() + config_.snapshot_interval_us;
  }
  if (io_.watchdog != nullptr) io_.watchdog->pat();
}

bool Daemon::snapshots_on() const { return config_.snapshot_interval_us > 0 && io_.engine->has_snapshots(); }

void Daemon::write_snapshot(bool may_fork) {
  if (snapshot_child_ > 0) {
    ++counters_.snapshots_skipped_busy;
    return;
  }
  const std::int64_t t0 = io_.clock->now_us();
  const std::uint64_t scans = counters_.scans_placed;
  if (may_fork && io_.fork_snapshots) {
    // The daemon is one thread: the child is a consistent copy of the whole state. It
    // writes the file and leaves with _exit (no stdio flush, no atexit handler of the
    // parent's runs twice); its error, if any, goes to stderr as its own line.
    std::fflush(nullptr);
    const pid_t pid = ::fork();
    if (pid == 0) {
      std::string error;
      std::uint64_t bytes = 0U;
      const bool ok = io_.engine->save_snapshot(snapshot_path(config_), config_.slam_fingerprint, &bytes, &error);
      if (!ok) dprintf(2, "sdpslamd: snapshot: %s\n", error.c_str());
      ::_exit(ok ? 0 : 1);
    }
    if (pid > 0) {
      snapshot_child_ = static_cast<int>(pid);
      snapshot_child_scans_ = scans;
      snapshot_child_started_us_ = t0;
      return;
    }
    log_.log(Event::kOutput, "snapshot: fork failed (%s), written in the loop", std::strerror(errno));
  }
  std::string error;
  std::uint64_t bytes = 0U;
  const bool ok = io_.engine->save_snapshot(snapshot_path(config_), config_.slam_fingerprint, &bytes, &error);
  snapshot_done(ok, error, scans, t0);
}

void Daemon::reap_snapshot(bool wait) {
  int status = 0;
  const pid_t r = ::waitpid(static_cast<pid_t>(snapshot_child_), &status, wait ? 0 : WNOHANG);
  if (r == 0) return;  // still writing
  const bool ok = r > 0 && WIFEXITED(status) && WEXITSTATUS(status) == 0;
  snapshot_child_ = 0;
  snapshot_done(ok, ok ? std::string() : "the writing process failed (its message is above)", snapshot_child_scans_,
                snapshot_child_started_us_);
}

void Daemon::snapshot_done(bool ok, const std::string& error, std::uint64_t scans, std::int64_t started_us) {
  if (ok) {
    ++counters_.snapshots_written;
    struct stat st{};
    counters_.snapshot_bytes = ::stat(snapshot_path(config_).c_str(), &st) == 0 ? static_cast<std::uint64_t>(st.st_size) : 0U;
    snapshot_at_scans_ = scans;
  } else {
    ++counters_.snapshot_failures;
    log_.log(Event::kOutput, "snapshot not written, the previous one is kept: %s", error.c_str());
  }
  const std::int64_t dt = io_.clock->now_us() - started_us;
  if (dt > counters_.max_snapshot_write_us) counters_.max_snapshot_write_us = dt;
}

std::string snapshot_path(const DaemonConfig& config) { return config.output_directory + "/snapshot.sdps"; }

ResumeOutcome resume_from_snapshot(const DaemonConfig& config, SlamEngine& engine, EventLog& log) {
  if (config.snapshot_interval_us <= 0 || !engine.has_snapshots()) return ResumeOutcome::kFresh;
  const std::string path = snapshot_path(config);
  struct stat st{};
  if (::stat(path.c_str(), &st) != 0) return ResumeOutcome::kFresh;
  std::string error;
  std::uint64_t scans = 0U;
  if (engine.resume_snapshot(path, config.slam_fingerprint, &scans, &error)) {
    log.log(Event::kStartup, "resumed the session of %s: %" PRIu64 " scans mapped before", path.c_str(), scans);
    return ResumeOutcome::kResumed;
  }
  std::string aside;
  std::string move_error;
  if (io::keep_snapshot_aside(path, &aside, &move_error)) {
    log.log(Event::kStartup, "snapshot refused, kept as %s; starting a new map: %s", aside.c_str(), error.c_str());
  } else {
    log.log(Event::kStartup, "snapshot refused (%s) and could not be moved aside (%s); starting a new map",
            error.c_str(), move_error.c_str());
  }
  return ResumeOutcome::kRefused;
}

bool Daemon::run(const volatile std::sig_atomic_t* stop, volatile std::sig_atomic_t* localize) {
  while (*stop == 0) {
    if (localize != nullptr && *localize != 0) {
      *localize = 0;
      std::string error;
      (void)switch_to_localization(&error);  // logged either way
    }
    step();
  }
  log_.log(Event::kShutdown, "signal received: finishing");
  return finish();
}

void Daemon::adopt_engine(std::unique_ptr<SlamEngine> engine) {
  owned_engine_ = std::move(engine);
  io_.engine = owned_engine_.get();
}

bool Daemon::switch_to_localization(std::string* error) {
  auto refuse = [&](const std::string& why) {
    *error = why;
    log_.log(Event::kOutput, "cannot switch to localization, mapping goes on: %s", why.c_str());
    return false;
  };
  if (config_.mode == SlamMode::kLocalize) return refuse("already localizing");
  update_odometry();
  place_scans(io_.clock->now_us(), true);
  // The map as a periodic output has it (the engine is not finished: should the switch
  // fail, mapping goes on as before).
  const std::vector<io::StampedPose> trajectory = io_.engine->trajectory();
  io::OccupancyImage image;
  io_.engine->map_image(&image);
  if (trajectory.empty() || image.width == 0U) return refuse("nothing mapped yet");
  written_at_scans_ = ~std::uint64_t{0};
  if (!write_outputs()) return refuse("the outputs could not be written: " + last_output_error_);
  // The session's map and path, kept beside the output set (which the localization's
  // outputs replace).
  const std::string session = config_.output_directory + "/session";
  if (::mkdir(session.c_str(), 0755) != 0 && errno != EEXIST) {
    return refuse(session + ": cannot be created: " + std::strerror(errno));
  }
  std::string why;
  if (!io::write_map_pgm_yaml(session + "/map", image, slam::slam_map_thresholds(), &why) ||
      !slam::write_trajectories(session, trajectory, &why)) {
    return refuse(why);
  }
  DaemonConfig next = config_;
  next.mode = SlamMode::kLocalize;
  next.localize_map = session + "/map.yaml";
  next.localize_have_start = true;
  next.localize_start = trajectory.back().pose;
  std::unique_ptr<SlamEngine> engine = make_engine(next, &why);
  if (!engine) return refuse(why);
  const char* from = io_.engine->name();
  log_.log(Event::kStartup, "mode %s -> localize on %s from (%.3f, %.3f, %.3f) after %" PRIu64 " scans placed", from,
           next.localize_map.c_str(), next.localize_start.x_m, next.localize_start.y_m,
           next.localize_start.heading_rad, counters_.scans_placed);
  adopt_engine(std::move(engine));  // the mapping engine is freed here if the daemon owned it
  config_ = next;
  written_at_scans_ = ~std::uint64_t{0};
  return true;
}

bool Daemon::finish() {
  update_odometry();
  place_scans(io_.clock->now_us(), true);
  // The state a restart continues from: before finish(), which completes pending work at
  // once rather than spread over scans as a run that goes on does it.
  if (snapshot_child_ > 0) reap_snapshot(true);
  if (snapshots_on() && counters_.scans_placed != snapshot_at_scans_) write_snapshot(false);
  io_.engine->finish();
  written_at_scans_ = ~std::uint64_t{0};  // finishing may move the path: always delivered
  return write_outputs();
}

bool Daemon::write_outputs() {
  const std::int64_t t0 = io_.clock->now_us();
  std::string error;
  bool ok = true;
  // The set is rendered and written only when a scan was placed since the last one
  // delivered: an idle robot does not rewrite (and fsync) the same files every period.
  const bool changed = counters_.scans_placed != written_at_scans_;
  if (changed) {
    const std::vector<io::StampedPose> trajectory = io_.engine->trajectory();
    if (config_.write_map) {
      io::OccupancyImage image;
      io_.engine->map_image(&image);
      ok = slam::write_trajectory_and_map(outputs_.staging_dir(), trajectory, image, &error);
    } else {
      ok = slam::write_trajectories(outputs_.staging_dir(), trajectory, &error);
    }
    ok = ok && outputs_.commit(&error);
  } else {
    ++counters_.output_writes_unchanged;
  }
  const std::int64_t dt = io_.clock->now_us() - t0;
  if (dt > counters_.max_output_write_us) counters_.max_output_write_us = dt;
  if (changed && ok) {
    ++counters_.output_writes;
    written_at_scans_ = counters_.scans_placed;
  } else if (changed) {
    ++counters_.output_failures;
    last_output_error_ = error;
    log_.log(Event::kOutput, "write failed, previous files kept: %s", error.c_str());
  }
  // The heartbeat is rewritten every period and replaced by the next one: atomic (a
  // reader sees one whole file), not flushed to storage each time, so an idle daemon
  // makes no fsync at all.
  std::string status_error;
  if (!io::write_file_atomic(config_.output_directory + "/status.json", status_json(), &status_error,
                             io::Sync::kAtomicOnly)) {
    ++counters_.output_failures;
    last_output_error_ = status_error;
    log_.log(Event::kOutput, "write failed, previous file kept: %s", status_error.c_str());
    ok = false;
  }
  return ok;
}

LatencyFigures Daemon::figures(const RingBuffer<std::int32_t, kLatencyWindow>& w, std::int64_t max_us,
                               std::uint64_t count) {
  LatencyFigures f;
  f.count = count;
  if (w.empty()) return f;
  static std::int32_t sorted[kLatencyWindow];  // single-threaded program
  const std::size_t n = w.size();
  for (std::size_t i = 0; i < n; ++i) sorted[i] = w[i];
  std::sort(sorted, sorted + n);
  auto at = [&](double q) {
    const auto idx = static_cast<std::size_t>(q * static_cast<double>(n - 1U) + 0.5);
    return static_cast<double>(sorted[std::min(idx, n - 1U)]) / 1000.0;
  };
  f.p50_ms = at(0.5);
  f.p99_ms = at(0.99);
  f.max_ms = static_cast<double>(max_us) / 1000.0;
  return f;
}

std::string Daemon::status_json() const {
  const std::int64_t now = io_.clock->now_us();
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  const double user_s = static_cast<double>(ru.ru_utime.tv_sec) + static_cast<double>(ru.ru_utime.tv_usec) * 1e-6;
  const double sys_s = static_cast<double>(ru.ru_stime.tv_sec) + static_cast<double>(ru.ru_stime.tv_usec) * 1e-6;
  const double up_s = static_cast<double>(now - start_us_) * 1e-6;
  auto lat = [](const LatencyFigures& f) {
    return io::Json{{"count", f.count}, {"p50", fixed3(f.p50_ms)}, {"p99", fixed3(f.p99_ms)}, {"max", fixed3(f.max_ms)}};
  };
  const DaemonCounters& c = counters_;
  const hal::RangeSourceStats& ls = io_.laser->stats();
  const hal::OdometryReading od = odom_.latest();
  io::Json js;
  js["program"] = "sdpslamd";
  js["mode"] = io_.engine->name();
  js["uptime_s"] = fixed3(up_s);
  js["health"] = {{"laser", health_name(io_.laser->health())},
                  {"can", io_.bus != nullptr ? hal::to_string(io_.bus->state()) : "none"},
                  {"odometry", hal::to_string(od.status)}};
  js["scans"] = {{"received", c.scans_received},
                 {"placed", c.scans_placed},
                 {"processed", c.scans_processed},
                 {"held", c.scans_held},
                 {"skipped_no_odometry", c.scans_skipped_no_odometry},
                 {"skipped_too_old", c.scans_skipped_too_old},
                 {"skipped_gap", c.scans_skipped_gap},
                 {"dropped_queue_full", c.scans_dropped_queue_full},
                 {"dropped_total", c.scans_dropped()},
                 {"queued", queue_.size()}};
  js["latency_ms"] = {{"from_scan_stamp", lat(latency_from_stamp())},
                      {"from_driver_read", lat(latency_from_read())},
                      {"max_odometry_wait", fixed3(static_cast<double>(c.max_odometry_wait_us) / 1000.0)}};
  js["odometry"] = {{"samples", c.odometry_samples},
                    {"stale_events", c.odometry_stale_events},
                    {"wheel_pairs", paired_.pairs_published()},
                    {"drain_stale_overrides", paired_.drain_stale_overrides()},
                    {"relatches", odom_.relatch_count()},
                    {"ring_breaks", ring_.break_count()},
                    {"x_m", fixed3(od.pose.x_m)},
                    {"y_m", fixed3(od.pose.y_m)},
                    {"heading_rad", fixed3(od.pose.heading_rad)}};
  io::Json laser = {{"scans", ls.scan_count},
                    {"rejected", ls.dropped_scan_count},
                    {"checksum_errors", ls.checksum_error_count},
                    {"framing_errors", ls.framing_error_count},
                    {"timeouts", ls.timeout_count},
                    {"stalls", ls.stall_count},
                    {"disconnects", ls.disconnect_count},
                    {"restarts", ls.restart_count}};
  if (io_.laser_stream != nullptr) {
    const hal::ByteStreamStats& bs = io_.laser_stream->stats();
    laser["opens"] = bs.open_count;
    laser["hangups"] = bs.hangup_count;
  }
  js["laser"] = std::move(laser);
  if (io_.bus != nullptr) {
    const hal::CanBusStats& cs = io_.bus->stats();
    js["can"] = {{"rx_frames", cs.rx_frames},
                 {"tx_frames", cs.tx_frames},
                 {"rx_overflows", cs.rx_overflows},
                 {"error_frames", cs.error_frames},
                 {"bus_off", cs.errors.bus_off},
                 {"down_count", cs.down_count},
                 {"reopen_count", cs.reopen_count},
                 {"tx_errors", cs.tx_errors},
                 {"tx_while_down", cs.tx_while_down}};
  }
  const InputRecorderStats& rs = recorder_.stats();
  js["input_log"] = {{"enabled", recorder_.is_open()},
                     {"lines", rs.lines_written},
                     {"bytes", rs.bytes_written},
                     {"write_failures", rs.write_failures},
                     {"roundtrip_changed", rs.changed_count},
                     {"roundtrip_failures", rs.roundtrip_failures}};
  const PosePublisherStats& ps = publisher_.stats();
  js["pose_socket"] = {{"enabled", publisher_.is_open()},
                       {"subscribers", publisher_.subscribers()},
                       {"records", ps.records},
                       {"datagrams_sent", ps.datagrams_sent},
                       {"datagrams_dropped", ps.datagrams_dropped},
                       {"subscribes", ps.subscribes},
                       {"subscribers_refused", ps.subscribers_refused},
                       {"subscribers_lost", ps.subscribers_lost},
                       {"map_version", map_version()}};
  js["engine"] = io_.engine->status_json();
  js["outputs"] = {{"writes", c.output_writes},
                   {"failures", c.output_failures},
                   {"unchanged", c.output_writes_unchanged},
                   {"max_write_ms", fixed3(static_cast<double>(c.max_output_write_us) / 1000.0)}};
  js["snapshots"] = {{"enabled", snapshots_on()},
                     {"written", c.snapshots_written},
                     {"failures", c.snapshot_failures},
                     {"file_bytes", c.snapshot_bytes},
                     {"skipped_busy", c.snapshots_skipped_busy},
                     {"max_write_ms", fixed3(static_cast<double>(c.max_snapshot_write_us) / 1000.0)}};
  js["events"] = {{"logged", log_.printed()}, {"suppressed", log_.suppressed()}};
  js["cpu"] = {{"user_s", fixed3(user_s)},
               {"system_s", fixed3(sys_s)},
               {"percent", fixed3(up_s > 0.0 ? 100.0 * (user_s + sys_s) / up_s : 0.0)}};
  return io::json_text(js);
}

}  // namespace sdpslam::daemon
