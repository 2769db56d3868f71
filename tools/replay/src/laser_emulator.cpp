#include "sdpslam/replay/laser_emulator.h"

#include <fcntl.h>
#include <pty.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "sdpslam/drivers/lms2xx.h"
#include "sdpslam/drivers/scip2.h"
#include "sdpslam/drivers/serial_port.h"

namespace sdpslam::replay {

namespace scip2 = drivers::scip2;
namespace lms2xx = drivers::lms2xx;

// ------------------------------------------------------------------ common scheduling
LaserEngine::LaserEngine(const std::vector<ReplayScan>& scans, const ReplayTimeline& timeline)
    : scans_(scans), timeline_(timeline) {}

std::int64_t LaserEngine::next_wake_us() const {
  if (done()) return INT64_MAX;
  return timeline_.due_us(scans_[next_scan_].stamp_us) + send_delay_us();
}

void LaserEngine::advance(std::int64_t now_us, std::uint32_t host_baud) {
  while (!done()) {
    const std::int64_t send_us = timeline_.due_us(scans_[next_scan_].stamp_us) + send_delay_us();
    if (send_us > now_us) return;
    const std::size_t k = next_scan_++;
    if (!streaming()) {
      ++stats_.scans_not_requested;
      continue;
    }
    if (!done() && timeline_.due_us(scans_[next_scan_].stamp_us) + send_delay_us() <= now_us) {
      ++stats_.scans_dropped;  // the next one is due already: this one is history
      continue;
    }
    if (!emit_scan(scans_[k], send_us, host_baud)) {
      ++stats_.scans_dropped;  // the line cannot carry it (SICK: host at another speed)
      continue;
    }
    ++stats_.scans_served;
    const std::int64_t late = now_us - send_us;
    if (late > stats_.max_lateness_us) stats_.max_lateness_us = late;
    if (late > late_threshold_us) ++stats_.scans_late;
  }
}

// ------------------------------------------------------------------ SCIP 2.0
bool scip_geometry_for(const ScanGeometry& g, std::uint32_t beam_count, ScipGeometry* out,
                       std::string* error) {
  constexpr double kTwoPi = 6.283185307179586;
  const double d = static_cast<double>(g.angle_increment_rad);
  const double a0 = static_cast<double>(g.angle_min_rad);
  if (beam_count == 0 || !(d > 0.0)) {
    *error = "scan geometry has no beams or a non-positive angle increment";
    return false;
  }
  for (std::uint32_t k = 1; k <= 16; ++k) {
    const double ares = static_cast<double>(k) * kTwoPi / d;
    const double afrt = static_cast<double>(k) * -a0 / d;
    if (std::fabs(ares - std::round(ares)) > 1e-3 || std::fabs(afrt - std::round(afrt)) > 1e-3 ||
        std::round(afrt) < 0.0) {
      continue;
    }
    ScipGeometry geo;
    geo.ares = static_cast<std::uint32_t>(std::lround(ares));
    geo.afrt = static_cast<std::uint32_t>(std::lround(afrt));
    geo.steps_per_beam = k;
    geo.beam_count = beam_count;
    if (geo.ares == 1024U && k == 1U && geo.afrt == 340U) {  // the URG-04LX's own grid
      geo.afrt = 384U;
      geo.amin = 44U;
    }
    geo.amax = geo.amin + k * beam_count - 1U;
    geo.dmax_mm = scip_value_mm(g.range_max_m);
    if (geo.dmax_mm < geo.dmin_mm) geo.dmax_mm = geo.dmin_mm;
    *out = geo;
    return true;
  }
  *error = "beam grid (angle_min " + std::to_string(a0) + " rad, increment " + std::to_string(d) +
           " rad) does not fall on integer SCIP steps for any steps-per-beam up to 16";
  return false;
}

std::uint32_t scip_value_mm(float range_m) {
  if (!(range_m > 0.0F)) return 0U;  // 0, negative, NaN: no information
  const double mm = std::round(static_cast<double>(range_m) * 1000.0);
  if (mm >= 262143.0) return 262143U;  // largest 3-char value
  return static_cast<std::uint32_t>(mm);
}

namespace {

std::string scip_line(const std::string& body) {
  return body + scip2::checksum(body.data(), body.size()) + "\n";
}
std::string param_line(const std::string& kv) {
  return kv + ";" + scip2::checksum(kv.data(), kv.size()) + "\n";
}
bool all_digits(const std::string& s, std::size_t pos, std::size_t n) {
  if (s.size() < pos + n) return false;
  for (std::size_t i = pos; i < pos + n; ++i) {
    if (s[i] < '0' || s[i] > '9') return false;
  }
  return true;
}
std::uint32_t digits(const std::string& s, std::size_t pos, std::size_t n) {
  std::uint32_t v = 0;
  for (std::size_t i = pos; i < pos + n; ++i) v = v * 10U + static_cast<std::uint32_t>(s[i] - '0');
  return v;
}

}  // namespace

ScipEngine::ScipEngine(const std::vector<ReplayScan>& scans, const ReplayTimeline& timeline,
                       const ScipGeometry& geometry)
    : LaserEngine(scans, timeline), geo_(geometry) {}

void ScipEngine::reply(const std::string& echo, const char* status, const std::string& payload) {
  std::string st(status);
  // The SCIP1.1 answer to "SCIP2.0" is a bare "0" without checksum.
  put(echo + "\n" + (st == "0" ? st + "\n" : scip_line(st)) + payload + "\n");
}

void ScipEngine::on_host_bytes(const std::uint8_t* data, std::size_t n, std::int64_t, std::uint32_t) {
  for (std::size_t i = 0; i < n; ++i) {
    const char c = static_cast<char>(data[i]);
    if (c == '\n' || c == '\r') {
      if (!line_.empty()) handle(line_);
      line_.clear();
    } else if (line_.size() < scip2::kMaxCommandChars) {
      line_.push_back(c);
    }
  }
}

void ScipEngine::handle(const std::string& line) {
  // Optional ";text" is echoed back unchanged but not part of the command.
  const std::string cmd = line.substr(0, line.find(';'));
  ++stats_.commands;
  if (cmd == "SCIP2.0") {
    reply(line, scip2_ ? "0E" : "0");
    scip2_ = true;
  } else if (cmd == "VV") {
    reply(line, "00",
          param_line("VEND:sdpslam") + param_line("PROD:sdpslam replay SCIP 2.0 laser") +
              param_line("FIRM:1.0") + param_line("PROT:SCIP 2.0") + param_line("SERI:R0000001"));
  } else if (cmd == "PP") {
    reply(line, "00",
          param_line("MODL:sdpslam replay") + param_line("DMIN:" + std::to_string(geo_.dmin_mm)) +
              param_line("DMAX:" + std::to_string(geo_.dmax_mm)) + param_line("ARES:" + std::to_string(geo_.ares)) +
              param_line("AMIN:" + std::to_string(geo_.amin)) + param_line("AMAX:" + std::to_string(geo_.amax)) +
              param_line("AFRT:" + std::to_string(geo_.afrt)) + param_line("SCAN:" + std::to_string(geo_.scan_rpm)));
  } else if (cmd == "II") {
    reply(line, "00",
          param_line("MODL:sdpslam replay") + param_line(std::string("LASR:") + (laser_on_ ? "ON" : "OFF")) +
              param_line("SCSP:" + std::to_string(geo_.scan_rpm)) + param_line("MESM:Log replay") +
              param_line("SBPS:USB only") + param_line("STAT:Sensor works well."));
  } else if (cmd == "BM") {
    reply(line, laser_on_ ? "02" : "00");
    laser_on_ = true;
  } else if (cmd == "QT") {
    streaming_ = false;
    laser_on_ = false;
    reply(line, "00");
  } else if (cmd == "RS") {
    streaming_ = false;
    laser_on_ = false;
    reply(line, "00");
  } else if ((cmd.rfind("MD", 0) == 0 || cmd.rfind("MS", 0) == 0) && cmd.size() == 15 && all_digits(cmd, 2, 13)) {
    const std::uint32_t start = digits(cmd, 2, 4), end = digits(cmd, 6, 4), cluster = digits(cmd, 10, 2);
    if (start < geo_.amin || start > geo_.amax) {
      reply(line, "04");  // starting step out of range
    } else if (end < start || end > geo_.amax) {
      reply(line, "05");  // end step out of range
    } else {
      md_cmd_ = cmd;
      md_start_ = start;
      md_end_ = end;
      md_cluster_ = cluster == 0U ? 1U : cluster;  // SCIP: 00 means no grouping
      md_chars_ = cmd[1] == 'D' ? 3U : 2U;
      md_remaining_ = digits(cmd, 13, 2);
      laser_on_ = true;  // MD switches the laser on by itself
      streaming_ = true;
      reply(line, "00");
    }
  } else {
    ++stats_.unknown_commands;
    --stats_.commands;
    reply(line, "0E");
  }
}

std::uint32_t ScipEngine::step_value(const ReplayScan& s, std::uint32_t step) const {
  const std::uint32_t beam = (step - geo_.amin) / geo_.steps_per_beam;
  if (beam >= s.scan.beam_count) return 0U;
  return scip_value_mm(s.scan.ranges_m[beam]);
}

bool ScipEngine::emit_scan(const ReplayScan& s, std::int64_t send_us, std::uint32_t) {
  const std::uint32_t ts_ms =
      static_cast<std::uint32_t>(((send_us - timeline_.play_start_us) / 1000) & 0xFFFFFF);
  char enc[4];
  scip2::encode(ts_ms, 4, enc);
  std::string echo = md_cmd_;
  if (md_remaining_ > 0U) {  // finite request: the echo counts down the scans still to come
    --md_remaining_;
    echo[13] = static_cast<char>('0' + md_remaining_ / 10U);
    echo[14] = static_cast<char>('0' + md_remaining_ % 10U);
  }
  std::string out = echo + "\n" + scip_line("99") + scip_line(std::string(enc, 4));
  std::string data;
  const std::uint32_t cap = md_chars_ == 3U ? 262143U : 4095U;
  for (std::uint32_t first = md_start_; first <= md_end_; first += md_cluster_) {
    const std::uint32_t last = first + md_cluster_ - 1U < md_end_ ? first + md_cluster_ - 1U : md_end_;
    std::uint32_t best = step_value(s, first);
    for (std::uint32_t st = first + 1U; st <= last; ++st) {
      const std::uint32_t v = step_value(s, st);
      if (v >= scip2::kMinValidRangeMm && (best < scip2::kMinValidRangeMm || v < best)) best = v;
    }
    if (best > cap) best = cap;
    scip2::encode(best, md_chars_, enc);
    data.append(enc, md_chars_);
  }
  for (std::size_t pos = 0; pos < data.size(); pos += 64) out += scip_line(data.substr(pos, 64));
  out += "\n";
  put(out);
  if (md_cmd_.size() == 15 && md_remaining_ == 0U && digits(md_cmd_, 13, 2) != 0U) streaming_ = false;
  return true;
}

// ------------------------------------------------------------------ SICK LMS2xx
SickEngine::SickEngine(const std::vector<ReplayScan>& scans, const ReplayTimeline& timeline)
    : LaserEngine(scans, timeline) {}

std::int64_t SickEngine::send_delay_us() const {
  const std::uint32_t n = angle_deg_ == 180U ? (res_cdeg_ == 100U ? 181U : 361U)
                                             : (res_cdeg_ == 100U ? 101U : res_cdeg_ == 50U ? 201U : 401U);
  const std::int64_t bytes = 4 + 1 + 2 + 2 * static_cast<std::int64_t>(n) + 1 + 2;
  return bytes * 10 * 1000000 / static_cast<std::int64_t>(baud_);
}

void SickEngine::reply(const std::vector<std::uint8_t>& body) {
  std::uint8_t t[lms2xx::kMaxTelegram];
  const std::uint8_t ack = lms2xx::kAckByte;
  put(&ack, 1);
  put(t, lms2xx::build_telegram(0x80U, body.data(), body.size(), t, sizeof t));
}

void SickEngine::on_host_bytes(const std::uint8_t* data, std::size_t n, std::int64_t, std::uint32_t host_baud) {
  if (host_baud != 0U && host_baud != baud_) {  // wrong speed: framing noise to the scanner
    stats_.bytes_lost_line_speed += n;
    return;
  }
  lms2xx::Parser& parser = parser_;
  std::size_t pos = 0;
  while (pos < n) {
    std::size_t used = 0;
    const auto ev = parser.feed(data + pos, n - pos, &used);
    pos += used;
    if (ev == lms2xx::Parser::Event::kTelegram) handle();
  }
}

void SickEngine::handle() {
  const lms2xx::Telegram& t = parser_.telegram();
  ++stats_.commands;
  if (t.command() == 0x20U && t.length == 2U) {
    const std::uint8_t mode = t.body[1];
    std::uint32_t rate = 0;
    switch (mode) {
      case 0x42: rate = 9600U; break;
      case 0x41: rate = 19200U; break;
      case 0x40: rate = 38400U; break;
      case 0x48: rate = 500000U; break;
      case 0x24: streaming_ = true; break;
      case 0x25: streaming_ = false; break;
      default:
        reply({0xA0U, 0x01U, 0x10U});  // mode not supported
        return;
    }
    reply({0xA0U, 0x00U, 0x10U});
    if (rate != 0U) baud_ = rate;  // after the reply went out at the old rate
  } else if (t.command() == 0x31U && t.length == 1U) {
    std::vector<std::uint8_t> body = {0xB1U};
    const char* version = "V02.10 sdpslam";
    body.insert(body.end(), version, version + std::strlen(version));
    body.push_back(0x10U);
    reply(body);
  } else if (t.command() == 0x3BU && t.length == 5U) {
    const auto angle = static_cast<std::uint16_t>(t.body[1] | (t.body[2] << 8));
    const auto res = static_cast<std::uint16_t>(t.body[3] | (t.body[4] << 8));
    const bool ok = (angle == 180U && (res == 100U || res == 50U)) ||
                    (angle == 100U && (res == 100U || res == 50U || res == 25U));
    if (ok) {
      angle_deg_ = angle;
      res_cdeg_ = res;
    }
    reply({0xBBU, static_cast<std::uint8_t>(ok ? 1U : 0U), t.body[1], t.body[2], t.body[3], t.body[4], 0x10U});
  } else {
    --stats_.commands;
    ++stats_.unknown_commands;
    const std::uint8_t nak = lms2xx::kNakByte;
    put(&nak, 1);
  }
}

std::vector<std::uint16_t> SickEngine::values_for(const RangeScan& s) const {
  constexpr double kDegToRad = 3.14159265358979323846 / 180.0;
  const std::uint32_t n = static_cast<std::uint32_t>(angle_deg_) * 100U / res_cdeg_ + 1U;
  std::vector<std::uint16_t> v(n, 0U);
  const double a0 = static_cast<double>(s.geometry.angle_min_rad);
  const double d = static_cast<double>(s.geometry.angle_increment_rad);
  for (std::uint32_t i = 0; i < n; ++i) {
    const double angle = (-static_cast<double>(angle_deg_) / 2.0 + static_cast<double>(i * res_cdeg_) / 100.0) * kDegToRad;
    if (!(d > 0.0)) break;
    const double j = std::round((angle - a0) / d);
    if (j < 0.0 || j >= static_cast<double>(s.beam_count)) continue;  // outside the log's view
    const auto b = static_cast<std::uint32_t>(j);
    if (s.classify(b) == RangeScan::Beam::kInvalid) continue;
    const std::uint32_t mm = scip_value_mm(s.ranges_m[b]);
    v[i] = static_cast<std::uint16_t>(mm >= lms2xx::kFirstErrorCode ? lms2xx::kFirstErrorCode : mm);
  }
  return v;
}

bool SickEngine::emit_scan(const ReplayScan& s, std::int64_t, std::uint32_t host_baud) {
  if (host_baud != 0U && host_baud != baud_) return false;  // the host hears noise only
  const std::vector<std::uint16_t> v = values_for(s.scan);
  std::vector<std::uint8_t> body = {0xB0U, static_cast<std::uint8_t>(v.size() & 0xFFU),
                                    static_cast<std::uint8_t>(((v.size() >> 8) & 0x03U) | 0x40U)};
  for (const std::uint16_t w : v) {
    body.push_back(static_cast<std::uint8_t>(w & 0xFFU));
    body.push_back(static_cast<std::uint8_t>(w >> 8));
  }
  body.push_back(0x10U);
  std::uint8_t t[lms2xx::kMaxTelegram];
  put(t, lms2xx::build_telegram(0x80U, body.data(), body.size(), t, sizeof t));
  return true;
}

// ------------------------------------------------------------------ pty
LaserPty::~LaserPty() {
  if (!link_.empty()) ::unlink(link_.c_str());
  if (master_ >= 0) ::close(master_);
  if (slave_ >= 0) ::close(slave_);
}

bool LaserPty::open(const std::string& link_path, std::string* error) {
  char name[128] = {};
  if (::openpty(&master_, &slave_, name, nullptr, nullptr) != 0) {
    *error = std::string("openpty: ") + std::strerror(errno);
    return false;
  }
  slave_name_ = name;
  termios tio{};
  if (::tcgetattr(slave_, &tio) == 0) {
    ::cfmakeraw(&tio);
    ::cfsetispeed(&tio, B9600);
    ::cfsetospeed(&tio, B9600);
    ::tcsetattr(slave_, TCSANOW, &tio);
  }
  ::fcntl(master_, F_SETFL, ::fcntl(master_, F_GETFL) | O_NONBLOCK);
  ::fcntl(master_, F_SETFD, FD_CLOEXEC);
  ::fcntl(slave_, F_SETFD, FD_CLOEXEC);
  struct stat st{};
  if (::lstat(link_path.c_str(), &st) == 0) {
    if (!S_ISLNK(st.st_mode)) {
      *error = link_path + ": exists and is not a symlink; refusing to replace it";
      return false;
    }
    ::unlink(link_path.c_str());
  }
  if (::symlink(name, link_path.c_str()) != 0) {
    *error = link_path + ": symlink: " + std::strerror(errno);
    return false;
  }
  link_ = link_path;
  return true;
}

std::uint32_t LaserPty::host_baud() const { return slave_ >= 0 ? drivers::tty_baud_rate(slave_) : 0U; }

void LaserPty::pump(LaserEngine& engine, std::int64_t now_us) {
  if (master_ < 0) return;
  const std::uint32_t baud = host_baud();
  std::uint8_t buf[512];
  for (;;) {
    const ssize_t n = ::read(master_, buf, sizeof buf);
    if (n <= 0) break;
    engine.on_host_bytes(buf, static_cast<std::size_t>(n), now_us, baud);
  }
  engine.advance(now_us, baud);
  std::vector<std::uint8_t>& out = engine.output();
  if (!out.empty()) {
    queued_.insert(queued_.end(), out.begin(), out.end());
    out.clear();
  }
  while (!queued_.empty()) {
    const ssize_t w = ::write(master_, queued_.data(), queued_.size());
    if (w <= 0) break;  // the slave's input queue is full: the host is behind
    queued_.erase(queued_.begin(), queued_.begin() + w);
  }
  if (queued_.size() > kMaxQueued) {
    bytes_dropped_ += queued_.size() - kMaxQueued;
    queued_.erase(queued_.begin(), queued_.end() - static_cast<std::ptrdiff_t>(kMaxQueued));
  }
}

}  // namespace sdpslam::replay
