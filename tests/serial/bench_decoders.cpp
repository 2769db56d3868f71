// Decode throughput of the two laser decoders on one core, against the sensors' own
// rates (URG-04LX 10 scans/s, LMS2xx 75 scans/s). Input: a synthetic MD stream of
// 682-value scans and 361-value B0 telegrams, built in memory with the codecs' own rules
// (so this runs without ../shared). Prints scans/s and MB/s.
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "sdpslam/drivers/lms2xx.h"
#include "sdpslam/drivers/scip2.h"

namespace scip2 = sdpslam::drivers::scip2;
namespace lms2xx = sdpslam::drivers::lms2xx;

namespace {

std::string scip_line(const std::string& d) { return d + scip2::checksum(d.data(), d.size()) + "\n"; }

std::vector<std::uint8_t> urg_stream(int scans) {
  std::string s;
  for (int k = 0; k < scans; ++k) {
    char e[4];
    scip2::encode(static_cast<std::uint32_t>(k * 100), 4, e);
    std::string out = "MD0044072501000\n99b\n" + scip_line(std::string(e, 4));
    std::string data;
    for (std::uint32_t i = 0; i < 682U; ++i) {
      scip2::encode(20U + (i * 7U + static_cast<std::uint32_t>(k)) % 5000U, 3, e);
      data.append(e, 3);
    }
    for (std::size_t p = 0; p < data.size(); p += 64) out += scip_line(data.substr(p, 64));
    s += out + "\n";
  }
  return std::vector<std::uint8_t>(s.begin(), s.end());
}

std::vector<std::uint8_t> sick_stream(int scans) {
  std::vector<std::uint8_t> s;
  for (int k = 0; k < scans; ++k) {
    std::vector<std::uint8_t> body = {0xB0, 0x69, 0x41};
    for (std::uint32_t i = 0; i < 361U; ++i) {
      const auto w = static_cast<std::uint16_t>((i * 13U + static_cast<std::uint32_t>(k)) % 8000U);
      body.push_back(static_cast<std::uint8_t>(w & 0xFFU));
      body.push_back(static_cast<std::uint8_t>(w >> 8U));
    }
    body.push_back(0x10);
    std::uint8_t t[lms2xx::kMaxTelegram];
    const std::size_t n = lms2xx::build_telegram(0x80, body.data(), body.size(), t, sizeof t);
    s.push_back(lms2xx::kAckByte);
    s.insert(s.end(), t, t + n);
  }
  return s;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

int main() {
  constexpr int kScans = 2000;
  constexpr int kRounds = 10;
  const auto urg = urg_stream(kScans);
  static scip2::Parser sp;
  std::uint64_t urg_scans = 0;
  std::uint64_t checksum = 0;
  auto t0 = std::chrono::steady_clock::now();
  for (int r = 0; r < kRounds; ++r) {
    std::size_t pos = 0;
    while (pos < urg.size()) {
      std::size_t used = 0;
      if (sp.feed(urg.data() + pos, urg.size() - pos, &used) == scip2::Parser::Event::kReply && sp.reply().is_scan) {
        ++urg_scans;
        checksum += sp.reply().values[340];
      }
      pos += used;
    }
  }
  const double urg_s = seconds_since(t0);
  const auto sick = sick_stream(kScans);
  static lms2xx::Parser lp;
  static lms2xx::MeasuredValues mv;
  std::uint64_t sick_scans = 0;
  t0 = std::chrono::steady_clock::now();
  for (int r = 0; r < kRounds; ++r) {
    std::size_t pos = 0;
    while (pos < sick.size()) {
      std::size_t used = 0;
      if (lp.feed(sick.data() + pos, sick.size() - pos, &used) == lms2xx::Parser::Event::kTelegram &&
          lms2xx::decode_b0(lp.telegram(), &mv) == lms2xx::B0Error::kNone) {
        ++sick_scans;
        checksum += mv.distance[180];
      }
      pos += used;
    }
  }
  const double sick_s = seconds_since(t0);
  const double urg_rate = static_cast<double>(urg_scans) / urg_s;
  const double sick_rate = static_cast<double>(sick_scans) / sick_s;
  std::printf("SCIP 2.0 MD (682 values, %zu B/scan): %llu scans in %.3f s = %.0f scans/s, %.1f MB/s, %.0fx the URG's 10 scans/s\n",
              urg.size() / kScans, static_cast<unsigned long long>(urg_scans), urg_s, urg_rate,
              static_cast<double>(urg.size()) * kRounds / urg_s / 1e6, urg_rate / 10.0);
  std::printf("LMS2xx B0  (361 values, %zu B/scan): %llu scans in %.3f s = %.0f scans/s, %.1f MB/s, %.0fx the LMS's 75 scans/s\n",
              sick.size() / kScans, static_cast<unsigned long long>(sick_scans), sick_s, sick_rate,
              static_cast<double>(sick.size()) * kRounds / sick_s / 1e6, sick_rate / 75.0);
  std::printf("(checksum %llu)\n", static_cast<unsigned long long>(checksum));
  return urg_scans == static_cast<std::uint64_t>(kScans) * kRounds && sick_scans == static_cast<std::uint64_t>(kScans) * kRounds ? 0 : 1;
}
