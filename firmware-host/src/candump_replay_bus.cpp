#include "sdpslam/daemon/candump_replay_bus.h"

#include <time.h>

#include <cerrno>
#include <climits>
#include <cstring>

namespace sdpslam::daemon {

CandumpReplayBus::CandumpReplayBus(const hal::MonotonicClock& clock, const CandumpReplayOptions& options)
    : clock_(clock), options_(options) {
  if (!(options_.speed > 0.0)) options_.speed = 1.0;
}

bool CandumpReplayBus::open(const std::string& path, std::string* error) {
  if (!reader_.open(path.c_str())) {
    *error = path + ": cannot open: " + std::strerror(errno);
    return false;
  }
  path_ = path;
  if (options_.start_us == 0) options_.start_us = clock_.now_us();
  state_ = hal::CanBusState::kActive;
  load_next();
  return true;
}

void CandumpReplayBus::load_next() {
  have_next_ = false;
  for (;;) {
    const int r = reader_.next(next_);
    if (r == 0) return;
    if (r < 0) {
      ++bad_lines_;
      last_bad_ = path_ + ":" + std::to_string(reader_.line_number()) + ": " + drivers::to_string(reader_.error()) +
                  " (column " + std::to_string(reader_.column()) + ")";
      continue;
    }
    if (!have_origin_) {
      log_origin_us_ = next_.stamp_us;
      have_origin_ = true;
    }
    have_next_ = true;
    return;
  }
}

std::int64_t CandumpReplayBus::next_due_us() const {
  if (!have_next_) return INT64_MAX;
  return options_.start_us +
         static_cast<std::int64_t>(static_cast<double>(next_.stamp_us - log_origin_us_) / options_.speed);
}

int CandumpReplayBus::send(const hal::CanFrame& frame) {
  (void)frame;
  if (state_ == hal::CanBusState::kDown) {
    ++stats_.tx_while_down;
    return -1;
  }
  ++stats_.tx_frames;
  return 1;
}

int CandumpReplayBus::receive(hal::CanFrame& out) {
  if (state_ == hal::CanBusState::kDown) {
    ++stats_.rx_errors;
    return -1;
  }
  for (;;) {
    const std::int64_t due = next_due_us();
    if (due == INT64_MAX || due > clock_.now_us()) return 0;
    hal::CanFrame f = next_.frame;
    f.stamp_us = due;
    load_next();
    if (f.is_error()) {
      // linux/can/error.h: CAN_ERR_BUSOFF 0x40 in can_id; controller details in data[1].
      ++stats_.error_frames;
      if ((f.id & 0x40U) != 0U) {
        ++stats_.errors.bus_off;
        state_ = hal::CanBusState::kBusOff;
      }
      continue;
    }
    if (state_ == hal::CanBusState::kBusOff) {
      state_ = hal::CanBusState::kActive;  // traffic again: the controller recovered
      ++stats_.reopen_count;
    }
    ++stats_.rx_frames;
    out = f;
    return 1;
  }
}

int CandumpReplayBus::wait_readable(std::int64_t timeout_us) {
  if (state_ == hal::CanBusState::kDown) return -1;
  const std::int64_t now = clock_.now_us();
  const std::int64_t due = next_due_us();
  if (due <= now) return 1;
  const std::int64_t wait = due - now < timeout_us ? due - now : timeout_us;
  if (wait > 0) {
    timespec ts{static_cast<time_t>(wait / 1000000), static_cast<long>((wait % 1000000) * 1000)};
    nanosleep(&ts, nullptr);
  }
  return next_due_us() <= clock_.now_us() ? 1 : 0;
}

}  // namespace sdpslam::daemon
