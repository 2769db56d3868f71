// The SocketCAN driver's I/O loop against a real fd: socketpair(AF_UNIX, SOCK_SEQPACKET)
// carries 16-byte datagrams exactly as CAN_RAW does.
#include <CppUTest/TestHarness.h>

#include <linux/can/error.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <string>

#include "can_test_support.h"
#include "sdpslam/drivers/linux_clock.h"
#include "sdpslam/drivers/socketcan_bus.h"

using namespace sdpslam;
using namespace sdpslam::drivers;

namespace {
SocketCanOptions no_kernel_stamps() {
  SocketCanOptions o;
  o.kernel_timestamps = false;  // stamps from the fake clock
  return o;
}
hal::CanFrame data_frame(std::uint32_t id, std::uint8_t dlc) {
  hal::CanFrame f;
  f.id = id;
  f.dlc = dlc;
  for (std::uint8_t i = 0; i < dlc; ++i) f.data[i] = static_cast<std::uint8_t>(0xA0 + i);
  return f;
}
}  // namespace

TEST_GROUP(SocketCanBus) {
  test::FakeClock clock;
  test::SeqPacketPair pair;
};

TEST(SocketCanBus, adopted_fd_starts_active_and_tolerates_missing_can_options) {
  SocketCanBus bus(SocketCanBus::AdoptFd{pair.take_local()}, no_kernel_stamps(), clock);
  CHECK(bus.state() == hal::CanBusState::kActive);
  CHECK_TRUE(bus.adopted());
}

TEST(SocketCanBus, frame_sent_arrives_at_peer_unchanged) {
  SocketCanBus bus(SocketCanBus::AdoptFd{pair.take_local()}, no_kernel_stamps(), clock);
  const hal::CanFrame out = data_frame(0x185 | hal::CanFrame::kExtendedFlag, 8);
  LONGS_EQUAL(1, bus.send(out));
  hal::CanFrame got;
  LONGS_EQUAL(1, pair.peer_receive(got));
  UNSIGNED_LONGS_EQUAL(out.id, got.id);
  LONGS_EQUAL(8, got.dlc);
  MEMCMP_EQUAL(out.data, got.data, 8);
  LONGS_EQUAL(1, bus.stats().tx_frames);
}

TEST(SocketCanBus, frame_from_peer_is_received_and_stamped_on_the_clock) {
  SocketCanBus bus(SocketCanBus::AdoptFd{pair.take_local()}, no_kernel_stamps(), clock);
  clock.t_us = 4242;
  CHECK_TRUE(pair.peer_send(data_frame(0x705, 1)));
  hal::CanFrame got;
  LONGS_EQUAL(1, bus.receive(got));
  LONGS_EQUAL(0x705, got.id);
  LONGS_EQUAL(1, got.dlc);
  LONGS_EQUAL(0xA0, got.data[0]);
  LONGS_EQUAL(4242, got.stamp_us);
  LONGS_EQUAL(1, bus.stats().rx_frames);
}

TEST(SocketCanBus, nothing_pending_returns_zero_not_error) {
  SocketCanBus bus(SocketCanBus::AdoptFd{pair.take_local()}, no_kernel_stamps(), clock);
  hal::CanFrame got;
  LONGS_EQUAL(0, bus.receive(got));
  LONGS_EQUAL(0, bus.stats().rx_errors);
}

TEST(SocketCanBus, wait_readable_times_out_then_sees_a_frame) {
  SocketCanBus bus(SocketCanBus::AdoptFd{pair.take_local()}, no_kernel_stamps(), clock);
  LONGS_EQUAL(0, bus.wait_readable(1000));
  pair.peer_send(data_frame(0x080, 0));
  LONGS_EQUAL(1, bus.wait_readable(1000000));
}

TEST(SocketCanBus, twelve_byte_datagram_is_rejected_and_counted_then_reading_goes_on) {
  SocketCanBus bus(SocketCanBus::AdoptFd{pair.take_local()}, no_kernel_stamps(), clock);
  const unsigned char short_dgram[12] = {0x85, 0x01, 0, 0, 4, 0, 0, 0, 1, 2, 3, 4};
  CHECK_EQUAL(12, ::send(pair.peer, short_dgram, sizeof short_dgram, 0));
  pair.peer_send(data_frame(0x185, 4));
  hal::CanFrame got;
  got.id = 0x7FF;
  LONGS_EQUAL(-1, bus.receive(got));
  CHECK(bus.last_error() == SocketCanError::kBadLength);
  LONGS_EQUAL(1, bus.stats().bad_length_reads);
  LONGS_EQUAL(0x7FF, got.id);  // untouched
  CHECK(bus.state() == hal::CanBusState::kActive);
  LONGS_EQUAL(1, bus.receive(got));
  LONGS_EQUAL(0x185, got.id);
}

TEST(SocketCanBus, longer_datagram_is_rejected_too) {
  SocketCanBus bus(SocketCanBus::AdoptFd{pair.take_local()}, no_kernel_stamps(), clock);
  unsigned char big[72] = {};  // a CAN FD sized datagram
  ::send(pair.peer, big, sizeof big, 0);
  hal::CanFrame got;
  LONGS_EQUAL(-1, bus.receive(got));
  LONGS_EQUAL(1, bus.stats().bad_length_reads);
}

TEST(SocketCanBus, full_send_buffer_returns_try_later_and_counts) {
  SocketCanBus bus(SocketCanBus::AdoptFd{pair.take_local()}, no_kernel_stamps(), clock);
  int sent = 0, r = 1;
  for (int i = 0; i < 100000 && r == 1; ++i) {
    r = bus.send(data_frame(0x080, 0));
    if (r == 1) ++sent;
  }
  LONGS_EQUAL(0, r);  // EAGAIN on a full AF_UNIX queue: try later, not an error
  CHECK_TRUE(sent > 0);
  LONGS_EQUAL(1, bus.stats().tx_try_later);
  LONGS_EQUAL(0, bus.stats().tx_errors);
  CHECK(bus.state() == hal::CanBusState::kActive);
  hal::CanFrame drained;
  LONGS_EQUAL(1, pair.peer_receive(drained));  // room again after the peer reads
  LONGS_EQUAL(1, bus.send(data_frame(0x080, 0)));
}

TEST(SocketCanBus, peer_closed_puts_bus_down_on_receive) {
  SocketCanBus bus(SocketCanBus::AdoptFd{pair.take_local()}, no_kernel_stamps(), clock);
  pair.close_peer();
  hal::CanFrame got;
  LONGS_EQUAL(-1, bus.receive(got));
  CHECK(bus.state() == hal::CanBusState::kDown);
  CHECK(bus.last_error() == SocketCanError::kPeerClosed);
  LONGS_EQUAL(1, bus.stats().down_count);
  LONGS_EQUAL(-1, bus.wait_readable(1000));  // an adopted fd is never re-opened
}

TEST(SocketCanBus, peer_closed_makes_send_fail_without_sigpipe) {
  SocketCanBus bus(SocketCanBus::AdoptFd{pair.take_local()}, no_kernel_stamps(), clock);
  pair.close_peer();
  LONGS_EQUAL(-1, bus.send(data_frame(0x080, 0)));
  CHECK(bus.state() == hal::CanBusState::kDown);
  LONGS_EQUAL(1, bus.stats().tx_errors);
}

TEST(SocketCanBus, frame_with_dlc_above_eight_is_refused) {
  SocketCanBus bus(SocketCanBus::AdoptFd{pair.take_local()}, no_kernel_stamps(), clock);
  hal::CanFrame f = data_frame(0x123, 8);
  f.dlc = 9;
  LONGS_EQUAL(-1, bus.send(f));
  hal::CanFrame got;
  LONGS_EQUAL(0, pair.peer_receive(got));
}

TEST(SocketCanBus, software_filter_drops_unlisted_ids_and_counts) {
  SocketCanOptions o = no_kernel_stamps();
  o.filters[0] = {0x185, 0x7FF};
  o.filter_count = 1;
  SocketCanBus bus(SocketCanBus::AdoptFd{pair.take_local()}, o, clock);
  CHECK_FALSE(bus.kernel_filter_active());
  pair.peer_send(data_frame(0x186, 4));
  pair.peer_send(data_frame(0x185, 4));
  hal::CanFrame got;
  LONGS_EQUAL(1, bus.receive(got));
  LONGS_EQUAL(0x185, got.id);
  LONGS_EQUAL(1, bus.stats().rx_filtered);
}

TEST(SocketCanBus, error_frames_are_consumed_and_decoded_into_state) {
  SocketCanBus bus(SocketCanBus::AdoptFd{pair.take_local()}, no_kernel_stamps(), clock);
  hal::CanFrame e;
  e.id = hal::CanFrame::kErrorFlag | CAN_ERR_CRTL;
  e.dlc = 8;
  e.data[1] = CAN_ERR_CRTL_RX_WARNING;
  pair.peer_send(e);
  hal::CanFrame got;
  LONGS_EQUAL(0, bus.receive(got));  // consumed, nothing delivered
  CHECK(bus.state() == hal::CanBusState::kWarning);
  e.data[1] = CAN_ERR_CRTL_TX_PASSIVE | CAN_ERR_CRTL_RX_OVERFLOW;
  pair.peer_send(e);
  bus.receive(got);
  CHECK(bus.state() == hal::CanBusState::kPassive);
  hal::CanFrame off;
  off.id = hal::CanFrame::kErrorFlag | CAN_ERR_BUSOFF;
  off.dlc = 8;
  pair.peer_send(off);
  hal::CanFrame noack;
  noack.id = hal::CanFrame::kErrorFlag | CAN_ERR_ACK | CAN_ERR_BUSERROR;
  noack.dlc = 8;
  pair.peer_send(noack);
  bus.receive(got);
  CHECK(bus.state() == hal::CanBusState::kBusOff);
  const hal::CanBusStats& s = bus.stats();
  LONGS_EQUAL(4, s.error_frames);
  LONGS_EQUAL(1, s.errors.warning);
  LONGS_EQUAL(1, s.errors.passive);
  LONGS_EQUAL(1, s.errors.controller_overflow);
  LONGS_EQUAL(1, s.errors.bus_off);
  LONGS_EQUAL(1, s.errors.no_ack);
  LONGS_EQUAL(1, s.errors.bus_error);
  LONGS_EQUAL(0, s.rx_frames);
}

TEST(SocketCanBus, restarted_error_frame_returns_to_active) {
  SocketCanBus bus(SocketCanBus::AdoptFd{pair.take_local()}, no_kernel_stamps(), clock);
  hal::CanFrame f;
  f.id = hal::CanFrame::kErrorFlag | CAN_ERR_BUSOFF;
  f.dlc = 8;
  bus.account_error_frame(f);
  CHECK(bus.state() == hal::CanBusState::kBusOff);
  f.id = hal::CanFrame::kErrorFlag | CAN_ERR_RESTARTED;
  bus.account_error_frame(f);
  CHECK(bus.state() == hal::CanBusState::kActive);
  LONGS_EQUAL(1, bus.stats().errors.restarted);
}

TEST(SocketCanBus, missing_interface_starts_down_and_retries_at_most_every_interval) {
  SocketCanOptions o;
  std::snprintf(o.interface_name, sizeof o.interface_name, "sdpnocan9");
  o.reopen_interval_us = 500000;
  SocketCanBus bus(o, clock);
  CHECK(bus.state() == hal::CanBusState::kDown);
  CHECK(bus.last_error() == SocketCanError::kNoInterface || bus.last_error() == SocketCanError::kOs);
  hal::CanFrame f;
  LONGS_EQUAL(-1, bus.receive(f));
  LONGS_EQUAL(-1, bus.send(f));
  LONGS_EQUAL(-1, bus.send(f));
  // Sends refused while down are not errors: the bus going down is the event.
  LONGS_EQUAL(0, bus.stats().tx_errors);
  LONGS_EQUAL(2, bus.stats().tx_while_down);
  LONGS_EQUAL(1, bus.stats().down_count);
  // The cause in words: this machine either has no CAN in its kernel or no such interface.
  char cause[160];
  const std::string text = bus.describe_last_failure(cause, sizeof cause);
  CHECK_TEXT(text.find("interface sdpnocan9 does not exist") == 0 || text.find("the kernel has no CAN support") == 0,
             text.c_str());
  LONGS_EQUAL(0, bus.stats().reopen_attempts);  // interval not yet elapsed
  clock.t_us += 500000;
  LONGS_EQUAL(-1, bus.receive(f));
  LONGS_EQUAL(1, bus.stats().reopen_attempts);
  LONGS_EQUAL(-1, bus.receive(f));
  LONGS_EQUAL(1, bus.stats().reopen_attempts);
  LONGS_EQUAL(0, bus.stats().reopen_count);
}

// SO_TIMESTAMP also works on AF_UNIX sockets, so the cmsg path is exercised here: the
// stamp comes from the kernel (CLOCK_REALTIME) mapped onto CLOCK_MONOTONIC, not from the
// (fake) clock handed to the driver.
TEST(SocketCanBus, kernel_receive_stamp_is_mapped_onto_the_monotonic_clock) {
  SocketCanOptions o;  // kernel_timestamps = true
  SocketCanBus bus(SocketCanBus::AdoptFd{pair.take_local()}, o, clock);
  if (!bus.kernel_timestamps_active()) {
    std::printf("note: SO_TIMESTAMP refused on AF_UNIX here; stamp path not exercised\n");
    return;
  }
  LinuxMonotonicClock mono;
  const std::int64_t before = mono.now_us();
  pair.peer_send(data_frame(0x185, 4));
  hal::CanFrame got;
  LONGS_EQUAL(1, bus.receive(got));
  const std::int64_t after = mono.now_us();
  CHECK_TRUE(got.stamp_us != clock.t_us);
  // Allow for the realtime/monotonic offset being sampled a moment later.
  CHECK_TRUE(got.stamp_us >= before - 2000 && got.stamp_us <= after + 2000);
}

TEST(SocketCanBus, failure_causes_are_named_in_words) {
  char out[160];
  STRCMP_CONTAINS("the kernel has no CAN support",
                  describe_failure(SocketCanError::kOs, EAFNOSUPPORT, "can0", out, sizeof out));
  STRCMP_CONTAINS("interface can1 does not exist",
                  describe_failure(SocketCanError::kNoInterface, ENODEV, "can1", out, sizeof out));
  STRCMP_CONTAINS("interface can0 is down", describe_failure(SocketCanError::kDown, ENETDOWN, "can0", out, sizeof out));
  STRCMP_CONTAINS("Permission denied", describe_failure(SocketCanError::kOs, EACCES, "can0", out, sizeof out));
  char tiny[8];
  STRCMP_EQUAL("the ker", describe_failure(SocketCanError::kOs, EAFNOSUPPORT, "can0", tiny, sizeof tiny));
}
