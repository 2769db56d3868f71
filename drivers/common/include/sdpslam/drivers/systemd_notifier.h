#pragma once
// systemd's service notification protocol (sd_notify(3)), written out: a datagram of
// newline-separated KEY=VALUE assignments sent to the AF_UNIX datagram socket that
// $NOTIFY_SOCKET names (a path, or '@' + a name in the abstract namespace). The protocol is
// stable and documented for implementations without libsystemd (systemd's "Interface
// Portability and Stability" promise; sd_notify(3) NOTES); writing it out keeps the robot
// program free of a library that the cross sysroots do not carry.
//
// Used by a Type=notify unit (firmware-host/systemd/sdpslamd.service):
//   - ready() once the program is up (READY=1), so that `systemctl start` returns only
//     then and a unit ordered after it starts on a running daemon;
//   - pat() from the main loop (hal::Watchdog): WATCHDOG=1 at most every half of
//     $WATCHDOG_USEC (the cadence sd_watchdog_enabled(3) advises). If the loop stalls the
//     pings stop, and after WatchdogSec= systemd kills the process (SIGABRT) and
//     Restart=on-failure starts it again;
//   - status() for `systemctl status`, stopping() when it shuts down.
// Without $NOTIFY_SOCKET (started by hand, or by another supervisor) every call does
// nothing. $WATCHDOG_PID, when set, must be this process's id, else the watchdog was meant
// for another process and pat() stays silent (sd_watchdog_enabled(3)).
//
// A send never blocks (MSG_DONTWAIT): a busy service manager costs a lost ping, counted,
// never a stalled loop. Failures are counted and the last one is kept as text.
#include <cstdint>
#include <string>

#include "sdpslam/hal/clock.h"
#include "sdpslam/hal/watchdog.h"

namespace sdpslam::drivers {

// The variables the service manager sets (empty: not set).
struct NotifyEnvironment {
  std::string notify_socket;  // $NOTIFY_SOCKET
  std::string watchdog_usec;  // $WATCHDOG_USEC
  std::string watchdog_pid;   // $WATCHDOG_PID
  static NotifyEnvironment from_process();  // getenv()
};

class SystemdNotifier final : public hal::Watchdog {
 public:
  // `pid`: this process's id (getpid()), compared with $WATCHDOG_PID.
  SystemdNotifier(const NotifyEnvironment& env, const hal::MonotonicClock& clock, long pid);
  ~SystemdNotifier() override;
  SystemdNotifier(const SystemdNotifier&) = delete;
  SystemdNotifier& operator=(const SystemdNotifier&) = delete;

  // A service manager listens ($NOTIFY_SOCKET given, valid, and a socket open).
  bool enabled() const { return fd_ >= 0; }
  // The watchdog's timeout ($WATCHDOG_USEC), 0 when there is none (or not for us).
  std::int64_t watchdog_timeout_us() const { return watchdog_us_; }
  // Why the environment could not be used ("" when it could, or when nothing was set).
  const std::string& setup_error() const { return setup_error_; }

  // Each sends one datagram; true iff it was sent (false also when not enabled).
  // `status` (may be null) is one line for `systemctl status` (newlines become spaces).
  bool ready(const char* status);
  bool status(const char* status);
  bool stopping();
  // WATCHDOG=1, when the watchdog is on and half its timeout has passed since the last.
  void pat() override;

  std::uint64_t sent() const { return sent_; }
  std::uint64_t failures() const { return failures_; }
  const std::string& last_error() const { return last_error_; }

 private:
  bool send(const std::string& message);

  const hal::MonotonicClock& clock_;
  int fd_ = -1;
  std::string address_;  // sun_path bytes (abstract: leading '\0')
  std::int64_t watchdog_us_ = 0;
  std::int64_t last_ping_us_ = 0;
  bool pinged_ = false;
  std::uint64_t sent_ = 0U;
  std::uint64_t failures_ = 0U;
  std::string setup_error_;
  std::string last_error_;
};

}  // namespace sdpslam::drivers
