#include "sdpslam/drivers/systemd_notifier.h"

#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstddef>
#include <cstdlib>
#include <cstring>

namespace sdpslam::drivers {
namespace {

std::string env_or_empty(const char* name) {
  const char* v = std::getenv(name);
  return v != nullptr ? std::string(v) : std::string();
}

// A positive decimal integer without sign, spaces or suffix; false otherwise.
bool parse_positive(const std::string& text, long long* out) {
  if (text.empty() || text.size() > 18U) return false;
  long long v = 0;
  for (const char c : text) {
    if (c < '0' || c > '9') return false;
    v = v * 10 + (c - '0');
  }
  if (v <= 0) return false;
  *out = v;
  return true;
}

}  // namespace

NotifyEnvironment NotifyEnvironment::from_process() {
  NotifyEnvironment e;
  e.notify_socket = env_or_empty("NOTIFY_SOCKET");
  e.watchdog_usec = env_or_empty("WATCHDOG_USEC");
  e.watchdog_pid = env_or_empty("WATCHDOG_PID");
  return e;
}

SystemdNotifier::SystemdNotifier(const NotifyEnvironment& env, const hal::MonotonicClock& clock, long pid)
    : clock_(clock) {
  if (env.notify_socket.empty()) return;  // no service manager listens: nothing to do
  const std::string& s = env.notify_socket;
  if (s[0] != '/' && s[0] != '@') {
    setup_error_ = "NOTIFY_SOCKET '" + s + "': neither an absolute path nor '@' + an abstract name";
    return;
  }
  if (s.size() < 2U || s.size() > sizeof(sockaddr_un{}.sun_path) - 1U) {
    setup_error_ = "NOTIFY_SOCKET '" + s + "': empty or longer than a socket address holds";
    return;
  }
  address_ = s;
  if (s[0] == '@') address_[0] = '\0';
  if (!env.watchdog_usec.empty()) {
    long long us = 0;
    long long watchdog_pid = 0;
    if (!parse_positive(env.watchdog_usec, &us)) {
      setup_error_ = "WATCHDOG_USEC '" + env.watchdog_usec + "': not a positive number of microseconds; no watchdog";
    } else if (!env.watchdog_pid.empty() && !parse_positive(env.watchdog_pid, &watchdog_pid)) {
      setup_error_ = "WATCHDOG_PID '" + env.watchdog_pid + "': not a process id; no watchdog";
    } else if (env.watchdog_pid.empty() || watchdog_pid == pid) {
      watchdog_us_ = static_cast<std::int64_t>(us);
    }  // else the watchdog is another process's
  }
  fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) {
    setup_error_ = std::string("cannot open a notification socket: ") + std::strerror(errno);
    watchdog_us_ = 0;
  }
}

SystemdNotifier::~SystemdNotifier() {
  if (fd_ >= 0) ::close(fd_);
}

bool SystemdNotifier::send(const std::string& message) {
  if (fd_ < 0) return false;
  sockaddr_un sa{};
  sa.sun_family = AF_UNIX;
  std::memcpy(sa.sun_path, address_.data(), address_.size());
  // An abstract address is exactly its bytes; a path gets its terminating NUL.
  const std::size_t length = offsetof(sockaddr_un, sun_path) + address_.size() + (address_[0] == '\0' ? 0U : 1U);
  const ssize_t n = ::sendto(fd_, message.data(), message.size(), MSG_DONTWAIT | MSG_NOSIGNAL,
                             reinterpret_cast<const sockaddr*>(&sa), static_cast<socklen_t>(length));
  if (n == static_cast<ssize_t>(message.size())) {
    ++sent_;
    return true;
  }
  ++failures_;
  last_error_ = n < 0 ? std::string("notification not sent: ") + std::strerror(errno) : "notification cut short";
  return false;
}

namespace {
std::string status_line(const char* status) {
  std::string line = "STATUS=";
  for (const char* p = status; *p != '\0'; ++p) line += (*p == '\n' || *p == '\r') ? ' ' : *p;
  return line;
}
}  // namespace

bool SystemdNotifier::ready(const char* status) {
  return send(status != nullptr ? "READY=1\n" + status_line(status) : std::string("READY=1"));
}

bool SystemdNotifier::status(const char* status) { return status != nullptr && send(status_line(status)); }

bool SystemdNotifier::stopping() { return send("STOPPING=1"); }

void SystemdNotifier::pat() {
  if (watchdog_us_ <= 0 || fd_ < 0) return;
  const std::int64_t now = clock_.now_us();
  if (pinged_ && now - last_ping_us_ < watchdog_us_ / 2) return;
  // A ping that could not be sent is tried again on the next pat.
  if (send("WATCHDOG=1")) {
    pinged_ = true;
    last_ping_us_ = now;
  }
}

}  // namespace sdpslam::drivers
