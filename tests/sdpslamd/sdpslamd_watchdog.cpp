// sdpslamd under a stand-in for systemd's service manager, with the protocol of a
// Type=notify unit with WatchdogSec= (sd_notify(3), systemd.service(5)):
//   1. the manager listens on $NOTIFY_SOCKET and starts sdpslamd with $WATCHDOG_USEC set;
//      sdpslamd must say READY=1;
//   2. while its loop runs (no sensors attached: it keeps retrying them) WATCHDOG=1 must
//      come more often than the timeout, never leaving a gap the manager would act on;
//   3. the process is stalled (SIGSTOP): no ping may come, the timeout expires, and the
//      manager does what systemd does, SIGABRT, which must end the process;
//   4. a second start is stopped with SIGTERM: STOPPING=1 and exit 0 (final outputs written).
//
//   sdpslamd_watchdog WORK_DIR SDPSLAMD [PREFIX...]   (PREFIX: an emulator before SDPSLAMD)
// Exit 0 when every step holds, 1 with the reason on stderr otherwise.
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

extern char** environ;

namespace {

constexpr long long kWatchdogUs = 1000000;  // WatchdogSec=1 s

long long now_us() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<long long>(ts.tv_sec) * 1000000LL + ts.tv_nsec / 1000;
}

int fail(const std::string& why) {
  std::fprintf(stderr, "sdpslamd_watchdog: FAIL: %s\n", why.c_str());
  return 1;
}

class Manager {
 public:
  explicit Manager(const std::string& name) : name_(name) {
    fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_un sa{};
    sa.sun_family = AF_UNIX;
    if (name.size() >= sizeof sa.sun_path) return;
    std::memcpy(sa.sun_path, name.data(), name.size());
    ::unlink(name.c_str());
    const auto len = static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + name.size() + 1U);
    ok_ = fd_ >= 0 && ::bind(fd_, reinterpret_cast<const sockaddr*>(&sa), len) == 0;
  }
  bool ok() const { return ok_; }
  // Starts the program with the manager's environment; its pid, or -1.
  // (posix_spawn, not fork + exec: the harness itself may run under qemu-user, whose
  // forked child must not allocate before it execs.) $WATCHDOG_PID is left unset, which
  // means "this process" (the unit test covers a pid that is someone else's).
  pid_t start(const std::vector<std::string>& argv) {
    std::vector<std::string> env_text = {"NOTIFY_SOCKET=" + name_, "WATCHDOG_USEC=" + std::to_string(kWatchdogUs)};
    for (char** e = environ; *e != nullptr; ++e) {
      const std::string v = *e;
      if (v.compare(0, 14, "NOTIFY_SOCKET=") != 0 && v.compare(0, 14, "WATCHDOG_USEC=") != 0 &&
          v.compare(0, 13, "WATCHDOG_PID=") != 0) {
        env_text.push_back(v);
      }
    }
    std::vector<char*> env;
    for (std::string& v : env_text) env.push_back(v.data());
    env.push_back(nullptr);
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    pid_t pid = -1;
    if (::posix_spawnp(&pid, args[0], nullptr, nullptr, args.data(), env.data()) != 0) return -1;
    return pid;
  }
  // The next message within timeout_us; "" on timeout.
  std::string next(long long timeout_us) {
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(timeout_us / 1000)) <= 0) return std::string();
    char buf[512];
    const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
    return n > 0 ? std::string(buf, static_cast<std::size_t>(n)) : std::string();
  }

 private:
  std::string name_;
  int fd_ = -1;
  bool ok_ = false;
};

bool exited(pid_t pid, int* status) { return ::waitpid(pid, status, WNOHANG) == pid; }

// Waits for READY=1 (the state is sized and initialised first: slow under sanitizers or
// an emulator).
bool wait_ready(Manager& m, pid_t pid, std::string* why) {
  const long long deadline = now_us() + 120000000LL;
  while (now_us() < deadline) {
    const std::string msg = m.next(200000);
    if (msg.compare(0, 8, "READY=1\n") == 0 || msg == "READY=1") return true;
    int status = 0;
    if (exited(pid, &status)) {
      *why = "sdpslamd ended before READY=1 (status " + std::to_string(status) + ")";
      return false;
    }
  }
  *why = "no READY=1 within 120 s";
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: sdpslamd_watchdog WORK_DIR SDPSLAMD [PREFIX...]\n");
    return 2;
  }
  const std::string work = argv[1];
  ::mkdir(work.c_str(), 0755);
  // No sensor is there: the laser's device does not exist and the CAN interface neither;
  // sdpslamd retries both from its loop, which is what the watchdog watches.
  const std::string ini = work + "/sdpslamd.ini";
  if (std::FILE* f = std::fopen(ini.c_str(), "w")) {
    std::fprintf(f, "[can]\ninterface = sdpslamnone0\n[laser]\ndevice = %s/no-laser\n[slam]\nmode = sdp\n", work.c_str());
    std::fclose(f);
  } else {
    return fail("cannot write " + ini);
  }
  std::vector<std::string> cmd;
  for (int i = 3; i < argc; ++i) cmd.emplace_back(argv[i]);
  cmd.emplace_back(argv[2]);
  for (const char* a : {"--config", ini.c_str(), "--out"}) cmd.emplace_back(a);
  cmd.push_back(work + "/out");

  // A path, not the abstract namespace: qemu-user rewrites abstract socket addresses.
  const std::string name = work + "/notify.sock";
  Manager m(name);
  if (!m.ok()) return fail("cannot listen on " + name + " (longer than a socket address holds?)");
  ::signal(SIGPIPE, SIG_IGN);

  // 1-3: ready, pings while running, silence and SIGABRT when stalled.
  pid_t pid = m.start(cmd);
  if (pid < 0) return fail("fork");
  std::string why;
  if (!wait_ready(m, pid, &why)) {
    ::kill(pid, SIGKILL);
    return fail(why);
  }
  long long last = now_us();
  long long worst_gap = 0;
  int pings = 0;
  for (const long long end = last + 4000000LL; now_us() < end;) {
    const std::string msg = m.next(kWatchdogUs);
    const long long t = now_us();
    if (msg == "WATCHDOG=1") {
      worst_gap = t - last > worst_gap ? t - last : worst_gap;
      last = t;
      ++pings;
    } else if (msg.empty()) {
      ::kill(pid, SIGKILL);
      return fail("no WATCHDOG=1 for " + std::to_string(kWatchdogUs) + " us from a running loop: systemd would kill it");
    }
  }
  std::printf("running: %d pings in 4 s, longest gap %.3f s (timeout %.1f s)\n", pings, 1e-6 * static_cast<double>(worst_gap),
              1e-6 * static_cast<double>(kWatchdogUs));
  if (pings < 4) {
    ::kill(pid, SIGKILL);
    return fail("fewer than 4 pings in 4 s");
  }
  ::kill(pid, SIGSTOP);  // the loop stalls
  while (!m.next(1000).empty()) {}  // what was already on its way
  const std::string during = m.next(kWatchdogUs + kWatchdogUs / 2);
  if (!during.empty()) {
    ::kill(pid, SIGKILL);
    return fail("a stalled process sent '" + during + "'");
  }
  ::kill(pid, SIGABRT);  // the watchdog timeout expired: what systemd sends (WatchdogSignal=)
  ::kill(pid, SIGCONT);
  int status = 0;
  if (::waitpid(pid, &status, 0) != pid) return fail("waitpid");
  if (!(WIFSIGNALED(status) && WTERMSIG(status) == SIGABRT)) {
    return fail("the stalled process did not end by SIGABRT (status " + std::to_string(status) + ")");
  }
  std::printf("stalled: no ping for %.1f s, ended by SIGABRT as systemd's watchdog ends it\n",
              1.5e-6 * static_cast<double>(kWatchdogUs));

  // 4: a clean stop.
  pid = m.start(cmd);
  if (pid < 0) return fail("fork");
  if (!wait_ready(m, pid, &why)) {
    ::kill(pid, SIGKILL);
    return fail(why);
  }
  ::kill(pid, SIGTERM);
  bool stopping = false;
  const long long deadline = now_us() + 60000000LL;
  while (!exited(pid, &status)) {
    if (now_us() > deadline) {
      ::kill(pid, SIGKILL);
      return fail("no exit within 60 s of SIGTERM");
    }
    stopping = stopping || m.next(100000) == "STOPPING=1";
  }
  for (std::string msg = m.next(100000); !msg.empty(); msg = m.next(100000)) stopping = stopping || msg == "STOPPING=1";
  if (!stopping) return fail("no STOPPING=1 after SIGTERM");
  if (!(WIFEXITED(status) && WEXITSTATUS(status) == 0)) {
    return fail("SIGTERM did not end with exit 0 (status " + std::to_string(status) + ")");
  }
  std::printf("stopped: STOPPING=1 and exit 0\n");
  return 0;
}
