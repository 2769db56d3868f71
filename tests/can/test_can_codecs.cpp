#include <CppUTest/TestHarness.h>

#include <cmath>

#include "sdpslam/drivers/canopen_codec.h"
#include "sdpslam/drivers/odrive_codec.h"

using namespace sdpslam;
using namespace sdpslam::drivers;

namespace {
hal::CanFrame frame(std::uint32_t id, std::initializer_list<std::uint8_t> bytes) {
  hal::CanFrame f;
  f.id = id;
  for (std::uint8_t b : bytes) f.data[f.dlc++] = b;
  return f;
}
}  // namespace

TEST_GROUP(CanOpenCodec){};

TEST(CanOpenCodec, nmt_start_node_is_cmd_then_node) {
  hal::CanFrame f;
  CHECK_TRUE(canopen::make_nmt(canopen::NmtCommand::kStart, 5, f));
  LONGS_EQUAL(0x000, f.id);
  LONGS_EQUAL(2, f.dlc);
  LONGS_EQUAL(0x01, f.data[0]);
  LONGS_EQUAL(0x05, f.data[1]);
}

TEST(CanOpenCodec, nmt_to_node_above_127_is_refused) {
  hal::CanFrame f;
  f.id = 0x123;
  CHECK_FALSE(canopen::make_nmt(canopen::NmtCommand::kStart, 128, f));
  LONGS_EQUAL(0x123, f.id);
}

TEST(CanOpenCodec, nmt_decode_round_trips_every_command) {
  const canopen::NmtCommand cmds[] = {canopen::NmtCommand::kStart, canopen::NmtCommand::kStop,
                                      canopen::NmtCommand::kEnterPreOperational,
                                      canopen::NmtCommand::kResetNode,
                                      canopen::NmtCommand::kResetCommunication};
  for (auto c : cmds) {
    hal::CanFrame f;
    canopen::make_nmt(c, 0, f);
    canopen::NmtCommand got{};
    std::uint8_t node = 99;
    CHECK(canopen::decode_nmt(f, got, node) == CanDecodeError::kOk);
    CHECK(got == c);
    LONGS_EQUAL(0, node);
  }
}

TEST(CanOpenCodec, nmt_unknown_command_is_bad_value) {
  canopen::NmtCommand c{};
  std::uint8_t node = 0;
  CHECK(canopen::decode_nmt(frame(0x000, {0x03, 0x05}), c, node) == CanDecodeError::kBadValue);
}

TEST(CanOpenCodec, sync_has_id_080_and_no_data) {
  const hal::CanFrame f = canopen::make_sync();
  LONGS_EQUAL(0x080, f.id);
  LONGS_EQUAL(0, f.dlc);
  CHECK(canopen::decode_sync(f) == CanDecodeError::kOk);
  CHECK(canopen::decode_sync(frame(0x080, {1, 2})) == CanDecodeError::kWrongLength);
}

TEST(CanOpenCodec, tpdo1_position_is_u32_little_endian) {
  std::uint32_t pos = 0;
  CHECK(canopen::decode_tpdo1_position(frame(0x185, {0x45, 0x23, 0x01, 0x00}), 5, 4, pos) ==
        CanDecodeError::kOk);
  LONGS_EQUAL(74565, pos);
  CHECK(canopen::decode_tpdo1_position(frame(0x186, {0xBB, 0xDC, 0xFE, 0xFF}), 6, 4, pos) ==
        CanDecodeError::kOk);
  UNSIGNED_LONGS_EQUAL(0xFFFEDCBBu, pos);
}

TEST(CanOpenCodec, tpdo1_sixteen_bit_counter_reads_two_bytes) {
  std::uint32_t pos = 0;
  CHECK(canopen::decode_tpdo1_position(frame(0x185, {0x34, 0x12}), 5, 2, pos) == CanDecodeError::kOk);
  LONGS_EQUAL(0x1234, pos);
}

TEST(CanOpenCodec, tpdo1_short_payload_is_wrong_length_and_output_untouched) {
  std::uint32_t pos = 7;
  CHECK(canopen::decode_tpdo1_position(frame(0x185, {0x45, 0x23, 0x01}), 5, 4, pos) ==
        CanDecodeError::kWrongLength);
  LONGS_EQUAL(7, pos);
}

TEST(CanOpenCodec, tpdo1_of_another_node_is_wrong_id) {
  std::uint32_t pos = 0;
  CHECK(canopen::decode_tpdo1_position(frame(0x186, {1, 2, 3, 4}), 5, 4, pos) == CanDecodeError::kWrongId);
}

TEST(CanOpenCodec, tpdo1_extended_rtr_and_error_frames_are_refused) {
  std::uint32_t pos = 0;
  hal::CanFrame f = frame(0x185, {1, 2, 3, 4});
  f.id |= hal::CanFrame::kExtendedFlag;
  CHECK(canopen::decode_tpdo1_position(f, 5, 4, pos) == CanDecodeError::kExtendedId);
  f.id = 0x185 | hal::CanFrame::kRtrFlag;
  CHECK(canopen::decode_tpdo1_position(f, 5, 4, pos) == CanDecodeError::kRtr);
  f.id = 0x185 | hal::CanFrame::kErrorFlag;
  CHECK(canopen::decode_tpdo1_position(f, 5, 4, pos) == CanDecodeError::kErrorFrame);
}

TEST(CanOpenCodec, decoders_refuse_node_zero_and_above_127) {
  std::uint32_t pos = 0;
  CHECK(canopen::decode_tpdo1_position(frame(0x180, {1, 2, 3, 4}), 0, 4, pos) == CanDecodeError::kBadNode);
  canopen::NodeState st{};
  CHECK(canopen::decode_heartbeat(frame(0x700, {5}), 200, st) == CanDecodeError::kBadNode);
}

TEST(CanOpenCodec, heartbeat_states_decode) {
  canopen::NodeState st{};
  CHECK(canopen::decode_heartbeat(frame(0x705, {0x05}), 5, st) == CanDecodeError::kOk);
  CHECK(st == canopen::NodeState::kOperational);
  CHECK(canopen::decode_heartbeat(frame(0x706, {0x7F}), 6, st) == CanDecodeError::kOk);
  CHECK(st == canopen::NodeState::kPreOperational);
  CHECK(canopen::decode_heartbeat(frame(0x720, {0x00}), 0x20, st) == CanDecodeError::kOk);
  CHECK(st == canopen::NodeState::kBootUp);
  CHECK(canopen::decode_heartbeat(frame(0x705, {0x04}), 5, st) == CanDecodeError::kOk);
  CHECK(st == canopen::NodeState::kStopped);
}

TEST(CanOpenCodec, heartbeat_unknown_state_is_bad_value) {
  canopen::NodeState st = canopen::NodeState::kStopped;
  CHECK(canopen::decode_heartbeat(frame(0x705, {0x85}), 5, st) == CanDecodeError::kBadValue);
  CHECK(st == canopen::NodeState::kStopped);
}

TEST(CanOpenCodec, heartbeat_with_two_bytes_is_wrong_length) {
  canopen::NodeState st{};
  CHECK(canopen::decode_heartbeat(frame(0x705, {0x05, 0x00}), 5, st) == CanDecodeError::kWrongLength);
}

TEST(CanOpenCodec, emcy_fields_decode_little_endian) {
  canopen::Emergency e;
  CHECK(canopen::decode_emcy(frame(0x085, {0x10, 0x81, 0x11, 0x01, 0x02, 0x03, 0x04, 0x05}), 5, e) ==
        CanDecodeError::kOk);
  LONGS_EQUAL(0x8110, e.error_code);
  LONGS_EQUAL(0x11, e.error_register);
  LONGS_EQUAL(0x01, e.vendor[0]);
  LONGS_EQUAL(0x05, e.vendor[4]);
}

TEST(CanOpenCodec, emcy_shorter_than_eight_is_wrong_length) {
  canopen::Emergency e;
  CHECK(canopen::decode_emcy(frame(0x085, {0x10, 0x81, 0x11}), 5, e) == CanDecodeError::kWrongLength);
}

TEST(CanOpenCodec, classify_names_object_and_node) {
  CHECK(canopen::classify(frame(0x000, {1, 0})).kind == canopen::ObjectKind::kNmt);
  CHECK(canopen::classify(frame(0x080, {})).kind == canopen::ObjectKind::kSync);
  const auto emcy = canopen::classify(frame(0x0A0, {}));
  CHECK(emcy.kind == canopen::ObjectKind::kEmcy);
  LONGS_EQUAL(0x20, emcy.node);
  CHECK(canopen::classify(frame(0x5A0, {})).kind == canopen::ObjectKind::kSdoTx);
  CHECK(canopen::classify(frame(0x620, {})).kind == canopen::ObjectKind::kSdoRx);
  CHECK(canopen::classify(frame(0x720, {})).kind == canopen::ObjectKind::kHeartbeat);
  CHECK(canopen::classify(frame(0x185, {})).kind == canopen::ObjectKind::kTpdo1);
  CHECK(canopen::classify(frame(0x029, {})).kind == canopen::ObjectKind::kOther);
}

TEST_GROUP(ODriveCodec){};

TEST(ODriveCodec, id_is_node_shifted_by_five_or_cmd) {
  LONGS_EQUAL(0x029, odrive::make_id(1, odrive::kCmdGetEncoderEstimates));
  LONGS_EQUAL(0x021, odrive::make_id(1, odrive::kCmdHeartbeat));
  LONGS_EQUAL(1, odrive::node_of(0x029));
  LONGS_EQUAL(9, odrive::cmd_of(0x029));
}

TEST(ODriveCodec, encoder_estimates_worked_example) {
  odrive::EncoderEstimates e;
  CHECK(odrive::decode_encoder_estimates(frame(0x029, {0x00, 0x00, 0xC0, 0x3F, 0x00, 0x00, 0x00, 0xC0}), 1, e) ==
        CanDecodeError::kOk);
  DOUBLES_EQUAL(1.5, e.pos_turns, 0.0);
  DOUBLES_EQUAL(-2.0, e.vel_turns_s, 0.0);
}

TEST(ODriveCodec, encoder_estimates_round_trip) {
  hal::CanFrame f;
  CHECK_TRUE(odrive::make_encoder_estimates(3, {-12.25f, 0.5f}, f));
  odrive::EncoderEstimates e;
  CHECK(odrive::decode_encoder_estimates(f, 3, e) == CanDecodeError::kOk);
  DOUBLES_EQUAL(-12.25, e.pos_turns, 0.0);
  DOUBLES_EQUAL(0.5, e.vel_turns_s, 0.0);
}

TEST(ODriveCodec, encoder_estimates_nan_is_bad_value) {
  odrive::EncoderEstimates e;
  CHECK(odrive::decode_encoder_estimates(frame(0x029, {0x00, 0x00, 0xC0, 0x7F, 0, 0, 0, 0}), 1, e) ==
        CanDecodeError::kBadValue);
}

TEST(ODriveCodec, encoder_estimates_rtr_request_is_refused_as_rtr) {
  hal::CanFrame req;
  CHECK_TRUE(odrive::make_encoder_estimates_request(1, req));
  CHECK_TRUE(req.is_rtr());
  LONGS_EQUAL(0x029, req.arbitration_id());
  odrive::EncoderEstimates e;
  CHECK(odrive::decode_encoder_estimates(req, 1, e) == CanDecodeError::kRtr);
}

TEST(ODriveCodec, encoder_estimates_with_four_bytes_is_wrong_length) {
  odrive::EncoderEstimates e;
  CHECK(odrive::decode_encoder_estimates(frame(0x029, {0, 0, 0xC0, 0x3F}), 1, e) == CanDecodeError::kWrongLength);
}

TEST(ODriveCodec, heartbeat_axis_error_and_state) {
  odrive::Heartbeat hb;
  CHECK(odrive::decode_heartbeat(frame(0x021, {0x00, 0x00, 0x00, 0x00, 0x08, 0x00, 0x00, 0x00}), 1, hb) ==
        CanDecodeError::kOk);
  LONGS_EQUAL(0, hb.axis_error);
  LONGS_EQUAL(8, hb.axis_state);
  CHECK(odrive::decode_heartbeat(frame(0x021, {0x01, 0x02, 0x00, 0x80, 0x01}), 1, hb) == CanDecodeError::kOk);
  UNSIGNED_LONGS_EQUAL(0x80000201u, hb.axis_error);
}

TEST(ODriveCodec, heartbeat_with_four_bytes_is_wrong_length) {
  odrive::Heartbeat hb;
  CHECK(odrive::decode_heartbeat(frame(0x021, {0, 0, 0, 0}), 1, hb) == CanDecodeError::kWrongLength);
}

TEST(ODriveCodec, heartbeat_of_other_node_is_wrong_id) {
  odrive::Heartbeat hb;
  CHECK(odrive::decode_heartbeat(frame(0x041, {0, 0, 0, 0, 8}), 1, hb) == CanDecodeError::kWrongId);
}

TEST(ODriveCodec, node_above_63_is_refused) {
  hal::CanFrame f;
  CHECK_FALSE(odrive::make_encoder_estimates_request(64, f));
  odrive::Heartbeat hb;
  CHECK(odrive::decode_heartbeat(frame(0x021, {0, 0, 0, 0, 8}), 64, hb) == CanDecodeError::kBadNode);
}
