#pragma once
// Wheel-encoder CAN frames from a robot log, for hardware-in-the-loop replay.
//
// Two sources of wheel motion:
//  - a pose track (CARMEN ODOM lines, or the odometry pose inside each laser record):
//    resampled at a fixed period by linear interpolation in time (heading interpolated
//    along the shorter arc), then turned into cumulative ticks by the inverse model
//    drivers::poses_to_ticks (protocols.md §4; constant-curvature arcs between samples);
//  - real counter readings (tinySLAM logs carry them: read_tinyslam_ticks()).
// The ticks become CANopen TPDO1 position frames (CiA 406 object 0x6004, u32 LE,
// wrapping modulo 2^32, optionally each pair preceded by SYNC 080#) or ODrive
// Get_Encoder_Estimates frames (f32 turns, f32 turns/s; protocols.md §3).
// Stamps keep the log's time base, so frames and laser scans of the same log align.
#include <cstdint>
#include <string>
#include <vector>

#include "sdpslam/core/pose2.h"
#include "sdpslam/drivers/can_wheel_encoders.h"
#include "sdpslam/drivers/candump_log.h"
#include "sdpslam/drivers/diff_drive_odometry.h"

namespace sdpslam::replay {

using sdpslam::StampedPose;  // core/pose2.h

// Cumulative signed wheel travel (ticks, after DiffDriveParams signs) at one instant.
struct TickSample {
  std::int64_t stamp_us = 0;
  std::int64_t left_ticks = 0;
  std::int64_t right_ticks = 0;
};

// Samples `poses` (stamps strictly increasing is NOT required: equal or decreasing
// stamps are dropped and counted in *dropped) every period_us from the first stamp to
// the last, and converts the samples to ticks with poses_to_ticks. Returns false iff
// params are invalid, period_us <= 0 or fewer than one usable pose remains; *error says
// why. The first sample has ticks 0/0.
bool poses_to_tick_track(const std::vector<StampedPose>& poses, const drivers::DiffDriveParams& params,
                         std::int64_t period_us, std::vector<TickSample>* out, std::size_t* dropped,
                         std::string* error);

// Interpolated pose at t (clamped to the track's ends); the track must be non-empty and
// sorted by stamp.
Pose2 interpolate_pose(const std::vector<StampedPose>& poses, std::int64_t t_us);

struct EncoderFrameOptions {
  drivers::EncoderProtocol protocol = drivers::EncoderProtocol::kCanOpen;
  drivers::DiffDriveParams params;  // signs and ticks_per_rev / gear ratio apply
  std::uint8_t left_node = 1;
  std::uint8_t right_node = 2;
  bool with_sync = true;            // CANopen: 080# before each TPDO1 pair
  char interface_name[16] = "can0";
};

// Frames for each sample, in time order: [SYNC] left right (CANopen: TPDO1 of the raw
// u32 counter = static_cast<uint32_t>(ticks)); ODrive: Get_Encoder_Estimates with
// pos = ticks / ticks_per_rev (turns of the encoder shaft) and vel = the difference to
// the previous sample over its time (0 for the first). Record stamps are the sample
// stamps. Returns false iff a node id is out of range for the protocol.
bool tick_track_to_frames(const std::vector<TickSample>& track, const EncoderFrameOptions& options,
                          std::vector<drivers::CandumpRecord>* out, std::string* error);

// Writes the records as a candump -l log. False iff the file cannot be written.
bool write_candump_file(const std::string& path, const std::vector<drivers::CandumpRecord>& records,
                        std::string* error);

// Reads the TPDO1 positions of both nodes back from candump records and integrates them
// with DiffDriveOdometry exactly as a receiver sees them: a pair is complete when both
// nodes have a sample newer than the last pair. Returns the number of pairs integrated
// (the first is the latch). `pose_out` receives the final pose.
std::size_t integrate_canopen_frames(const std::vector<drivers::CandumpRecord>& records,
                                     const drivers::DiffDriveParams& params, std::uint8_t left_node,
                                     std::uint8_t right_node, Pose2* pose_out);

}  // namespace sdpslam::replay
