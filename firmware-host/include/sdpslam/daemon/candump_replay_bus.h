#pragma once
// A hal::CanBus that replays a `candump -l` log (protocols.md §3) at its recorded times
// on the program's monotonic clock: sdpslamd's --can-candump input, for running the
// unmodified program without CAN hardware.
//
// Frame k is due at start_us + (t_k − t_0) / speed, t_0 = the first frame's log stamp.
// receive() hands out every frame whose time has come, stamped with its due time (as the
// kernel's SO_TIMESTAMP stamps a frame on arrival), so a reader that is late still sees
// the recorded timing. send() accepts and counts every frame (SYNC, NMT go nowhere).
// Malformed lines are skipped, counted and remembered as "file:line: reason"; the frames
// around them are kept. Error frames in the log (CAN_ERR_FLAG) are consumed into the
// stats and the bus state like SocketCanBus does (bus-off → kBusOff until the next data
// frame). At the end of the log the bus stays active and silent (ended() is true).
// Memory: fixed (one line buffer, one look-ahead record); the file is read as it plays.
#include <cstdint>
#include <string>

#include "sdpslam/drivers/candump_log.h"
#include "sdpslam/hal/can_bus.h"
#include "sdpslam/hal/clock.h"

namespace sdpslam::daemon {

struct CandumpReplayOptions {
  std::int64_t start_us = 0;  // monotonic time the first frame is due; 0 = at open()
  double speed = 1.0;         // > 0
};

class CandumpReplayBus final : public hal::CanBus {
 public:
  CandumpReplayBus(const hal::MonotonicClock& clock, const CandumpReplayOptions& options);
  // False iff the file cannot be opened (*error says why).
  bool open(const std::string& path, std::string* error);

  int send(const hal::CanFrame& frame) override;
  int receive(hal::CanFrame& out) override;
  int wait_readable(std::int64_t timeout_us) override;
  hal::CanBusState state() const override { return state_; }
  const hal::CanBusStats& stats() const override { return stats_; }

  bool ended() const { return !have_next_; }
  std::uint64_t bad_line_count() const { return bad_lines_; }
  // "file:line: reason" of the newest malformed line ("" if none).
  const std::string& last_bad_line() const { return last_bad_; }
  // Due time of the next frame (INT64_MAX at the end).
  std::int64_t next_due_us() const;

 private:
  void load_next();

  const hal::MonotonicClock& clock_;
  CandumpReplayOptions options_;
  drivers::CandumpReader reader_;
  std::string path_;
  drivers::CandumpRecord next_;
  bool have_next_ = false;
  bool have_origin_ = false;
  std::int64_t log_origin_us_ = 0;
  hal::CanBusState state_ = hal::CanBusState::kDown;
  hal::CanBusStats stats_;
  std::uint64_t bad_lines_ = 0U;
  std::string last_bad_;
};

}  // namespace sdpslam::daemon
