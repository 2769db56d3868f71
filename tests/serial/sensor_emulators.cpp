#include "sensor_emulators.h"

#include <fcntl.h>
#include <poll.h>
#include <pty.h>
#include <termios.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>

#include "sdpslam/drivers/scip2.h"
#include "sdpslam/drivers/serial_port.h"

namespace sdpslam::test {

namespace scip2 = drivers::scip2;
namespace lms2xx = drivers::lms2xx;

namespace {
std::uint64_t xorshift(std::uint64_t& s) {
  s ^= s << 13U;
  s ^= s >> 7U;
  s ^= s << 17U;
  return s;
}
std::string scip_line(const std::string& data) { return data + scip2::checksum(data.data(), data.size()) + "\n"; }
std::string param_line(const std::string& kv) {
  return kv + ";" + scip2::checksum(kv.data(), kv.size()) + "\n";
}
}  // namespace

PtyDevice::PtyDevice(const std::string& link_path) : link_(link_path) { open_pty(); }

PtyDevice::~PtyDevice() {
  stop();
  close_pty();
  ::unlink(link_.c_str());
}

void PtyDevice::open_pty() {
  char name[128] = {};
  if (::openpty(&master_, &slave_, name, nullptr, nullptr) != 0) return;
  termios tio{};
  ::tcgetattr(slave_, &tio);
  ::cfmakeraw(&tio);
  ::tcsetattr(slave_, TCSANOW, &tio);
  ::fcntl(master_, F_SETFL, ::fcntl(master_, F_GETFL) | O_NONBLOCK);
  const std::string tmp = link_ + ".new";
  ::unlink(tmp.c_str());
  if (::symlink(name, tmp.c_str()) == 0) ::rename(tmp.c_str(), link_.c_str());
}

void PtyDevice::close_pty() {
  if (master_ >= 0) ::close(master_);
  if (slave_ >= 0) ::close(slave_);
  master_ = slave_ = -1;
}

void PtyDevice::start() {
  running_ = true;
  thread_ = std::thread([this] { run(); });
}

void PtyDevice::stop() {
  if (running_.exchange(false) && thread_.joinable()) thread_.join();
}

void PtyDevice::unplug() {
  std::lock_guard<std::mutex> lock(mutex_);
  close_pty();
}

void PtyDevice::replug() {
  std::lock_guard<std::mutex> lock(mutex_);
  open_pty();
  on_replug();
}

std::uint64_t PtyDevice::now_ms() const {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::milliseconds>(
                                        std::chrono::steady_clock::now().time_since_epoch())
                                        .count());
}

void PtyDevice::send(const std::uint8_t* data, std::size_t n) {
  // A full slave input queue means the driver is behind (a loaded machine can hold its
  // thread off for 100 ms and more): wait for it rather than cut the message, which would
  // look like a line fault to the driver. Give up only after 2 s without progress.
  std::size_t sent = 0;
  int idle_polls = 0;
  while (sent < n && master_ >= 0 && running_) {
    const ssize_t w = ::write(master_, data + sent, n - sent);
    if (w > 0) {
      sent += static_cast<std::size_t>(w);
      idle_polls = 0;
    } else if (++idle_polls > 4000) {
      break;
    } else {
      ::usleep(500);
    }
  }
  if (sent < n) ++sends_cut_;
}

void PtyDevice::run() {
  std::uint8_t buf[512];
  while (running_) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (master_ >= 0) {
        const ssize_t n = ::read(master_, buf, sizeof buf);
        if (n > 0) on_bytes(buf, static_cast<std::size_t>(n));
        tick();
      }
    }
    ::usleep(1000);
  }
}

// ---------------------------------------------------------------- URG

UrgEmulator::UrgEmulator(const std::string& link, std::uint32_t period_ms) : PtyDevice(link), period_ms_(period_ms) {}

std::uint32_t UrgEmulator::value(std::uint32_t scan, std::uint32_t i) {
  if (i == 0U) return 1000U + scan % 1000U;
  if (i % 50U == 0U) return (i / 50U) % 20U;  // error codes
  return 20U + (scan % 1000U * 31U + i * 7U) % 5000U;
}

void UrgEmulator::on_replug() {
  laser_on_ = false;
  streaming_ = false;
  line_.clear();
}

void UrgEmulator::on_bytes(const std::uint8_t* data, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) {
    if (data[i] == '\n') {
      handle(line_);
      line_.clear();
    } else if (line_.size() < 64) {
      line_.push_back(static_cast<char>(data[i]));
    }
  }
}

void UrgEmulator::handle(const std::string& cmd) {
  if (cmd == "SCIP2.0") {
    send("SCIP2.0\n0Ee\n\n");
  } else if (cmd == "QT") {
    streaming_ = false;
    laser_on_ = false;
    send("QT\n00P\n\n");
  } else if (cmd == "VV") {
    send("VV\n00P\n" + param_line("VEND:Hokuyo Automatic Co.,Ltd.") +
         param_line("PROD:SOKUIKI Sensor URG-04LX-UG01(Simple-URG)") + param_line("FIRM:3.4.03(17/Dec./2012)") +
         param_line("PROT:SCIP 2.0") + param_line("SERI:H1510998") + "\n");
  } else if (cmd == "PP") {
    send("PP\n00P\n" + param_line("MODL:URG-04LX-UG01(Hokuyo Automatic Co.,Ltd.)") + param_line("DMIN:20") +
         param_line("DMAX:5600") + param_line("ARES:1024") + param_line("AMIN:44") + param_line("AMAX:725") +
         param_line("AFRT:384") + param_line("SCAN:600") + "\n");
  } else if (cmd == "BM") {
    send(laser_on_ ? "BM\n02R\n\n" : "BM\n00P\n\n");
    laser_on_ = true;
  } else if (cmd.rfind("MD", 0) == 0 && cmd.size() == 15) {
    ++md_commands_;
    send(cmd + "\n00P\n\n");
    md_echo_ = cmd;
    streaming_ = laser_on_;
    next_scan_ms_ = now_ms() + period_ms_;
  } else {
    send(cmd + "\n0Ee\n\n");
  }
}

void UrgEmulator::tick() {
  if (!streaming_ || now_ms() < next_scan_ms_) return;
  next_scan_ms_ += period_ms_;
  send_scan();
}

void UrgEmulator::send_scan() {
  const int fault = fault_.exchange(kNone);
  if (fault != kNone) faulted_scan_.store(static_cast<int>(scan_no_ % 1000U));
  if (fault == kGarbage) {
    std::uint8_t junk[64];
    for (auto& b : junk) b = static_cast<std::uint8_t>(xorshift(rng_));
    send(junk, sizeof junk);
  }
  // Sensor time starts 300 ms before the 24-bit counter wraps, so the wrap is exercised.
  const std::uint32_t ts = static_cast<std::uint32_t>((16777216U - 300U + scan_no_ * period_ms_) & 0xFFFFFFU);
  char enc[4];
  scip2::encode(ts, 4, enc);
  std::string out = md_echo_ + "\n99b\n" + scip_line(std::string(enc, 4));
  std::string data;
  for (std::uint32_t i = 0; i < 682U; ++i) {
    scip2::encode(value(scan_no_, i), 3, enc);
    data.append(enc, 3);
  }
  for (std::size_t pos = 0, block = 0; pos < data.size(); pos += 64, ++block) {
    std::string line = scip_line(data.substr(pos, 64));
    if (block == 3 && fault == kCorruptData) line[10] = line[10] == '0' ? '1' : '0';
    if (block == 5 && fault == kTruncateLine) line = line.substr(0, 30) + "\n";
    if (block == 5 && fault == kDropLine) continue;
    out += line;
  }
  out += "\n";
  send(out);
  ++scan_no_;
  ++scans_sent_;
}

// ---------------------------------------------------------------- SICK

SickEmulator::SickEmulator(const std::string& link, std::uint32_t period_ms) : PtyDevice(link), period_ms_(period_ms) {}

std::uint16_t SickEmulator::value(std::uint32_t scan, std::uint32_t i) {
  if (i == 0U) return static_cast<std::uint16_t>(1000U + scan % 1000U);
  if (i % 40U == 0U) return 0U;                         // no echo
  if (i % 97U == 0U) return 0x1FFFU;                    // error code (overflow)
  const auto d = static_cast<std::uint16_t>(10U + (scan % 1000U * 31U + i * 7U) % 8000U);
  return static_cast<std::uint16_t>(i % 3U == 0U ? d | 0x2000U : d);  // a flag bit set
}

void SickEmulator::on_replug() {
  baud_ = 9600U;  // power-cycled scanner
  streaming_ = false;
  parser_.reset();
}

bool SickEmulator::line_ok() const { return drivers::tty_baud_rate(slave_fd()) == baud_.load(); }

void SickEmulator::reply(const std::vector<std::uint8_t>& body) {
  std::uint8_t t[lms2xx::kMaxTelegram];
  const std::uint8_t ack = lms2xx::kAckByte;
  send(&ack, 1);
  const std::size_t n = lms2xx::build_telegram(0x80U, body.data(), body.size(), t, sizeof t);
  send(t, n);
}

void SickEmulator::on_bytes(const std::uint8_t* data, std::size_t n) {
  if (!line_ok()) return;  // wrong speed: the scanner sees framing noise
  std::size_t pos = 0;
  while (pos < n) {
    std::size_t used = 0;
    const auto ev = parser_.feed(data + pos, n - pos, &used);
    pos += used;
    if (ev != lms2xx::Parser::Event::kTelegram) continue;
    if (fault_.load() == kNakNextRequest) {
      fault_.store(kNone);
      const std::uint8_t nak = lms2xx::kNakByte;
      send(&nak, 1);
      ++naks_sent_;
      continue;
    }
    const lms2xx::Telegram& t = parser_.telegram();
    if (t.command() == 0x20U && t.length == 2U) {
      const std::uint8_t mode = t.body[1];
      reply({0xA0U, 0x00U, 0x10U});
      switch (mode) {
        case 0x42: baud_ = 9600U; break;
        case 0x41: baud_ = 19200U; break;
        case 0x40: baud_ = 38400U; break;
        case 0x48: baud_ = 500000U; break;
        case 0x24: streaming_ = true; next_scan_ms_ = now_ms() + period_ms_; break;
        case 0x25: streaming_ = false; break;
        default: break;
      }
    } else if (t.command() == 0x3BU && t.length == 5U) {
      const bool ok = t.body[1] == 180U && t.body[3] == 50U;  // this unit only does 180/0.5
      reply({0xBBU, static_cast<std::uint8_t>(ok ? 1U : 0U), t.body[1], t.body[2], t.body[3], t.body[4], 0x10U});
    }
  }
}

std::vector<std::uint8_t> SickEmulator::b0_telegram() {
  std::vector<std::uint8_t> body = {0xB0U, 0x69U, 0x41U};  // 361 values, mm
  for (std::uint32_t i = 0; i < 361U; ++i) {
    const std::uint16_t w = value(scan_no_, i);
    body.push_back(static_cast<std::uint8_t>(w & 0xFFU));
    body.push_back(static_cast<std::uint8_t>(w >> 8U));
  }
  body.push_back(0x10U);
  std::vector<std::uint8_t> t(lms2xx::kMaxTelegram);
  t.resize(lms2xx::build_telegram(0x80U, body.data(), body.size(), t.data(), t.size()));
  ++scan_no_;
  return t;
}

void SickEmulator::tick() {
  if (!streaming_ || now_ms() < next_scan_ms_ || !line_ok()) return;
  next_scan_ms_ += period_ms_;
  const int fault = fault_.load() == kNakNextRequest ? kNone : fault_.exchange(kNone);
  if (fault != kNone) faulted_scan_.store(static_cast<int>(scan_no_ % 1000U));
  std::vector<std::uint8_t> t = b0_telegram();
  if (fault == kGarbage) {
    std::uint8_t junk[48];
    for (auto& b : junk) b = static_cast<std::uint8_t>(xorshift(rng_));
    junk[5] = lms2xx::kStxByte;  // false telegram starts
    junk[30] = lms2xx::kStxByte;
    junk[31] = 0x80U;
    send(junk, sizeof junk);
  }
  if (fault == kCorruptCrc) t[100] ^= 0x40U;
  if (fault == kTruncateTelegram) t.resize(t.size() / 2);
  send(t.data(), t.size());
  ++scans_sent_;
}

}  // namespace sdpslam::test
