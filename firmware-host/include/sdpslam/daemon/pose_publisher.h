#pragma once
// The live pose for a navigation stack ([output] pose_socket): sdpslamd sends each placed
// scan's pose, as one fixed 64-byte datagram, to every subscriber of a UNIX datagram
// socket.
//
// Subscribing: a client binds a datagram socket of its own (a path, or Linux's abstract
// namespace) and sends any datagram to the daemon's socket: "SUBSCRIBE" (or anything
// else) subscribes its address, "UNSUBSCRIBE" removes it. Up to kMaxSubscribers at once
// (more are refused and counted); a subscriber whose socket is gone (ECONNREFUSED,
// ENOENT) is removed; a record a subscriber's full queue cannot take is dropped for it
// and counted, never waited for: the loop does not block on its clients.
// tools/examples/pose_client.py is a client.
//
// Record (little-endian, no padding):
//   off size
//     0   4  magic "SDPP"
//     4   2  version (1)
//     6   2  flags: bit 0 the engine updated its estimate with this scan (else the pose is
//            the last estimate moved by odometry), bit 1 mode localize
//     8   4  sequence: 1 for the first record, +1 each (a gap: records dropped)
//    12   4  map_version: map deliveries so far (output periods that rewrote map.pgm);
//            a client reloads the map when it changes
//    16   8  stamp_us: the scan's stamp, int64, CLOCK_MONOTONIC µs
//    24  24  x_m, y_m, heading_rad: float64, map frame
//    48  16  covariance: float32 var_x (m²), cov_xy (m²), var_y (m²), var_heading (rad²):
//            the spread of the particles behind the estimate (the bottom-level filter's
//            in modes dpslam and sdp, the localizer's in mode localize)
#include <sys/socket.h>
#include <sys/un.h>

#include <cstdint>
#include <string>

#include "sdpslam/core/pose2.h"

namespace sdpslam::daemon {

struct PoseRecord {
  static constexpr std::size_t kBytes = 64U;
  static constexpr std::uint16_t kVersion = 1U;
  static constexpr std::uint16_t kFlagProcessed = 1U;
  static constexpr std::uint16_t kFlagLocalize = 2U;
  std::uint16_t flags = 0U;
  std::uint32_t sequence = 0U;
  std::uint32_t map_version = 0U;
  std::int64_t stamp_us = 0;
  Pose2 pose;
  float var_x = 0.0F;
  float cov_xy = 0.0F;
  float var_y = 0.0F;
  float var_heading = 0.0F;
};

void encode_pose_record(const PoseRecord& r, unsigned char out[PoseRecord::kBytes]);
// False iff the bytes are no version-1 record (size, magic or version).
bool decode_pose_record(const unsigned char* data, std::size_t n, PoseRecord* out);

struct PosePublisherStats {
  std::uint64_t records = 0U;              // records published (each to every subscriber)
  std::uint64_t datagrams_sent = 0U;
  std::uint64_t datagrams_dropped = 0U;    // a subscriber's queue was full
  std::uint64_t subscribes = 0U;
  std::uint64_t subscribers_refused = 0U;  // kMaxSubscribers reached
  std::uint64_t subscribers_lost = 0U;     // their socket went away
};

class PosePublisher {
 public:
  static constexpr std::size_t kMaxSubscribers = 8U;

  PosePublisher() = default;
  ~PosePublisher();
  PosePublisher(const PosePublisher&) = delete;
  PosePublisher& operator=(const PosePublisher&) = delete;

  // Binds `path` (a stale socket file there is replaced). False with *error otherwise.
  bool open(const std::string& path, std::string* error);
  bool is_open() const { return fd_ >= 0; }
  // Takes the (un)subscriptions waiting on the socket; never blocks.
  void poll();
  // Sends the record (its sequence is set here) to every subscriber; never blocks.
  void publish(PoseRecord record);
  std::size_t subscribers() const { return count_; }
  const PosePublisherStats& stats() const { return stats_; }

 private:
  struct Subscriber {
    sockaddr_un addr;
    socklen_t len;
  };
  void remove(std::size_t i);

  int fd_ = -1;
  std::string path_;
  Subscriber subs_[kMaxSubscribers] = {};
  std::size_t count_ = 0U;
  std::uint32_t sequence_ = 0U;
  PosePublisherStats stats_;
};

}  // namespace sdpslam::daemon
