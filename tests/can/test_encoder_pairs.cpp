// Encoder protocol handlers end to end: SocketCanBus on one end of a SOCK_SEQPACKET pair,
// a scripted fake encoder (two CANopen nodes or two ODrive axes) on the other.
#include <CppUTest/TestHarness.h>

#include <cmath>

#include "can_test_support.h"
#include "sdpslam/drivers/can_wheel_encoders.h"
#include "sdpslam/drivers/canopen_encoder_pair.h"
#include "sdpslam/drivers/diff_drive_odometry.h"
#include "sdpslam/drivers/odrive_encoder_pair.h"
#include "sdpslam/drivers/socketcan_bus.h"

using namespace sdpslam;
using namespace sdpslam::drivers;

namespace {
SocketCanOptions bus_options() {
  SocketCanOptions o;
  o.kernel_timestamps = false;
  return o;
}
CanOpenEncoderOptions canopen_options() {
  CanOpenEncoderOptions o;
  o.left_node = 5;
  o.right_node = 6;
  o.position_timeout_us = 50000;
  return o;
}
// Two axes, nodes 1 and 2, estimates requested every 10 ms.
ODriveEncoderOptions odrive_request_options() {
  ODriveEncoderOptions o;
  o.left_node = 1;
  o.right_node = 2;
  o.request_period_us = 10000;
  return o;
}
}  // namespace

TEST_GROUP(CanOpenEncoderPair) {
  test::FakeClock clock;
  test::SeqPacketPair pair;
  SocketCanBus* bus = nullptr;
  void setup() override { bus = new SocketCanBus(SocketCanBus::AdoptFd{pair.take_local()}, bus_options(), clock); }
  void teardown() override { delete bus; }

  void encoder_sends_positions(std::uint32_t left, std::uint32_t right, std::uint8_t bytes = 4) {
    hal::CanFrame f;
    canopen::make_tpdo1_position(5, left, bytes, f);
    pair.peer_send(f);
    canopen::make_tpdo1_position(6, right, bytes, f);
    pair.peer_send(f);
  }
  void encoder_sends_heartbeat(std::uint8_t node, canopen::NodeState st) {
    hal::CanFrame f;
    canopen::make_heartbeat(node, st, f);
    pair.peer_send(f);
  }
  int count_syncs_at_peer() {
    int n = 0;
    hal::CanFrame f;
    while (pair.peer_receive(f) == 1) {
      if (canopen::decode_sync(f) == CanDecodeError::kOk) ++n;
    }
    return n;
  }
};

TEST(CanOpenEncoderPair, invalid_options_are_refused) {
  CanOpenEncoderOptions o = canopen_options();
  o.right_node = 5;
  CHECK(validate(o) == CanOpenOptionsError::kSameNode);
  CanOpenEncoderPair enc(*bus, clock, o);
  LONGS_EQUAL(-1, enc.start());
  LONGS_EQUAL(-1, enc.update());
}

TEST(CanOpenEncoderPair, start_sends_nmt_start_to_each_node) {
  CanOpenEncoderPair enc(*bus, clock, canopen_options());
  LONGS_EQUAL(1, enc.start());
  hal::CanFrame f;
  canopen::NmtCommand cmd{};
  std::uint8_t node = 0;
  LONGS_EQUAL(1, pair.peer_receive(f));
  CHECK(canopen::decode_nmt(f, cmd, node) == CanDecodeError::kOk);
  CHECK(cmd == canopen::NmtCommand::kStart);
  LONGS_EQUAL(5, node);
  LONGS_EQUAL(1, pair.peer_receive(f));
  CHECK(canopen::decode_nmt(f, cmd, node) == CanDecodeError::kOk);
  LONGS_EQUAL(6, node);
  LONGS_EQUAL(2, enc.stats().nmt_sent);
}

TEST(CanOpenEncoderPair, sync_period_is_honoured_without_drift) {
  CanOpenEncoderOptions o = canopen_options();
  o.sync_period_us = 10000;
  o.send_nmt_start = false;
  CanOpenEncoderPair enc(*bus, clock, o);
  enc.start();
  enc.update();
  LONGS_EQUAL(1, count_syncs_at_peer());
  clock.t_us += 5000;
  enc.update();
  LONGS_EQUAL(0, count_syncs_at_peer());
  clock.t_us += 5000;
  enc.update();
  LONGS_EQUAL(1, count_syncs_at_peer());
  clock.t_us += 12000;  // late by 2 ms: next one stays on the 10 ms grid
  enc.update();
  LONGS_EQUAL(1, count_syncs_at_peer());
  clock.t_us += 8000;
  enc.update();
  LONGS_EQUAL(1, count_syncs_at_peer());
  LONGS_EQUAL(4, enc.stats().sync_sent);
  LONGS_EQUAL(0, enc.stats().sync_missed);
}

TEST(CanOpenEncoderPair, sync_periods_missed_by_a_late_update_are_counted_not_burst) {
  CanOpenEncoderOptions o = canopen_options();
  o.sync_period_us = 10000;
  o.send_nmt_start = false;
  CanOpenEncoderPair enc(*bus, clock, o);
  enc.start();
  enc.update();
  count_syncs_at_peer();
  clock.t_us += 35000;
  enc.update();
  LONGS_EQUAL(1, count_syncs_at_peer());
  LONGS_EQUAL(2, enc.stats().sync_missed);
}

TEST(CanOpenEncoderPair, tpdo1_positions_become_fresh_ticks) {
  CanOpenEncoderPair enc(*bus, clock, canopen_options());
  encoder_sends_positions(74565, 0xFFFEDCBBu);
  LONGS_EQUAL(2, enc.update());
  const hal::WheelEncoderSample s = enc.latest();
  CHECK_TRUE(s.both_fresh());
  LONGS_EQUAL(74565, s.left.raw_count);
  UNSIGNED_LONGS_EQUAL(0xFFFEDCBBu, s.right.raw_count);
  LONGS_EQUAL(32, s.left.counter_bits);
  LONGS_EQUAL(clock.t_us, s.left.stamp_us);
}

TEST(CanOpenEncoderPair, sixteen_bit_mapping_reports_sixteen_bit_counter) {
  CanOpenEncoderOptions o = canopen_options();
  o.position_bytes = 2;
  CanOpenEncoderPair enc(*bus, clock, o);
  encoder_sends_positions(0x1234, 0xFFFF, 2);
  LONGS_EQUAL(2, enc.update());
  LONGS_EQUAL(16, enc.latest().left.counter_bits);
  LONGS_EQUAL(0xFFFF, enc.latest().right.raw_count);
}

TEST(CanOpenEncoderPair, no_position_within_timeout_makes_wheel_stale) {
  CanOpenEncoderPair enc(*bus, clock, canopen_options());
  encoder_sends_positions(1, 2);
  enc.update();
  clock.t_us += 40000;
  hal::CanFrame f;
  canopen::make_tpdo1_position(5, 3, 4, f);  // only the left wheel keeps talking
  pair.peer_send(f);
  enc.update();
  clock.t_us += 20000;
  enc.update();
  CHECK_TRUE(enc.latest().left.fresh());
  CHECK_FALSE(enc.latest().right.fresh());
  CHECK_FALSE(enc.latest().both_fresh());
}

TEST(CanOpenEncoderPair, heartbeat_timeout_makes_wheels_stale_and_is_counted_once) {
  CanOpenEncoderOptions o = canopen_options();
  o.heartbeat_timeout_us = 30000;
  o.position_timeout_us = 1000000;
  CanOpenEncoderPair enc(*bus, clock, o);
  enc.start();
  encoder_sends_heartbeat(5, canopen::NodeState::kOperational);
  encoder_sends_heartbeat(6, canopen::NodeState::kOperational);
  encoder_sends_positions(10, 20);
  enc.update();
  CHECK_TRUE(enc.latest().both_fresh());
  clock.t_us += 20000;
  encoder_sends_heartbeat(5, canopen::NodeState::kOperational);  // node 6 falls silent
  encoder_sends_positions(11, 21);
  enc.update();
  clock.t_us += 20000;
  encoder_sends_positions(12, 22);
  enc.update();
  CHECK_TRUE(enc.latest().left.fresh());
  CHECK_TRUE(enc.latest().right.stale);
  CHECK_TRUE(enc.heartbeat_lost(hal::WheelSide::kRight));
  clock.t_us += 5000;
  enc.update();
  LONGS_EQUAL(1, enc.stats().heartbeat_timeouts);
  encoder_sends_heartbeat(6, canopen::NodeState::kOperational);  // back
  encoder_sends_positions(13, 23);
  enc.update();
  CHECK_TRUE(enc.latest().right.fresh());
}

TEST(CanOpenEncoderPair, pre_operational_heartbeat_makes_wheel_stale) {
  CanOpenEncoderPair enc(*bus, clock, canopen_options());
  encoder_sends_heartbeat(6, canopen::NodeState::kPreOperational);
  encoder_sends_positions(1, 2);
  enc.update();
  CHECK_TRUE(enc.latest().left.fresh());
  CHECK_TRUE(enc.latest().right.stale);
  LONGS_EQUAL(1, enc.stats().not_operational);
}

TEST(CanOpenEncoderPair, boot_up_after_start_is_answered_with_nmt_start) {
  CanOpenEncoderPair enc(*bus, clock, canopen_options());
  enc.start();
  hal::CanFrame f;
  while (pair.peer_receive(f) == 1) {
  }
  encoder_sends_heartbeat(5, canopen::NodeState::kBootUp);
  enc.update();
  LONGS_EQUAL(1, enc.stats().boot_ups);
  LONGS_EQUAL(1, pair.peer_receive(f));
  canopen::NmtCommand cmd{};
  std::uint8_t node = 0;
  CHECK(canopen::decode_nmt(f, cmd, node) == CanDecodeError::kOk);
  CHECK(cmd == canopen::NmtCommand::kStart);
  LONGS_EQUAL(5, node);
}

TEST(CanOpenEncoderPair, emcy_is_decoded_counted_and_kept) {
  CanOpenEncoderPair enc(*bus, clock, canopen_options());
  const std::uint8_t b[8] = {0x10, 0x81, 0x11, 0, 0, 0, 0, 0};
  pair.peer_send(hal::CanFrame::standard(0x085, b, 8));
  enc.update();
  LONGS_EQUAL(1, enc.stats().emcy_count);
  LONGS_EQUAL(0x8110, enc.stats().last_emcy.error_code);
  LONGS_EQUAL(0x11, enc.stats().last_emcy.error_register);
  LONGS_EQUAL(5, enc.stats().last_emcy_node);
}

TEST(CanOpenEncoderPair, unexpected_and_malformed_frames_are_counted_not_fatal) {
  CanOpenEncoderPair enc(*bus, clock, canopen_options());
  const std::uint8_t b[8] = {0x43, 0, 0x10, 0, 0x92, 1, 2, 0};
  pair.peer_send(hal::CanFrame::standard(0x5A0, b, 8));  // SDO of another node
  pair.peer_send(hal::CanFrame::standard(0x585, b, 8));  // SDO of ours: not handled
  hal::CanFrame vesc = hal::CanFrame::standard(0, b, 8);
  vesc.id = 0x901 | hal::CanFrame::kExtendedFlag;
  pair.peer_send(vesc);
  pair.peer_send(hal::CanFrame::standard(0x185, b, 3));  // TPDO1 too short
  encoder_sends_positions(7, 8);
  LONGS_EQUAL(2, enc.update());
  LONGS_EQUAL(3, enc.stats().unexpected_frames);
  LONGS_EQUAL(1, enc.stats().decode_errors);
  LONGS_EQUAL(7, enc.latest().left.raw_count);
}

TEST(CanOpenEncoderPair, bad_length_datagram_is_skipped_and_reading_continues) {
  CanOpenEncoderPair enc(*bus, clock, canopen_options());
  const unsigned char junk[12] = {};
  ::send(pair.peer, junk, sizeof junk, 0);
  encoder_sends_positions(7, 8);
  LONGS_EQUAL(2, enc.update());
  LONGS_EQUAL(1, enc.stats().rx_errors);
  LONGS_EQUAL(1, bus->stats().bad_length_reads);
}

TEST(CanOpenEncoderPair, peer_gone_reports_transport_failure) {
  CanOpenEncoderPair enc(*bus, clock, canopen_options());
  pair.close_peer();
  LONGS_EQUAL(-1, enc.update());
}

// The whole chain: SYNC out, the fake encoders answer each SYNC with TPDO1 of wheels
// turning at constant, different speeds, odometry integrates an arc.
TEST(CanOpenEncoderPair, sync_driven_encoders_feed_odometry_along_an_arc) {
  CanOpenEncoderOptions o = canopen_options();
  o.sync_period_us = 10000;
  o.send_nmt_start = false;
  CanOpenEncoderPair enc(*bus, clock, o);
  DiffDriveParams p;  // MinesRover
  EncoderOdometrySource odo(enc, p);
  enc.start();
  std::uint32_t left = 0xFFFFFF00u, right = 0xFFFFFF00u;  // wraps on the way
  int integrated = 0;
  for (int step = 0; step < 101; ++step) {
    odo.update();  // drains positions, then produces the next SYNC
    hal::CanFrame f;
    while (pair.peer_receive(f) == 1) {
      if (canopen::decode_sync(f) == CanDecodeError::kOk) {
        encoder_sends_positions(left, right);
        left += 10;
        right += 20;
      }
    }
    clock.t_us += 10000;
    integrated += odo.update() > 0 ? 1 : 0;
  }
  CHECK_TRUE(odo.latest().valid());
  CHECK_TRUE(integrated >= 99);
  // Integrated exactly over all 100 deltas: same as one step of the totals.
  DiffDriveOdometry ref(p);
  ref.update(0, 0, 0);
  ref.update(static_cast<std::uint32_t>(odo.odometry().left_ticks_total()),
             static_cast<std::uint32_t>(odo.odometry().right_ticks_total()), 1);
  LONGS_EQUAL(1000, odo.odometry().left_ticks_total());
  LONGS_EQUAL(2000, odo.odometry().right_ticks_total());
  DOUBLES_EQUAL(ref.pose().x_m, odo.latest().pose.x_m, 1e-9);
  DOUBLES_EQUAL(ref.pose().y_m, odo.latest().pose.y_m, 1e-9);
}

TEST_GROUP(ODriveEncoderPair) {
  test::FakeClock clock;
  test::SeqPacketPair pair;
  SocketCanBus* bus = nullptr;
  void setup() override { bus = new SocketCanBus(SocketCanBus::AdoptFd{pair.take_local()}, bus_options(), clock); }
  void teardown() override { delete bus; }
  void axis_sends(std::uint8_t node, float pos, float vel) {
    hal::CanFrame f;
    odrive::make_encoder_estimates(node, {pos, vel}, f);
    pair.peer_send(f);
  }
};

TEST(ODriveEncoderPair, estimates_become_ticks_at_counts_per_turn) {
  ODriveEncoderOptions o;
  o.left_node = 1;
  o.right_node = 2;
  o.counts_per_turn = 8192;
  ODriveEncoderPair enc(*bus, clock, o);
  axis_sends(1, 1.5f, -2.0f);
  axis_sends(2, -0.5f, 0.0f);
  LONGS_EQUAL(2, enc.update());
  LONGS_EQUAL(12288, enc.latest().left.raw_count);
  UNSIGNED_LONGS_EQUAL(static_cast<std::uint32_t>(-4096), enc.latest().right.raw_count);
  DOUBLES_EQUAL(-2.0, enc.stats().vel_turns_s[0], 0.0);
  CHECK_TRUE(enc.latest().both_fresh());
}

TEST(ODriveEncoderPair, rtr_requests_follow_the_period) {
  ODriveEncoderPair enc(*bus, clock, odrive_request_options());
  enc.update();
  clock.t_us += 9999;
  enc.update();
  clock.t_us += 1;
  enc.update();
  int requests = 0;
  hal::CanFrame f;
  while (pair.peer_receive(f) == 1) {
    CHECK_TRUE(f.is_rtr());
    CHECK_EQUAL(odrive::kCmdGetEncoderEstimates, odrive::cmd_of(f.arbitration_id()));
    ++requests;
  }
  LONGS_EQUAL(4, requests);
  LONGS_EQUAL(4, enc.stats().requests_sent);
}

TEST(ODriveEncoderPair, heartbeat_errors_counted_and_timeout_makes_stale) {
  ODriveEncoderOptions o;
  o.left_node = 1;
  o.right_node = 2;
  o.heartbeat_timeout_us = 30000;
  o.position_timeout_us = 1000000;
  ODriveEncoderPair enc(*bus, clock, o);
  hal::CanFrame hb;
  odrive::make_heartbeat(1, {0x40, 8}, hb);
  pair.peer_send(hb);
  odrive::make_heartbeat(2, {0, 8}, hb);
  pair.peer_send(hb);
  axis_sends(1, 0.0f, 0.0f);
  axis_sends(2, 0.0f, 0.0f);
  enc.update();
  LONGS_EQUAL(1, enc.stats().axis_error_reports);
  LONGS_EQUAL(0x40, enc.stats().last_axis_error[0]);
  LONGS_EQUAL(8, enc.stats().axis_state[1]);
  CHECK_TRUE(enc.latest().both_fresh());
  clock.t_us += 31000;
  enc.update();
  CHECK_FALSE(enc.latest().left.fresh());
  LONGS_EQUAL(2, enc.stats().heartbeat_timeouts);
}

TEST(ODriveEncoderPair, other_commands_and_nodes_are_unexpected) {
  ODriveEncoderOptions o;
  o.left_node = 1;
  o.right_node = 2;
  ODriveEncoderPair enc(*bus, clock, o);
  const std::uint8_t b[8] = {};
  pair.peer_send(hal::CanFrame::standard(odrive::make_id(1, 0x17), b, 8));  // Get_Vbus_Voltage
  pair.peer_send(hal::CanFrame::standard(odrive::make_id(3, 0x09), b, 8));  // another axis
  pair.peer_send(hal::CanFrame::standard(odrive::make_id(1, 0x09), b, 4));  // short
  enc.update();
  LONGS_EQUAL(2, enc.stats().unexpected_frames);
  LONGS_EQUAL(1, enc.stats().decode_errors);
  CHECK_FALSE(enc.latest().left.has_sample);
}

TEST_GROUP(CanWheelEncoders){};

TEST(CanWheelEncoders, protocol_names_parse_and_unknown_is_refused) {
  EncoderProtocol p = EncoderProtocol::kODrive;
  CHECK_TRUE(parse_encoder_protocol("canopen", p));
  CHECK(p == EncoderProtocol::kCanOpen);
  CHECK_TRUE(parse_encoder_protocol("odrive", p));
  CHECK(p == EncoderProtocol::kODrive);
  CHECK_FALSE(parse_encoder_protocol("vesc", p));
  CHECK(p == EncoderProtocol::kODrive);
}

TEST(CanWheelEncoders, canopen_filters_pass_only_our_objects) {
  CanWheelEncoderConfig cfg;  // CANopen nodes 5 and 6
  SocketCanOptions o;
  o.kernel_timestamps = false;
  CHECK_TRUE(add_receive_filters(cfg, o));
  LONGS_EQUAL(6, o.filter_count);
  test::FakeClock clock;
  test::SeqPacketPair pair;
  SocketCanBus bus(SocketCanBus::AdoptFd{pair.take_local()}, o, clock);
  const std::uint8_t b[4] = {1, 0, 0, 0};
  pair.peer_send(hal::CanFrame::standard(0x187, b, 4));  // node 7: not ours
  hal::CanFrame rtr;
  rtr.id = 0x185 | hal::CanFrame::kRtrFlag;  // an RTR is not a position
  pair.peer_send(rtr);
  pair.peer_send(hal::CanFrame::standard(0x185, b, 4));
  pair.peer_send(hal::CanFrame::standard(0x706, b, 1));
  hal::CanFrame got;
  LONGS_EQUAL(1, bus.receive(got));
  LONGS_EQUAL(0x185, got.id);
  LONGS_EQUAL(1, bus.receive(got));
  LONGS_EQUAL(0x706, got.id);
  LONGS_EQUAL(2, bus.stats().rx_filtered);
}

TEST(CanWheelEncoders, filters_that_do_not_fit_are_refused_whole) {
  CanWheelEncoderConfig cfg;
  SocketCanOptions o;
  o.filter_count = SocketCanOptions::kMaxFilters - 5;
  CHECK_FALSE(add_receive_filters(cfg, o));
  LONGS_EQUAL(SocketCanOptions::kMaxFilters - 5, o.filter_count);
}

TEST(CanWheelEncoders, odrive_selected_by_config_reads_estimates) {
  CanWheelEncoderConfig cfg;
  parse_encoder_protocol("odrive", cfg.protocol);
  cfg.odrive.left_node = 1;
  cfg.odrive.right_node = 2;
  SocketCanOptions o;
  o.kernel_timestamps = false;
  CHECK_TRUE(add_receive_filters(cfg, o));
  LONGS_EQUAL(2, o.filter_count);
  test::FakeClock clock;
  test::SeqPacketPair pair;
  SocketCanBus bus(SocketCanBus::AdoptFd{pair.take_local()}, o, clock);
  CanWheelEncoders enc(bus, clock, cfg);
  CHECK(enc.canopen() == nullptr);
  LONGS_EQUAL(1, enc.start());
  hal::CanFrame f;
  odrive::make_encoder_estimates(1, {1.5f, -2.0f}, f);
  pair.peer_send(f);
  odrive::make_encoder_estimates(2, {2.0f, 0.0f}, f);
  pair.peer_send(f);
  odrive::make_encoder_estimates(3, {9.0f, 0.0f}, f);  // filtered out by the bus
  pair.peer_send(f);
  LONGS_EQUAL(2, enc.update());
  LONGS_EQUAL(12288, enc.latest().left.raw_count);
  LONGS_EQUAL(16384, enc.latest().right.raw_count);
  LONGS_EQUAL(1, bus.stats().rx_filtered);
  LONGS_EQUAL(0, enc.odrive()->stats().unexpected_frames);
}

namespace {
// A bus holding frames that were received (kernel stamps) long before they are read, as
// after the host was busy processing a scan.
class BacklogBus final : public hal::CanBus {
 public:
  int send(const hal::CanFrame&) override { return 1; }
  int receive(hal::CanFrame& out) override {
    if (next >= count) return 0;
    out = frames[next++];
    return 1;
  }
  int wait_readable(std::int64_t) override { return next < count ? 1 : 0; }
  hal::CanBusState state() const override { return hal::CanBusState::kActive; }
  const hal::CanBusStats& stats() const override { return stats_; }
  hal::CanFrame frames[64];
  int count = 0;
  int next = 0;

 private:
  hal::CanBusStats stats_{};
};
}  // namespace

TEST_GROUP(EncoderBacklog){};

TEST(EncoderBacklog, backlog_read_frame_by_frame_keeps_both_wheels_fresh) {
  test::FakeClock clock;
  clock.t_us = 10000000;
  BacklogBus bus;
  for (int k = 0; k < 10; ++k) {  // 50 Hz pairs, received ~3 s before they are read
    const std::int64_t stamp = 7000000 + 20000 * k;
    canopen::make_tpdo1_position(5, static_cast<std::uint32_t>(10 * k), 4, bus.frames[bus.count]);
    bus.frames[bus.count++].stamp_us = stamp;
    canopen::make_tpdo1_position(6, static_cast<std::uint32_t>(20 * k), 4, bus.frames[bus.count]);
    bus.frames[bus.count++].stamp_us = stamp + 1000;
  }
  CanOpenEncoderOptions o = canopen_options();
  o.max_frames_per_update = 1;
  CanOpenEncoderPair enc(bus, clock, o);
  enc.update();  // left only: the right wheel has no sample yet
  CHECK_FALSE(enc.latest().both_fresh());
  for (int i = 1; i < bus.count; ++i) {
    enc.update();
    CHECK_TRUE(enc.latest().both_fresh());  // judged at the newest frame's receive stamp
  }
  LONGS_EQUAL(90, enc.latest().left.raw_count);
  LONGS_EQUAL(7180000, enc.latest().left.stamp_us);
  // Once the backlog is read, silence is judged on the clock again.
  clock.t_us += 60000;
  enc.update();
  CHECK_FALSE(enc.latest().both_fresh());
}

namespace {
// A bus that is down (its interface missing or down): every send is refused, nothing arrives.
// It counts the refusals itself (SocketCanBus: CanBusStats::tx_while_down).
class DownBus final : public hal::CanBus {
 public:
  int send(const hal::CanFrame&) override {
    ++refused;
    return -1;
  }
  int receive(hal::CanFrame&) override { return 0; }
  int wait_readable(std::int64_t) override { return 0; }
  hal::CanBusState state() const override { return hal::CanBusState::kDown; }
  const hal::CanBusStats& stats() const override { return stats_; }
  int refused = 0;

 private:
  hal::CanBusStats stats_{};
};
}  // namespace

// While the bus is down the encoder pairs keep trying (SYNC, NMT start, RTR requests on
// their schedules) but count no transmit error: the outage is the bus's event, counted
// once there, not one error per retry (hundreds a second).
TEST_GROUP(EncoderPairsOnADownBus) {
  test::FakeClock clock;
  DownBus bus;
};

TEST(EncoderPairsOnADownBus, canopen_retries_count_no_transmit_error) {
  CanOpenEncoderOptions o = canopen_options();
  o.sync_period_us = 10000;
  o.send_nmt_start = true;
  CanOpenEncoderPair enc(bus, clock, o);
  CHECK(enc.start() < 0);
  for (int i = 0; i < 100; ++i) {
    clock.t_us += 10000;
    enc.update();
  }
  CHECK(bus.refused >= 100);  // it did keep trying
  LONGS_EQUAL(0, enc.stats().tx_errors);
  LONGS_EQUAL(0, enc.stats().sync_sent);
}

TEST(EncoderPairsOnADownBus, odrive_retries_count_no_transmit_error) {
  ODriveEncoderPair enc(bus, clock, odrive_request_options());
  for (int i = 0; i < 100; ++i) {
    clock.t_us += 10000;
    enc.update();
  }
  CHECK(bus.refused >= 100);
  LONGS_EQUAL(0, enc.stats().tx_errors);
  LONGS_EQUAL(0, enc.stats().requests_sent);
}
