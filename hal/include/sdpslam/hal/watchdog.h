#pragma once
// A supervisor that restarts the program when its main loop stops making progress (on
// Linux: systemd's service watchdog, drivers/common/systemd_notifier.h; ArduPilot's HAL
// has the same "pat" from its scheduler loop). The loop calls pat() once per pass; the
// implementation decides how often that reaches the supervisor. A pat must come from the
// loop itself, never from a timer or another thread: its absence is what tells the
// supervisor that the loop hangs.
namespace sdpslam::hal {

class Watchdog {
 public:
  virtual ~Watchdog() = default;
  virtual void pat() = 0;
};

}  // namespace sdpslam::hal
