// Real SocketCAN through a vcan interface, when the kernel has one. Creates vcan0 if it
// is missing and we may; otherwise prints why and exits 77 (CTest: skipped).
#include <CppUTest/TestHarness.h>

#include <linux/can.h>
#include <net/if.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>

#include "sdpslam/drivers/linux_clock.h"
#include "sdpslam/drivers/socketcan_bus.h"

using namespace sdpslam;
using namespace sdpslam::drivers;

namespace {
bool vcan0_usable() {
  if (::if_nametoindex("vcan0") == 0) {
    if (std::system("ip link add dev vcan0 type vcan >/dev/null 2>&1") != 0) return false;
  }
  std::system("ip link set up vcan0 >/dev/null 2>&1");
  const int s = ::socket(PF_CAN, SOCK_RAW, CAN_RAW);
  if (s < 0) return false;
  ::close(s);
  return ::if_nametoindex("vcan0") != 0;
}
}  // namespace

TEST_GROUP(Vcan){};

TEST(Vcan, frames_cross_vcan0_with_kernel_timestamps_and_filters) {
  if (!vcan0_usable()) {
    std::printf("SKIP: no vcan in this kernel (or no permission to create vcan0)\n");
    std::fflush(stdout);
    std::_Exit(77);
  }
  LinuxMonotonicClock clock;
  SocketCanOptions rx_opt;
  std::snprintf(rx_opt.interface_name, sizeof rx_opt.interface_name, "vcan0");
  rx_opt.filters[0] = {0x185, 0x7FF};
  rx_opt.filter_count = 1;
  SocketCanOptions tx_opt = rx_opt;
  tx_opt.filter_count = 0;
  SocketCanBus rx(rx_opt, clock), tx(tx_opt, clock);
  CHECK(rx.state() == hal::CanBusState::kActive);
  CHECK_TRUE(rx.kernel_filter_active());
  const std::uint8_t pos[4] = {0x45, 0x23, 0x01, 0x00};
  LONGS_EQUAL(1, tx.send(hal::CanFrame::standard(0x186, pos, 4)));
  LONGS_EQUAL(1, tx.send(hal::CanFrame::standard(0x185, pos, 4)));
  const std::int64_t before = clock.now_us();
  LONGS_EQUAL(1, rx.wait_readable(1000000));
  hal::CanFrame got;
  LONGS_EQUAL(1, rx.receive(got));
  LONGS_EQUAL(0x185, got.id);  // 0x186 filtered in the kernel
  CHECK_TRUE(got.stamp_us <= clock.now_us() && got.stamp_us > before - 1000000);
  LONGS_EQUAL(0, rx.receive(got));
}
