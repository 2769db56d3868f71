#pragma once
// Sensor emulators on pseudo-terminals for the driver tests: each owns a pty master,
// exposes the slave through a symlink (like a udev name), speaks the sensor's protocol
// from a thread, and injects faults on request. unplug() closes the pty (the driver sees
// a hang-up); replug() makes a new pty and moves the symlink to it.
#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "sdpslam/drivers/lms2xx.h"

namespace sdpslam::test {

class PtyDevice {
 public:
  explicit PtyDevice(const std::string& link_path);
  virtual ~PtyDevice();
  void start();
  void stop();
  void unplug();
  void replug();
  const std::string& link_path() const { return link_; }
  int slave_fd() const { return slave_; }
  // Writes given up part-way because the driver read nothing for 2 s (a cut message).
  std::uint32_t sends_cut() const { return sends_cut_.load(); }

 protected:
  virtual void on_bytes(const std::uint8_t* data, std::size_t n) = 0;
  virtual void tick() = 0;           // called every ~2 ms while plugged
  virtual void on_replug() {}
  void send(const std::uint8_t* data, std::size_t n);
  void send(const std::string& s) { send(reinterpret_cast<const std::uint8_t*>(s.data()), s.size()); }
  std::uint64_t now_ms() const;

 private:
  void open_pty();
  void close_pty();
  void run();
  std::string link_;
  int master_ = -1;
  int slave_ = -1;
  std::mutex mutex_;
  std::atomic<bool> running_{false};
  std::atomic<std::uint32_t> sends_cut_{0U};
  std::thread thread_;
};

// Hokuyo URG-04LX-UG01 speaking SCIP 2.0 (already in 2.0: answers SCIP2.0 with 0E).
// Scan n carries value[0] = 1000 + n % 1000 and value[i] = urg_value(n, i).
class UrgEmulator final : public PtyDevice {
 public:
  enum Fault : int { kNone, kCorruptData, kTruncateLine, kDropLine, kGarbage };
  explicit UrgEmulator(const std::string& link, std::uint32_t period_ms = 10U);
  ~UrgEmulator() override { stop(); }
  static std::uint32_t value(std::uint32_t scan, std::uint32_t i);
  void inject(Fault f) { fault_.store(f); }
  // Id (value[0] − 1000) of the scan the last injected fault hit; −1 before one did.
  int faulted_scan() const { return faulted_scan_.load(); }
  std::uint32_t scans_sent() const { return scans_sent_.load(); }
  std::uint32_t md_commands() const { return md_commands_.load(); }

 private:
  void on_bytes(const std::uint8_t* data, std::size_t n) override;
  void tick() override;
  void on_replug() override;
  void handle(const std::string& cmd);
  void send_scan();
  std::string line_;
  bool laser_on_ = false;
  bool streaming_ = false;
  std::string md_echo_;
  std::uint32_t period_ms_;
  std::uint64_t next_scan_ms_ = 0U;
  std::uint32_t scan_no_ = 0U;
  std::atomic<int> fault_{kNone};
  std::atomic<int> faulted_scan_{-1};
  std::atomic<std::uint32_t> scans_sent_{0U};
  std::atomic<std::uint32_t> md_commands_{0U};
  std::uint64_t rng_ = 0x9E3779B97F4A7C15ULL;
};

// SICK LMS2xx: 9600 baud at power-on, baud switch, variant, streaming B0 (361 mm values
// for 180/0.5). While the host tty's speed differs from the scanner's, bytes are lost
// both ways, as on a real line.
class SickEmulator final : public PtyDevice {
 public:
  enum Fault : int { kNone, kCorruptCrc, kTruncateTelegram, kGarbage, kNakNextRequest };
  explicit SickEmulator(const std::string& link, std::uint32_t period_ms = 10U);
  ~SickEmulator() override { stop(); }
  static std::uint16_t value(std::uint32_t scan, std::uint32_t i);  // raw word incl. flags
  void inject(Fault f) { fault_.store(f); }
  // Id (value[0] − 1000) of the telegram the last injected fault hit (kNakNextRequest
  // hits a request, not a telegram); −1 before one did.
  int faulted_scan() const { return faulted_scan_.load(); }
  std::uint32_t baud() const { return baud_.load(); }
  std::uint32_t scans_sent() const { return scans_sent_.load(); }
  std::uint32_t naks_sent() const { return naks_sent_.load(); }

 private:
  void on_bytes(const std::uint8_t* data, std::size_t n) override;
  void tick() override;
  void on_replug() override;
  bool line_ok() const;
  void reply(const std::vector<std::uint8_t>& body);
  std::vector<std::uint8_t> b0_telegram();
  drivers::lms2xx::Parser parser_{drivers::lms2xx::Parser::Source::kHost};
  std::atomic<std::uint32_t> baud_{9600U};
  bool streaming_ = false;
  std::uint32_t period_ms_;
  std::uint64_t next_scan_ms_ = 0U;
  std::uint32_t scan_no_ = 0U;
  std::atomic<int> fault_{kNone};
  std::atomic<int> faulted_scan_{-1};
  std::atomic<std::uint32_t> scans_sent_{0U};
  std::atomic<std::uint32_t> naks_sent_{0U};
  std::vector<std::uint8_t> pending_half_;
  std::uint64_t rng_ = 0xD1B54A32D192ED03ULL;
};

}  // namespace sdpslam::test
