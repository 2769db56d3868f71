// The sd_notify protocol as sdpslamd speaks it: READY=1 with its status, WATCHDOG=1 at
// half the timeout from the loop's pats, STOPPING=1; the environment's forms (path and
// abstract socket, $WATCHDOG_PID) and its errors.
#include <CppUTest/TestHarness.h>

#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstddef>
#include <cstring>
#include <string>

#include "sdpslam/drivers/systemd_notifier.h"
#include "shared_data.h"

using namespace sdpslam;
using namespace sdpslam::drivers;

namespace {

class FakeClock final : public hal::MonotonicClock {
 public:
  std::int64_t now_us() const override { return t; }
  std::int64_t t = 5000000;
};

// A service manager's end: a datagram socket bound to `name` ('@' = abstract namespace).
class Listener {
 public:
  explicit Listener(const std::string& name) {
    fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_un sa{};
    sa.sun_family = AF_UNIX;
    std::memcpy(sa.sun_path, name.data(), name.size());
    if (name[0] == '@') sa.sun_path[0] = '\0';
    else ::unlink(name.c_str());
    const std::size_t len = offsetof(sockaddr_un, sun_path) + name.size() + (name[0] == '@' ? 0U : 1U);
    bound_ = ::bind(fd_, reinterpret_cast<const sockaddr*>(&sa), static_cast<socklen_t>(len)) == 0;
  }
  ~Listener() { ::close(fd_); }
  bool bound() const { return bound_; }
  // The next datagram, or "" if none is waiting.
  std::string take() {
    char buf[512];
    const ssize_t n = ::recv(fd_, buf, sizeof buf, MSG_DONTWAIT);
    return n > 0 ? std::string(buf, static_cast<std::size_t>(n)) : std::string();
  }

 private:
  int fd_ = -1;
  bool bound_ = false;
};

std::string abstract_name(const char* what) {
  return "@sdpslam-test-" + std::string(what) + "-" + std::to_string(static_cast<long>(::getpid()));
}

}  // namespace

TEST_GROUP(SystemdNotifier){};

TEST(SystemdNotifier, without_a_notify_socket_it_does_nothing_and_reports_nothing) {
  FakeClock clock;
  SystemdNotifier n(NotifyEnvironment{}, clock, 42);
  CHECK_FALSE(n.enabled());
  CHECK_FALSE(n.ready("up"));
  n.pat();
  LONGS_EQUAL(0, n.watchdog_timeout_us());
  LONGS_EQUAL(0, n.sent());
  LONGS_EQUAL(0, n.failures());
  STRCMP_EQUAL("", n.setup_error().c_str());
}

TEST(SystemdNotifier, ready_carries_its_status_and_stopping_follows_on_a_path_socket) {
  const std::string path = test::make_temp_dir("notify") + "/notify.sock";
  Listener l(path);
  CHECK_TRUE(l.bound());
  FakeClock clock;
  NotifyEnvironment env;
  env.notify_socket = path;
  SystemdNotifier n(env, clock, 42);
  CHECK_TRUE(n.enabled());
  CHECK_TRUE(n.ready("running\nmode sdp"));
  STRCMP_EQUAL("READY=1\nSTATUS=running mode sdp", l.take().c_str());
  CHECK_TRUE(n.status("3 scans"));
  STRCMP_EQUAL("STATUS=3 scans", l.take().c_str());
  CHECK_TRUE(n.stopping());
  STRCMP_EQUAL("STOPPING=1", l.take().c_str());
  n.pat();  // no $WATCHDOG_USEC: no watchdog
  STRCMP_EQUAL("", l.take().c_str());
  LONGS_EQUAL(3, n.sent());
}

// sd_watchdog_enabled(3): ping at half the timeout; the loop pats far more often.
TEST(SystemdNotifier, pats_reach_the_manager_at_half_the_watchdog_timeout) {
  const std::string name = abstract_name("watchdog");
  Listener l(name);
  CHECK_TRUE(l.bound());
  FakeClock clock;
  NotifyEnvironment env;
  env.notify_socket = name;
  env.watchdog_usec = "2000000";
  env.watchdog_pid = "42";
  SystemdNotifier n(env, clock, 42);
  LONGS_EQUAL(2000000, n.watchdog_timeout_us());
  int pings = 0;
  for (int step = 0; step < 400; ++step) {  // 4 s of a loop stepping every 10 ms
    n.pat();
    for (std::string m = l.take(); !m.empty(); m = l.take()) {
      STRCMP_EQUAL("WATCHDOG=1", m.c_str());
      ++pings;
    }
    clock.t += 10000;
  }
  LONGS_EQUAL(4, pings);  // at 0, 1, 2 and 3 s
  LONGS_EQUAL(0, n.failures());
}

TEST(SystemdNotifier, a_watchdog_meant_for_another_process_stays_silent) {
  const std::string name = abstract_name("other");
  Listener l(name);
  FakeClock clock;
  NotifyEnvironment env;
  env.notify_socket = name;
  env.watchdog_usec = "1000000";
  env.watchdog_pid = "41";
  SystemdNotifier n(env, clock, 42);
  CHECK_TRUE(n.enabled());
  LONGS_EQUAL(0, n.watchdog_timeout_us());
  n.pat();
  STRCMP_EQUAL("", l.take().c_str());
  STRCMP_EQUAL("", n.setup_error().c_str());
}

TEST(SystemdNotifier, a_bad_environment_is_named_and_sends_nothing_it_cannot) {
  FakeClock clock;
  NotifyEnvironment relative;
  relative.notify_socket = "run/notify";
  SystemdNotifier a(relative, clock, 42);
  CHECK_FALSE(a.enabled());
  CHECK_TEXT(a.setup_error().find("NOTIFY_SOCKET 'run/notify': neither an absolute path") != std::string::npos,
             a.setup_error().c_str());
  NotifyEnvironment too_long;
  too_long.notify_socket = "/" + std::string(200, 'x');
  SystemdNotifier b(too_long, clock, 42);
  CHECK_FALSE(b.enabled());
  CHECK_TEXT(b.setup_error().find("longer than a socket address holds") != std::string::npos, b.setup_error().c_str());
  NotifyEnvironment bad_usec;
  bad_usec.notify_socket = abstract_name("bad");
  bad_usec.watchdog_usec = "30s";
  SystemdNotifier c(bad_usec, clock, 42);
  CHECK_TRUE(c.enabled());  // notifications still go; only the watchdog is off
  LONGS_EQUAL(0, c.watchdog_timeout_us());
  CHECK_TEXT(c.setup_error().find("WATCHDOG_USEC '30s': not a positive number") != std::string::npos,
             c.setup_error().c_str());
}

// Nobody listens at the address: counted and named, never fatal, and a later pat retries.
TEST(SystemdNotifier, a_manager_that_is_gone_costs_a_counted_failure) {
  FakeClock clock;
  NotifyEnvironment env;
  env.notify_socket = abstract_name("gone");
  env.watchdog_usec = "1000000";
  SystemdNotifier n(env, clock, 42);
  CHECK_FALSE(n.ready(nullptr));
  n.pat();
  n.pat();
  LONGS_EQUAL(3, n.failures());
  CHECK_TEXT(n.last_error().find("notification not sent: ") == 0, n.last_error().c_str());
}
