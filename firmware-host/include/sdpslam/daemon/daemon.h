#pragma once
// The onboard loop of sdpslamd: one thread, one monotonic clock.
//
// Each step():
//   1. drains the CAN bus frame by frame through the wheel encoders, paired
//      (PairedWheelEncoders), and the diff-drive odometry
//      (drivers::EncoderOdometrySource) and appends every new valid pose to the
//      OdometryRing; a stale encoder marks a break (no motion is ever invented across it);
//   2. waits for the laser at most loop_slice_us (less while a scan waits for odometry);
//      a finished scan enters a small queue (full: the oldest is dropped and counted);
//   3. places queued scans in order: the odometry pose at the scan's stamp is
//      interpolated (OdometryRing). A scan newer than the newest odometry waits up to
//      odometry_wait_us for the encoders to catch up, then is skipped and counted; one
//      older than the ring, or whose bracketing samples straddle a break or a gap longer
//      than max_interpolation_gap_us, is skipped and counted;
//   4. feeds placed scans to the SlamEngine (as their CARMEN line reads back, and appends
//      that line to <output>/input.clf when [output] input_log is on: InputRecorder),
//      sends the pose to the subscribers of [output] pose_socket (PosePublisher), and
//      records the latency: pose available minus
//      the scan's stamp (for SCIP the sensor's stamp mapped onto our clock, ≈ its last
//      byte's arrival on an idle line) and minus the moment the driver returned it;
//   5. watches the sensors' counters and states and logs every change (EventLog);
//   6. every output_period_us writes trajectory.txt/.tum, map.pgm/.yaml/.png and status.json
//      into the output directory, each atomically (a failed write keeps the previous file
//      and is logged and counted; the next period tries again).
//   7. in mode sdp, every [output] snapshot_interval_s writes the whole SLAM state to
//      <output>/snapshot.sdps (atomically; only when a scan was placed since the last;
//      by a forked child with DaemonIo::fork_snapshots, one at a time), so that a
//      restart continues the same map (resume_from_snapshot());
//   8. pats the watchdog (DaemonIo::watchdog), when there is one.
// run() steps until *stop becomes non-zero (SIGINT/SIGTERM), places what can still be
// placed, writes a last snapshot (mode sdp) and the final outputs. When *localize becomes non-zero (SIGUSR1) it
// switches from mapping to localization on the map just built
// (switch_to_localization()).
//
// Faults are handled by the drivers (serial re-open + sensor restart, SocketCAN re-open);
// the loop never exits on a sensor fault. Memory: the object holds the scan queue and the
// latency windows (~100 KiB): allocate it once at start-up.
#include <csignal>
#include <cstdint>
#include <memory>
#include <string>

#include "sdpslam/core/ring_buffer.h"
#include "sdpslam/daemon/daemon_config.h"
#include "sdpslam/daemon/event_log.h"
#include "sdpslam/daemon/input_recorder.h"
#include "sdpslam/daemon/odometry_ring.h"
#include "sdpslam/daemon/paired_wheel_encoders.h"
#include "sdpslam/daemon/pose_publisher.h"
#include "sdpslam/daemon/slam_engine.h"
#include "sdpslam/drivers/diff_drive_odometry.h"
#include "sdpslam/hal/byte_stream.h"
#include "sdpslam/hal/can_bus.h"
#include "sdpslam/hal/clock.h"
#include "sdpslam/hal/range_scan_source.h"
#include "sdpslam/hal/watchdog.h"
#include "sdpslam/hal/wheel_encoder_source.h"
#include "sdpslam/io/output_set.h"

namespace sdpslam::daemon {

struct DaemonCounters {
  std::uint64_t loop_steps = 0U;
  std::uint64_t scans_received = 0U;
  std::uint64_t scans_placed = 0U;           // given an odometry pose and fed to the engine
  std::uint64_t scans_processed = 0U;        // of those, the engine updated its particles
  std::uint64_t scans_held = 0U;             // fed but not placed: a resumed session looking for the robot
  std::uint64_t scans_skipped_no_odometry = 0U;  // odometry did not catch up in time
  std::uint64_t scans_skipped_too_old = 0U;  // older than the odometry ring
  std::uint64_t scans_skipped_gap = 0U;      // across a stale-encoder break or a long gap
  std::uint64_t scans_dropped_queue_full = 0U;
  std::uint64_t odometry_samples = 0U;
  std::uint64_t odometry_stale_events = 0U;
  std::uint64_t output_writes = 0U;
  std::uint64_t output_failures = 0U;
  std::uint64_t output_writes_unchanged = 0U;  // periods with no new scan: nothing rewritten
  std::int64_t max_output_write_us = 0;
  std::int64_t max_odometry_wait_us = 0;     // longest a placed scan waited for odometry
  std::uint64_t snapshots_written = 0U;
  std::uint64_t snapshot_failures = 0U;
  std::uint64_t snapshot_bytes = 0U;         // the last one's file size
  std::int64_t max_snapshot_write_us = 0;    // the loop's pause (in the loop) or the child's run (forked)
  std::uint64_t snapshots_skipped_busy = 0U;  // an interval ended while the previous one was still being written
  std::uint64_t scans_dropped() const {
    return scans_skipped_no_odometry + scans_skipped_too_old + scans_skipped_gap + scans_dropped_queue_full;
  }
};

// Latency percentiles over the last kWindow placed scans (exact, by sorting a copy).
struct LatencyFigures {
  std::uint64_t count = 0U;  // placed scans measured in all
  double p50_ms = 0.0, p99_ms = 0.0, max_ms = 0.0;  // p50/p99 of the window, max of all
};

struct DaemonIo {
  const hal::MonotonicClock* clock = nullptr;
  hal::CanBus* bus = nullptr;                    // state/stats watched; may be null
  hal::WheelEncoderSource* encoders = nullptr;
  // Called until it returns 1 (CANopen NMT start); may be empty.
  int (*start_encoders)(void* ctx) = nullptr;
  void* start_ctx = nullptr;
  hal::RangeScanSource* laser = nullptr;
  const hal::ByteStream* laser_stream = nullptr;  // stats only; may be null
  SlamEngine* engine = nullptr;
  // Patted at the end of every step(), so that a supervisor restarts a loop that hangs
  // (hal/watchdog.h; on the robot systemd's WatchdogSec=); may be null.
  hal::Watchdog* watchdog = nullptr;
  // Periodic snapshots are written by a forked copy of the process, so that the loop
  // goes on while the state is compressed and written (its memory is shared copy-on-write:
  // only the pages the loop changes meanwhile are duplicated); false writes them in the
  // loop itself, which then pauses for as long. The last snapshot, at a stop, is always
  // written in the loop.
  bool fork_snapshots = false;
};

// Where the daemon keeps its snapshot: <output directory>/snapshot.sdps.
std::string snapshot_path(const DaemonConfig& config);

// At start-up: continues the session a snapshot holds, if there is one and the engine
// has snapshots (mode sdp) and they are on ([output] snapshot_interval_s > 0).
enum class ResumeOutcome : std::uint8_t {
  kFresh,    // nothing to resume: no snapshot, or snapshots off or not in this mode
  kResumed,  // the engine continues the snapshot's session
  kRefused,  // the snapshot is another version's, another configuration's, or damaged:
             // it was moved aside (snapshot.sdps.refused) and the engine must be made
             // anew (it may hold part of the refused state)
};
// Logs what happened (Event::kStartup) with the reason of a refusal.
ResumeOutcome resume_from_snapshot(const DaemonConfig& config, SlamEngine& engine, EventLog& log);

class Daemon {
 public:
  static constexpr std::size_t kLatencyWindow = 4096U;
  // Frames read (one encoder update each) per odometry update at the most.
  static constexpr std::uint32_t kMaxFramesPerOdometryUpdate = 512U;

  Daemon(const DaemonConfig& config, const DaemonIo& io, EventLog& log);
  // Creates the output directory (and the input recording if enabled). False (with
  // *error) iff that fails.
  bool start(std::string* error);
  void step();
  // Steps until *stop != 0, then finishes (see header). Returns true iff the final
  // outputs were written. Whenever *localize != 0 (may be null), clears it and calls
  // switch_to_localization().
  bool run(const volatile std::sig_atomic_t* stop, volatile std::sig_atomic_t* localize = nullptr);
  // The daemon owns the engine from now on (DaemonIo::engine then points to it), so that
  // a switch can free it.
  void adopt_engine(std::unique_ptr<SlamEngine> engine);
  // Lifelong use: ends mapping and localizes on what it mapped. The scans that can be
  // placed are, the outputs are written, the map and trajectory are
  // kept in <output>/session/ (map.pgm/.yaml, trajectory.txt/.tum: the next outputs are
  // the localization's), and a localize engine ([localize] options) starts on
  // session/map.yaml at the last pose of the mapped trajectory; the mapping engine is
  // freed once it runs. False (logged, with *error; mapping goes on) when the engine
  // already localizes, nothing is mapped yet, or the map cannot be written or loaded.
  bool switch_to_localization(std::string* error);
  // Places every queued scan that can be placed now (no waiting), ends the engine's input
  // (SlamEngine::finish: the last outputs are the offline runner's), then writes the
  // outputs. Call once, at the end.
  bool finish();
  // Writes trajectory, map (if enabled) and status now. True iff all writes succeeded.
  bool write_outputs();

  const DaemonCounters& counters() const { return counters_; }
  LatencyFigures latency_from_stamp() const { return figures(stamp_latency_, stamp_latency_max_us_, latency_count_); }
  LatencyFigures latency_from_read() const { return figures(read_latency_, read_latency_max_us_, latency_count_); }
  const OdometryRing& odometry_ring() const { return ring_; }
  const InputRecorder& input_recorder() const { return recorder_; }
  const PosePublisher& pose_publisher() const { return publisher_; }
  // Map deliveries so far (PoseRecord::map_version): every delivered set holds the map
  // when [output] write_map is on.
  std::uint32_t map_version() const {
    return config_.write_map ? static_cast<std::uint32_t>(counters_.output_writes) : 0U;
  }
  const hal::OdometryReading odometry() const { return odom_.latest(); }
  std::string status_json() const;
  std::size_t queued_scans() const { return queue_.size(); }

 private:
  struct PendingScan {
    RangeScan scan;
    std::int64_t read_us = 0;  // when the driver handed it out
  };
  void update_odometry();
  void take_odometry(const hal::OdometryReading& r);
  void enqueue(std::int64_t now_us);
  void place_scans(std::int64_t now_us, bool final_pass);
  void watch_faults();
  bool snapshots_on() const;
  // In the loop, or by a forked child (`may_fork` and DaemonIo::fork_snapshots).
  void write_snapshot(bool may_fork);
  // Collects a finished child's outcome; with `wait`, waits for it.
  void reap_snapshot(bool wait);
  void snapshot_done(bool ok, const std::string& error, std::uint64_t scans, std::int64_t started_us);
  static LatencyFigures figures(const RingBuffer<std::int32_t, kLatencyWindow>& w, std::int64_t max_us,
                                std::uint64_t count);

  DaemonConfig config_;
  DaemonIo io_;
  std::unique_ptr<SlamEngine> owned_engine_;  // adopt_engine(), switch_to_localization()
  EventLog& log_;
  PairedWheelEncoders paired_;  // odometry steps on complete wheel pairs only (see its header)
  drivers::EncoderOdometrySource odom_;
  OdometryRing ring_;
  RingBuffer<PendingScan, DaemonConfig::kMaxScanQueue> queue_;
  RangeScan scratch_;
  InputRecorder recorder_;
  PosePublisher publisher_;
  io::OutputSet outputs_;  // trajectory and map, delivered together (manifest.txt)
  std::uint64_t written_at_scans_ = ~std::uint64_t{0};  // scans_placed at the last delivered set
  RangeScan slam_scan_;  // the placed scan as SLAM gets it (InputRecorder::pass)
  PendingScan pending_scratch_;
  DaemonCounters counters_;
  RingBuffer<std::int32_t, kLatencyWindow> stamp_latency_;
  RingBuffer<std::int32_t, kLatencyWindow> read_latency_;
  std::int64_t stamp_latency_max_us_ = 0;
  std::int64_t read_latency_max_us_ = 0;
  std::uint64_t latency_count_ = 0U;
  bool encoders_started_ = false;
  std::int64_t start_us_ = 0;
  std::int64_t next_output_us_ = 0;
  std::int64_t next_snapshot_us_ = 0;
  std::uint64_t snapshot_at_scans_ = 0U;  // scans_placed at the last snapshot (or the resumed one)
  int snapshot_child_ = 0;                // pid of the child writing one, 0 if none
  std::uint64_t snapshot_child_scans_ = 0U;
  std::int64_t snapshot_child_started_us_ = 0;
  std::string last_output_error_;
  // Previous values of watched counters/states.
  hal::RangeSourceHealth seen_health_ = hal::RangeSourceHealth::kStarting;
  hal::RangeSourceStats seen_laser_{};
  hal::CanBusState seen_can_state_ = hal::CanBusState::kActive;
  hal::CanBusStats seen_can_{};
  hal::OdometryStatus seen_odom_ = hal::OdometryStatus::kNoData;
  std::int64_t last_odom_stamp_us_ = 0;
};

}  // namespace sdpslam::daemon
