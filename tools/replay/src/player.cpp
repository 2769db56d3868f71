#include "sdpslam/replay/player.h"

#include <poll.h>
#include <time.h>

#include <climits>

namespace sdpslam::replay {

Player::Player(const hal::MonotonicClock& clock, const PlayerOptions& options)
    : clock_(clock), options_(options) {}

void Player::set_can(hal::CanBus* bus, const std::vector<drivers::CandumpRecord>* frames) {
  bus_ = bus;
  frames_ = frames;
}

void Player::set_laser(LaserEngine* engine, LaserPty* pty) {
  engine_ = engine;
  pty_ = pty;
}

void Player::run(std::int64_t log_start_us, double speed, std::int64_t start_delay_us) {
  const std::int64_t t_begin = clock_.now_us();
  timeline_ = ReplayTimeline{log_start_us, t_begin + start_delay_us, speed};
  if (engine_ != nullptr) engine_->set_timeline(timeline_);
  const std::size_t n_frames = (bus_ != nullptr && frames_ != nullptr) ? frames_->size() : 0U;
  std::size_t next = 0;
  std::int64_t failing_since = -1;
  std::int64_t end_us = -1;
  for (;;) {
    std::int64_t now = clock_.now_us();
    // CAN: everything due, in order; stop at the first frame the bus cannot take now.
    bool blocked = false;
    while (next < n_frames) {
      const std::int64_t due = timeline_.due_us((*frames_)[next].stamp_us);
      if (due > now) break;
      const int r = bus_->send((*frames_)[next].frame);
      if (r == 1) {
        ++stats_.frames_sent;
        const std::int64_t late = now - due;
        if (late > stats_.max_frame_lateness_us) stats_.max_frame_lateness_us = late;
        if (late > options_.late_threshold_us) ++stats_.frames_late;
        ++next;
        failing_since = -1;
        continue;
      }
      if (r == 0) ++stats_.send_try_later; else ++stats_.send_errors;
      if (failing_since < 0) failing_since = now;
      if (now - failing_since >= options_.give_up_us) {
        ++stats_.frames_dropped;  // reported, never silent
        ++next;
        failing_since = -1;
        continue;
      }
      blocked = true;
      break;
    }
    if (pty_ != nullptr && engine_ != nullptr) pty_->pump(*engine_, now);
    const bool can_done = next >= n_frames;
    const bool laser_done = engine_ == nullptr || (engine_->done() && (pty_ == nullptr || !pty_->has_queued_output()));
    if (can_done && laser_done) {
      if (end_us < 0) end_us = now + options_.tail_us;
      if (now >= end_us || engine_ == nullptr) break;
    }
    // Sleep until the next event, waking early for host bytes on the pty.
    std::int64_t wake = INT64_MAX;
    if (next < n_frames) wake = blocked ? now + options_.retry_interval_us : timeline_.due_us((*frames_)[next].stamp_us);
    if (engine_ != nullptr && engine_->next_wake_us() < wake) wake = engine_->next_wake_us();
    if (end_us >= 0 && end_us < wake) wake = end_us;
    if (pty_ != nullptr && pty_->has_queued_output() && now + 1000 < wake) wake = now + 1000;
    now = clock_.now_us();
    std::int64_t wait_us = wake == INT64_MAX ? 10000 : wake - now;
    if (wait_us <= 0) continue;
    if (wait_us > 100000) wait_us = 100000;
    pollfd pfd{pty_ != nullptr ? pty_->master_fd() : -1, POLLIN, 0};
    const int timeout_ms = static_cast<int>((wait_us + 999) / 1000);
    if (pfd.fd >= 0) {
      ::poll(&pfd, 1, timeout_ms);
    } else {
      // Fine-grained sleep for CAN-only play: poll's ms granularity would add jitter.
      timespec ts{static_cast<time_t>(wait_us / 1000000), static_cast<long>((wait_us % 1000000) * 1000)};
      ::nanosleep(&ts, nullptr);
    }
  }
  stats_.wall_us = clock_.now_us() - t_begin;
}

}  // namespace sdpslam::replay
