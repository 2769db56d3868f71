#pragma once
// Offline SDP-SLAM runner (`sdpslam run --mode sdp`, the default): reads a robot log,
// feeds every laser scan with its odometry to SdpSlam (core/sdp_slam.h) and writes into
// out_dir:
//  - trajectory.txt   one "t x y theta" line per laser scan, exactly as in dpslam mode (the
//                     scan's stamp to the µs), in the global frame (the first segment's
//                     frame = the first scan's pose at the origin) for the best
//                     combination of submaps: permanent segments, the live levels' chosen
//                     submaps and the current segment's best particle; scans that were
//                     not processed take the last estimate composed with the odometry;
//  - trajectory.tum   the same poses in TUM format (slam_outputs.h write_trajectories);
//  - map.pgm/.yaml,   the global map (Fig. 3 (j)-(l)): the permanent map (each cell moved
//    map.png          with its level's corrected frame) plus each
//                     chosen submap's DP-map view transformed into the global frame,
//                     hits and misses summed per cell; the PNG has the trajectory drawn;
//  - icp_error.csv    "stamp_s,mean_m,std_m,samples": mean and std of the ICP error of
//                     the top-level samples of every evaluation round that matched
//                     something (Figs. 6-7), and icp_error.png, its line plot;
//  - stats.json       counts, pools and their high-water marks, exhaustion counters,
//                     Table I's μ/σ over all samples; "timing" holds the only
//                     non-deterministic fields (wall time, per-scan times, RSS).
// Same log, options and seed -> bit-identical trajectory.txt, map and icp_error.csv.
#include <cstdint>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "sdpslam/core/sdp_options.h"
#include "sdpslam/core/sdp_profile.h"
#include "sdpslam/io/figures.h"
#include "sdpslam/slam/config_ini.h"
#include "sdpslam/slam/run_summary.h"

namespace sdpslam::slam {

struct SdpRunOptions {
  SlamConfig config;      // bottom level ([filter] particles = B) and log options
  SdpOptions sdp;         // [sdp]
  // The profile config and sdp started from (core/sdp_profile.h): reported in stats.json
  // only; the caller applies it before the file's keys.
  SdpProfile profile = kDefaultSdpProfile;
  std::uint64_t seed = 1U;
  // Called after every scan with the bytes of the log read so far (compressed bytes for
  // .gz; io::LogReader::input_offset()), for a progress display; may be empty.
  std::function<void(std::uint64_t input_bytes)> progress;
  // Draws map.png and icp_error.png (figures.h; the sdpslam CLI: plot::painter()).
  io::Painter painter = io::plain_painter();
  // Snapshots (io/snapshot_file.h). With snapshot_path set, the run's state (this
  // runner's and the engine's, SdpSlam::save_state) replaces that file every
  // snapshot_every_s seconds of log time, and once after the last scan. With
  // resume_path set, the run starts from that snapshot: the log is read again from its
  // start, the scans the snapshot holds are checked against it (same stamps) and not
  // processed again, and the outputs are those of a run that never stopped.
  // config_fingerprint names the options (the caller's hash of everything that sets
  // them): a snapshot written with other options, by another version, or damaged is
  // refused (kBadInput) before anything is read from it.
  std::string snapshot_path;
  double snapshot_every_s = 0.0;
  std::string resume_path;
  // With extend_path set (not with resume_path), the run continues the session that
  // snapshot holds with this log, another recording of the same building: every scan
  // of the log is processed after the snapshot's, the robot taken to start where the
  // session left it, or where its first scan is found in the saved map within
  // ±extend_window_m (session_continuation.h; 0 = where it was left). The outputs hold
  // both: the session's scans, then this log's (stamps shifted to follow the session's
  // when they do not).
  std::string extend_path;
  double extend_window_m = 10.0;
  std::uint64_t config_fingerprint = 0U;
};

struct SdpRunSummary : RunSummary {
  std::uint64_t segments = 0U;
  double icp_error_mean_m = 0.0;
  double icp_error_std_m = 0.0;
  std::uint64_t icp_error_samples = 0U;
  std::uint64_t resumed_at_scan = 0U;  // scans the resumed snapshot held (0: from the start)
  std::uint64_t extended_after_scan = 0U;  // scans the extended session held (0: not extended)
  std::string extend_place;            // what the extension found (ContinuationReport::describe)
  std::uint64_t snapshots_written = 0U;
  std::uint64_t snapshot_bytes = 0U;   // the last one's file size
  double snapshot_write_ms_max = 0.0;
};

enum class SdpRunStatus { kOk, kBadInput, kIoError, kInternal };

// Bytes of the whole SLAM state these options ask for (the one arena run_sdp_offline
// allocates: SdpSlam::required_arena_bytes), known before any work; 0 when the options
// are invalid or their sizes overflow.
std::size_t sdp_state_bytes(const SdpRunOptions& options);
// Whether the core starts with these options (SdpSlam::check_options: every check of
// init but the arena's size); false with *why = "section.key: reason" otherwise.
bool sdp_check_options(const SdpRunOptions& options, std::string* why);

SdpRunStatus run_sdp_offline(const std::string& log_path, const SdpRunOptions& options, const std::string& out_dir,
                             SdpRunSummary* summary, std::string* error);

// Applies `[sdp] key = value` to *options through SdpOptions::table() (option_text.h).
// kApplied / kUnknown (not an sdp key) / kInvalid (malformed value or outside the key's
// own range; *why says why). The checks that join keys are SdpOptions::validate(), for
// the caller to run once every key is applied.
enum class SdpKeyResult { kApplied, kUnknown, kInvalid };
SdpKeyResult apply_sdp_key(SdpOptions* options, const std::string& key, const char* value, std::string* why);
// Reads only the [sdp] section of an INI file (the keys of other sections are ignored),
// then validates the options once. False iff the file cannot be read (IniDocument), an
// [sdp] key is unknown or its value malformed or outside its range, or the options as a
// whole are invalid; `error` is then "file:line: why" of the line to change.
bool load_sdp_ini(const std::string& path, SdpOptions* options, std::string* error);
// The same from an open stream (read to its end, not closed); `name` stands for the file
// in messages.
bool load_sdp_ini(std::FILE* stream, const std::string& name, SdpOptions* options, std::string* error);

}  // namespace sdpslam::slam
