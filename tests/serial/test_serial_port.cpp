// SerialPort on pseudo-terminals: raw I/O, rates, hang-up detection, re-open.
#include <CppUTest/TestHarness.h>

#include <fcntl.h>
#include <pty.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>

#include "sdpslam/drivers/linux_clock.h"
#include "sdpslam/drivers/serial_port.h"
#include "shared_data.h"

using sdpslam::drivers::SerialOptions;
using sdpslam::drivers::SerialPort;
using sdpslam::hal::StreamState;

namespace {

struct Pty {
  int master = -1;
  int slave = -1;
  std::string link;
  explicit Pty(const std::string& link_path) : link(link_path) { plug(); }
  void plug() {
    char name[128];
    CHECK(openpty(&master, &slave, name, nullptr, nullptr) == 0);
    const std::string tmp = link + ".new";
    ::unlink(tmp.c_str());
    CHECK(::symlink(name, tmp.c_str()) == 0);
    CHECK(::rename(tmp.c_str(), link.c_str()) == 0);
  }
  void unplug() {
    ::close(master);
    ::close(slave);
    master = slave = -1;
  }
  ~Pty() {
    if (master >= 0) unplug();
    ::unlink(link.c_str());
  }
};

// What a driver does: wait, then read (a hung-up tty polls readable; read() says why).
int pump(SerialPort& port, std::int64_t timeout_us) {
  std::uint8_t buf[64];
  (void)port.wait_readable(timeout_us);
  return port.read(buf, sizeof buf);
}

SerialOptions options(const std::string& path, std::uint32_t baud) {
  SerialOptions o;
  o.path = path.c_str();
  o.baud = baud;
  o.reopen_interval_us = 50000;
  return o;
}

}  // namespace

TEST_GROUP(SerialPort) {
  sdpslam::drivers::LinuxMonotonicClock clock;
  std::string dir;
  void setup() override { dir = sdpslam::test::make_temp_dir("serialport"); }
};

TEST(SerialPort, open_of_missing_device_fails_naming_step_and_errno) {
  const std::string path = dir + "/nothing";
  SerialOptions o = options(path, 9600);
  o.reopen = false;
  SerialPort port(o, clock);
  CHECK_FALSE(port.open());
  STRCMP_EQUAL("open", port.last_error_step());
  LONGS_EQUAL(ENOENT, port.last_errno());
  CHECK(port.state() == StreamState::kClosed);
  LONGS_EQUAL(-1, port.read(nullptr, 0) < 0 ? -1 : 0);
}

TEST(SerialPort, read_returns_zero_when_nothing_waits_and_bytes_round_trip_raw) {
  Pty pty(dir + "/tty0");
  const std::string path = pty.link;
  SerialPort port(options(path, 115200), clock);
  CHECK(port.open());
  std::uint8_t buf[16];
  LONGS_EQUAL(0, port.read(buf, sizeof buf));
  const std::uint8_t raw[] = {'\r', '\n', 0x03, 0x11, 0x13, 0xFF};  // no CR/LF mapping, no XON/XOFF, no ISIG
  CHECK(::write(pty.master, raw, sizeof raw) == sizeof raw);
  LONGS_EQUAL(1, port.wait_readable(200000));
  LONGS_EQUAL(sizeof raw, port.read(buf, sizeof buf));
  MEMCMP_EQUAL(raw, buf, sizeof raw);
  LONGS_EQUAL(3, port.write(reinterpret_cast<const std::uint8_t*>("QT\n"), 3));
  char back[8] = {};
  usleep(10000);
  LONGS_EQUAL(3, ::read(pty.master, back, sizeof back));
  STRCMP_EQUAL("QT\n", back);
}

TEST(SerialPort, wait_readable_times_out_with_zero) {
  Pty pty(dir + "/tty1");
  SerialPort port(options(pty.link, 9600), clock);
  CHECK(port.open());
  const std::int64_t t0 = clock.now_us();
  LONGS_EQUAL(0, port.wait_readable(30000));
  CHECK(clock.now_us() - t0 >= 29000);
}

TEST(SerialPort, standard_and_termios2_rates_are_set_and_read_back) {
  Pty pty(dir + "/tty2");
  SerialPort port(options(pty.link, 750000), clock);
  CHECK(port.open());
  LONGS_EQUAL(750000, sdpslam::drivers::tty_baud_rate(port.fd()));
  CHECK(port.set_baud_rate(500000));
  LONGS_EQUAL(500000, sdpslam::drivers::tty_baud_rate(port.fd()));
  CHECK(port.set_baud_rate(250000));
  LONGS_EQUAL(250000, port.baud_rate());
  LONGS_EQUAL(250000, sdpslam::drivers::tty_baud_rate(port.fd()));
  CHECK(sdpslam::drivers::is_standard_baud(500000));
  CHECK_FALSE(sdpslam::drivers::is_standard_baud(750000));
}

TEST(SerialPort, flush_input_discards_pending_bytes) {
  Pty pty(dir + "/tty3");
  SerialPort port(options(pty.link, 9600), clock);
  CHECK(port.open());
  CHECK(::write(pty.master, "stale", 5) == 5);
  usleep(10000);
  port.flush_input();
  std::uint8_t buf[8];
  LONGS_EQUAL(0, port.read(buf, sizeof buf));
  LONGS_EQUAL(1, port.stats().flush_count);
}

TEST(SerialPort, closing_the_master_is_a_hangup_and_read_goes_negative) {
  Pty pty(dir + "/tty4");
  SerialPort port(options(pty.link, 9600), clock);
  CHECK(port.open());
  pty.unplug();
  std::uint8_t buf[8];
  (void)port.wait_readable(20000);
  CHECK(port.read(buf, sizeof buf) < 0);
  CHECK(port.state() == StreamState::kHungUp);
  LONGS_EQUAL(1, port.stats().hangup_count);
  LONGS_EQUAL(-1, port.fd());
}

TEST(SerialPort, reopens_when_the_symlink_points_at_a_new_device) {
  Pty pty(dir + "/tty5");
  SerialPort port(options(pty.link, 750000), clock);
  CHECK(port.open());
  pty.unplug();
  (void)pump(port, 20000);
  CHECK(port.state() == StreamState::kHungUp);
  LONGS_EQUAL(-1, port.wait_readable(60000));  // path gone: attempts fail
  pty.plug();
  CHECK(::write(pty.master, "x", 1) == 1);
  const std::int64_t t0 = clock.now_us();
  while (port.state() != StreamState::kOpen && clock.now_us() - t0 < 1000000) (void)pump(port, 20000);
  CHECK(port.state() == StreamState::kOpen);
  LONGS_EQUAL(2, port.stats().open_count);
  LONGS_EQUAL(750000, sdpslam::drivers::tty_baud_rate(port.fd()));
}

TEST(SerialPort, reopen_attempts_are_rate_limited) {
  Pty pty(dir + "/tty6");
  SerialPort port(options(pty.link, 9600), clock);
  CHECK(port.open());
  pty.unplug();
  ::unlink(pty.link.c_str());
  const std::int64_t t0 = clock.now_us();
  while (clock.now_us() - t0 < 260000) (void)pump(port, 5000);
  CHECK(port.stats().reopen_attempt_count >= 3);
  CHECK(port.stats().reopen_attempt_count <= 6);  // 50 ms interval over 260 ms
}
