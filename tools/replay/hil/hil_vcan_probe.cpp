// Runs inside the virtual-CAN test machine (tests/hil): two SocketCanBus sockets on
// vcan0 pass frames both ways, then a CanOpenEncoderPair (SYNC producer) reads two
// emulated CiA 406 encoders that answer each SYNC with TPDO1 over the real kernel CAN
// stack. Prints one line per check; exit 0 iff all pass.
#include <cstdio>
#include <cstring>

#include "sdpslam/drivers/canopen_codec.h"
#include "sdpslam/drivers/canopen_encoder_pair.h"
#include "sdpslam/drivers/linux_clock.h"
#include "sdpslam/drivers/socketcan_bus.h"

namespace {

using namespace sdpslam;

int failures = 0;
void check(bool ok, const char* what) {
  std::printf("%s %s\n", ok ? "PASS" : "FAIL", what);
  if (!ok) ++failures;
}

bool receive_within(drivers::SocketCanBus& bus, hal::CanFrame& out, std::int64_t timeout_us) {
  drivers::LinuxMonotonicClock clock;
  const std::int64_t end = clock.now_us() + timeout_us;
  while (clock.now_us() < end) {
    if (bus.receive(out) == 1) return true;
    bus.wait_readable(10000);
  }
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  const char* iface = argc > 1 ? argv[1] : "vcan0";
  drivers::LinuxMonotonicClock clock;
  drivers::SocketCanOptions opt;
  std::snprintf(opt.interface_name, sizeof opt.interface_name, "%s", iface);
  drivers::SocketCanBus a(opt, clock);
  drivers::SocketCanBus b(opt, clock);
  check(a.state() == hal::CanBusState::kActive && b.state() == hal::CanBusState::kActive, "both sockets open on the vcan");
  check(a.kernel_timestamps_active(), "kernel receive timestamps (SO_TIMESTAMP) active");

  const std::uint8_t bytes[8] = {1, 2, 3, 4, 5, 6, 7, 8};
  const hal::CanFrame f = hal::CanFrame::standard(0x123, bytes, 8);
  check(a.send(f) == 1, "send standard frame");
  hal::CanFrame got;
  check(receive_within(b, got, 1000000) && got.id == 0x123 && got.dlc == 8 && std::memcmp(got.data, bytes, 8) == 0,
        "other socket receives it intact");
  check(got.stamp_us > 0 && got.stamp_us <= clock.now_us(), "kernel receive stamp mapped onto the monotonic clock");
  hal::CanFrame ext;
  ext.id = 0x1ABCDEF0u | hal::CanFrame::kExtendedFlag;
  ext.dlc = 2;
  ext.data[0] = 0xAA;
  ext.data[1] = 0x55;
  check(b.send(ext) == 1 && receive_within(a, got, 1000000) && got.id == ext.id && got.dlc == 2, "extended frame the other way");

  // CANopen encoder pair end to end: `a` is the host, `b` plays encoders 1 and 2.
  drivers::CanOpenEncoderOptions co;
  co.left_node = 1;
  co.right_node = 2;
  co.sync_period_us = 10000;
  drivers::CanOpenEncoderPair pair(a, clock, co);
  int started = 0;
  for (int i = 0; i < 100 && started != 1; ++i) started = pair.start();
  check(started == 1, "NMT start sent to both nodes");
  int nmt_seen = 0;
  std::uint32_t left = 1000, right = 4294967000u;  // the right counter wraps during the run
  std::uint32_t syncs = 0;
  // 50 SYNC periods. The emulated machine may be slow or starved by the host: it gets
  // 20 s for them, and the checks do not depend on its speed (at least 50 SYNCs, never
  // more than one per period).
  const std::int64_t t_start = clock.now_us();
  const std::int64_t end = t_start + 20000000;
  while (clock.now_us() < end && syncs < 50) {
    pair.update();
    hal::CanFrame in;
    while (b.receive(in) == 1) {
      drivers::canopen::NmtCommand cmd;
      std::uint8_t node = 0;
      if (drivers::canopen::decode_nmt(in, cmd, node) == drivers::CanDecodeError::kOk) ++nmt_seen;
      if (drivers::canopen::decode_sync(in) == drivers::CanDecodeError::kOk) {
        ++syncs;
        left += 7;
        right += 11;
        hal::CanFrame l, r;
        drivers::canopen::make_tpdo1_position(1, left, 4, l);
        drivers::canopen::make_tpdo1_position(2, right, 4, r);
        b.send(l);
        b.send(r);
      }
    }
    b.wait_readable(2000);
  }
  for (int i = 0; i < 20; ++i) {  // collect the last answers
    pair.update();
    a.wait_readable(2000);
  }
  const hal::WheelEncoderSample s = pair.latest();
  std::printf("syncs %u nmt %d left %u right %u positions %llu/%llu\n", syncs, nmt_seen, s.left.raw_count,
              s.right.raw_count, static_cast<unsigned long long>(pair.stats().positions[0]),
              static_cast<unsigned long long>(pair.stats().positions[1]));
  check(nmt_seen == 2, "encoders saw NMT start for nodes 1 and 2");
  const std::int64_t elapsed_us = clock.now_us() - t_start;
  check(syncs >= 50, "SYNC keeps being produced");
  check(static_cast<std::int64_t>(syncs) <= elapsed_us / co.sync_period_us + 1, "never more than one SYNC per period");
  check(s.left.raw_count == left && s.right.raw_count == right, "host holds the newest TPDO1 of both wheels");
  check(pair.stats().positions[0] == syncs && pair.stats().positions[1] == syncs, "one position per SYNC per wheel");
  check(pair.stats().decode_errors == 0 && a.stats().rx_overflows == 0, "no decode errors, no kernel drops");
  std::printf("hil_vcan_probe: %s\n", failures == 0 ? "OK" : "FAILED");
  return failures == 0 ? 0 : 1;
}
