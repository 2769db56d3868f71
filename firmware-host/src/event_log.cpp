#include "sdpslam/daemon/event_log.h"

namespace sdpslam::daemon {

const char* to_string(Event e) {
  switch (e) {
    case Event::kStartup: return "startup";
    case Event::kSession: return "session";
    case Event::kLaser: return "laser";
    case Event::kLaserData: return "laser-data";
    case Event::kCan: return "can";
    case Event::kCanData: return "can-data";
    case Event::kOdometry: return "odometry";
    case Event::kScanSkipped: return "scan-skipped";
    case Event::kScanDropped: return "scan-dropped";
    case Event::kOutput: return "output";
    case Event::kShutdown: return "shutdown";
    case Event::kCount: break;
  }
  return "?";
}

void EventLog::log(Event e, const char* fmt, ...) {
  const int k = static_cast<int>(e);
  ++count_[k];
  const std::int64_t now = clock_.now_us();
  if (ever_[k] && now - last_us_[k] < interval_us_) {
    ++held_[k];
    ++suppressed_total_;
    return;
  }
  ever_[k] = true;
  last_us_[k] = now;
  char line[400];
  va_list ap;
  va_start(ap, fmt);
  std::vsnprintf(line, sizeof line, fmt, ap);
  va_end(ap);
  if (held_[k] > 0U) {
    std::fprintf(out_, "sdpslamd: %s: %s (+%llu similar)\n", to_string(e), line,
                 static_cast<unsigned long long>(held_[k]));
  } else {
    std::fprintf(out_, "sdpslamd: %s: %s\n", to_string(e), line);
  }
  std::fflush(out_);
  held_[k] = 0U;
  ++printed_;
}

}  // namespace sdpslam::daemon
